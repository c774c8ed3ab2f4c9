"""Issue 18, first classes: scene files the loader did not survive, and counts and spans a run cannot take.

Each case ends in one line naming what is wrong (exit 2), before any work starts; each failed on the code
before the fix (UnicodeDecodeError, RecursionError, OSError tracebacks; a raw terminal escape printed; a
ValueError from numpy for `--until inf`; a never-ending checkpoint loop for `checkpoint_interval = 1e-300`;
ten billion rows for `output.step = 1e-10`).
"""
import pytest

pytestmark = pytest.mark.hard


def _one_line_error(res, *needles):
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("content,needles", [
    (b'title = "\xff"\npreset = "band-4dof"\n', ("must be UTF-8", "0xff", "line 1")),
    (bytes(range(256)) * 2, ("must be UTF-8",)),
    (("a = " + "[" * 3000 + "]" * 3000 + "\n").encode(), ("nested",)),
    (b'preset = "band-4dof"\ntitle = "\\u001b[31mred"\n', ("`title`", "control characters", "\\x1b")),
    (b'preset = "band-4dof"\ndescription = "' + b"x" * 5000 + b'"\n', ("`description`", "at most 1000")),
])
def test_scene_files_the_loader_did_not_survive(tmp_path, cli, content, needles):
    path = tmp_path / "scene.toml"
    path.write_bytes(content)
    line = _one_line_error(cli("describe", str(path)), *needles)
    assert "\x1b" not in line   # an escape sequence is quoted, never sent to the terminal


def test_oversized_scene_file_is_refused_before_reading(tmp_path, cli):
    path = tmp_path / "huge.toml"
    path.write_bytes(b"# " + b"x" * (2 << 20) + b"\n")
    _one_line_error(cli("describe", str(path)), "at most 1024 KiB")


def test_a_name_too_long_for_the_file_system(cli):
    line = _one_line_error(cli("describe", "x" * 5000), "`SCENE`", "File name too long", "5002 characters")
    assert len(line) < 400   # the value is quoted shortened


@pytest.mark.parametrize("args,needles", [
    (("--until", "inf"), ("`--until`", "finite")),
    (("--until", "nan"), ("`--until`",)),
    (("--until", "1e300"), ("`output.step`", "samples")),
])
def test_run_spans_refused_up_front(cli, args, needles):
    _one_line_error(cli("run", "band-4dof", "--results", "none", *args), *needles)


@pytest.mark.parametrize("output,needles", [
    ("step = 1e-10", ("`output.step`", "1e+10 samples", "GB")),
    ("checkpoint_interval = 1e-300", ("`output.checkpoint_interval`", "magnitude")),   # the loop never ended
    ("checkpoint_interval = 1e-12", ("`output.checkpoint_interval`", "1e+05 checkpoints")),
])
def test_run_counts_bounded_up_front(tmp_path, cli, output, needles):
    scene = tmp_path / "s.toml"
    scene.write_text(f'preset = "band-4dof"\n[output]\n{output}\n')
    results = tmp_path / "r.h5"
    _one_line_error(cli("run", str(scene), "--until", "1", "--results", str(results), timeout=60), *needles)
    assert not results.exists()   # refused before any work or file


@pytest.mark.parametrize("argv,needles", [
    (("run", "band-4dof", "--until", "0.001", "--results", "{dir}"), ("`--results`", "not a folder")),
    (("run", "band-4dof", "--until", "0.001", "--results", "none", "--summary-json", "{file}/s.json"),
     ("`--summary-json`", "is a file")),
    (("campbell", "friswell_5_9_1", "--speeds", "0:100:3", "--png", "{dir}"), ("`--png`", "not a folder")),
    (("campbell", "friswell_5_9_1", "--speeds", "0:100:3", "--csv", "{file}/c.csv"), ("`--csv`",)),
    (("periodic", "engine_gear_train", "--json", "{dir}"), ("`--json`",)),
    (("modes", "friswell_5_9_1", "--json", "{long}.json"), ("`--json`", "255 bytes")),
    (("docs", "scenes", "--out", "{file}/scenes.md"), ("`--out`",)),
    (("demo", "--out", "{file}"), ("`--out`", "must be a folder")),
    # a path ending in "/" names a folder even when none exists yet (open() then fails after the study)
    (("study", "heat", "--N", "20", "--csv", "{dir}/new/"), ("`--csv`", "not a folder")),
    (("study", "order", "--csv", "{dir}/."), ("`--csv`", "not a folder")),
])
def test_output_paths_checked_before_the_work(tmp_path, cli, argv, needles):
    """Each of these used to end in a traceback after the work was done (the work lost)."""
    folder, file = tmp_path / "folder", tmp_path / "file"
    folder.mkdir()
    file.write_text("")
    args = [a.format(dir=folder, file=file, long=tmp_path / ("y" * 300)) for a in argv]
    _one_line_error(cli(*args, timeout=60), *needles)


def test_default_results_name_stays_in_out_runs(tmp_path, cli):
    """`cvtfem run ../x` (a scene file without .toml) used to write `out/runs/../x.h5`, outside out/runs."""
    (tmp_path / "x").write_text('preset = "band-4dof"\n')
    work = tmp_path / "work"
    work.mkdir()
    res = cli("run", "../x", "--until", "0.002", cwd=work)
    assert res.returncode == 0, res.stderr
    assert (work / "out" / "runs" / "x.h5").is_file() and not (work / "out" / "x.h5").exists()


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    from cvtfem.analysis.run import run_scene
    from cvtfem.scene.loader import load_scene

    path = tmp_path_factory.mktemp("run") / "r.h5"
    run_scene(load_scene("band-4dof"), until=0.01, results=path, show_progress=False)
    return path


@pytest.mark.parametrize("command", [("show",), ("run", "--resume")])
def test_truncated_results_file_is_refused_not_read(tmp_path, cli, finished_run, command):
    """`head -c 1000 run.h5 > t.h5`: `show` and `--resume` hung in HDF5's SWMR metadata retries."""
    cut = tmp_path / "t.h5"
    cut.write_bytes(finished_run.read_bytes()[:1000])
    _one_line_error(cli(*command, str(cut), timeout=30), "is truncated", "the file has 1000")


def test_hdf5_file_that_is_not_a_results_file(tmp_path, cli):
    import h5py

    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = "finished"
    _one_line_error(cli("show", str(path)), "must be a cvtfem results file", "series")


def _friswell_with(tmp_path, change):
    import copy
    import tomllib

    import tomli_w

    from cvtfem.scene.loader import preset_text

    data = copy.deepcopy(tomllib.loads(preset_text("friswell_5_9_1")))
    change(data)
    path = tmp_path / "rotor.toml"
    path.write_text(tomli_w.dumps(data))
    return str(path)


@pytest.mark.parametrize("change,needles", [
    (lambda d: d["shaft"][0].update(repeat=10 ** 7), ("`shaft[0].repeat`", "<= 3000")),        # hung
    (lambda d: d.update(shaft=[dict(d["shaft"][0], repeat=2000)] * 2), ("`shaft[].repeat`", "DOF")),
    (lambda d: d["material"][0].update(rho=1e-300), ("`material[0].rho`", "magnitude 1e-30")),  # geev ValueError
    (lambda d: d["material"][0].update(rho=0.5), ("`material[0].rho`", ">= 1")),
    (lambda d: d["material"][0].update(E=1e300), ("`material[0].E`", "magnitude", "1e+30")),
    (lambda d: d["material"][0].update(E=1e14), ("`material[0].E`", "<= 1e+13")),
    (lambda d: d["shaft"][0].update(length=1e-300), ("`shaft[0].length`",)),
])
def test_rotor_sizes_and_physical_ranges(tmp_path, cli, change, needles):
    _one_line_error(cli("modes", _friswell_with(tmp_path, change), timeout=60), *needles)


def test_periodic_harmonics_bounded(cli):
    """10^7 harmonics ran out of memory (or time) before saying anything."""
    _one_line_error(cli("periodic", "engine_gear_train", "--harmonics", "10000000", timeout=60),
                    "`--harmonics`", "1..1000", "GB")


def test_resume_of_a_running_run_is_refused_and_works_after_a_kill(tmp_path, cli):
    """`--resume` on a file another process is writing was accepted and the original died with a traceback;
    the writer now holds a lock (flock on a sidecar), which a kill -9 releases."""
    import os
    import signal
    import subprocess
    import sys

    scene = tmp_path / "s.toml"
    scene.write_text('preset = "band-4dof"\n[solver]\nmethod = "rk4"\nh = 2e-6\n'
                     '[output]\ncheckpoint_interval = 0.002\n')
    results = tmp_path / "r.h5"
    proc = subprocess.Popen([sys.executable, "-m", "cvtfem.cli", "run", str(scene), "--until", "1", "--results",
                             str(results), "--report-checkpoints"], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().startswith("checkpoint 1")
        _one_line_error(cli("run", "--resume", str(results)), "must not be in use", f"pid {proc.pid}")
        _one_line_error(cli("run", str(scene), "--results", str(results), "--overwrite"), "must not be in use")
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    from cvtfem.io.results import RunLock

    RunLock(results, "--resume").release()   # the killed writer's lock is gone with it


def test_results_writer_never_stores_a_non_finite_value(tmp_path):
    """A NaN in an output ends the run as failed, naming the output and its time; the rows before stay."""
    import numpy as np

    from cvtfem.errors import NumericalError
    from cvtfem.io.results import ResultsWriter, read_results
    from cvtfem.outputs import OutputSpec

    path = tmp_path / "r.h5"
    w = ResultsWriter(path, "", "run", [OutputSpec("a", "-", "a"), OutputSpec("b", "-", "b", 2)])
    for i in range(5):
        w.append(0.1 * i, {"a": float(i), "b": [i, np.nan if i == 3 else i]})
    with pytest.raises(NumericalError, match=r"output `b` became non-finite.*t = 0.3 s"):
        w.close()
    res = read_results(path)
    assert res.attrs["status"] == "failed" and res.time.tolist() == [0.0, 0.1, 0.2]
    assert np.isfinite(res.series["b"]).all()


def test_zero_torque_run_writes_only_finite_values(tmp_path, cli):
    """band-4dof at 0 N m wrote NaN efficiency and exited 0; the instantaneous efficiency is now 0 while no
    power is put in (the summary still calls the efficiency undefined)."""
    import numpy as np

    from cvtfem.io.results import read_results

    scene = tmp_path / "s.toml"
    scene.write_text('preset = "band-4dof"\n[cvt.regime]\ntorque = 0.0\n')
    res = cli("run", str(scene), "--until", "0.01", "--results", str(tmp_path / "r.h5"))
    assert res.returncode == 0 and "efficiency undefined" in res.stdout
    series = read_results(tmp_path / "r.h5").series
    assert all(np.isfinite(v).all() for v in series.values()) and np.all(series["efficiency"] == 0.0)


@pytest.mark.parametrize("until,needles", [
    ("0.005", ("the run diverged", "final ratio", "euler at h = 0.001 s")),   # exited 0 at -3.65e9 rpm
    ("0.05", ("right-hand side failed", "diverging")),                        # LinAlgError traceback
])
def test_diverged_fixed_step_run_fails_loudly(tmp_path, cli, until, needles):
    scene = tmp_path / "s.toml"
    scene.write_text('preset = "band-6+2n+8"\n[solver]\nmethod = "euler"\nh = 1e-3\n')
    res = cli("run", str(scene), "--until", until, "--results", str(tmp_path / "r.h5"))
    assert res.returncode == 3 and "Traceback" not in res.stderr, res.stderr
    line = res.stderr.strip()
    assert len(line.splitlines()) == 1 and all(n in line for n in needles), line
    from cvtfem.io.results import read_results

    assert read_results(tmp_path / "r.h5").attrs["status"] == "failed"


def test_damaged_results_file_metadata_ends_in_one_line(tmp_path, finished_run):
    """64 damaged 64-byte blocks over the file's first 4 KiB (its metadata), each read by `show` in a subprocess
    with a deadline: HDF5's SWMR reader retried damaged metadata for more than 10 minutes before the fix."""
    import subprocess
    import sys

    base = finished_run.read_bytes()
    for k, at in enumerate(range(0, 4096, 64)):
        blob = bytearray(base)
        blob[at:at + 64] = bytes((at + i) * 37 % 256 for i in range(64))
        (tmp_path / f"d{k}.h5").write_bytes(bytes(blob))
    code = ("import sys\nfrom cvtfem.cli import main\n"
            "for k in range(64):\n    print(main(['show', sys.argv[1] + f'/d{k}.h5']), file=sys.stderr)\n")
    res = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr[-2000:]
    lines = res.stderr.strip().splitlines()
    codes = [int(line) for line in lines if line in ("0", "2", "3")]
    assert len(codes) == 64 and set(codes) <= {0, 2}, lines
    errors = [line for line in lines if line not in ("0", "2", "3")]
    assert len(errors) == codes.count(2) and all(line.startswith("cvtfem show: error: `RESULTS` ")
                                                 for line in errors), errors


@pytest.mark.parametrize("argv,needles", [
    (("study", "stability", "--n", "0"), ("`--n`", "2..2001")),                            # TypeError
    (("study", "stability", "--methods", ","), ("`--methods`", "1..40 methods")),          # ZeroDivisionError
    (("study", "stability", "--extent", "nan"), ("`--extent`",)),                          # ran on NaN
    (("study", "order", "--hs", "0.1:0.01:0"), ("`--hs`", "COUNT in 2..50")),               # empty study
    (("study", "work", "--repeats", "0"), ("`--repeats`", "1..100")),                      # AttributeError
    (("study", "work", "--problem", "oscillator", "--steps", "1e-12"), ("`--steps`", "1e+07 steps")),
    (("study", "heat", "--methods", "foo", "--N", "10"), ("`--methods`", "heat benchmark")),  # KeyError
    (("study", "heat", "--N", "100000"), ("`--N`", "3..1000", "1.5e+09 steps")),
    (("study", "order", "--png", "o.0"), ("`--png`", ".png file")),                        # matplotlib ValueError
    (("study", "heat", "\x1e", "--N", "10"), ("unrecognized arguments: \\x1e",)),          # two lines
])
def test_study_arguments_refused_up_front(tmp_path, cli, argv, needles):
    line = _one_line_error(cli(*argv, cwd=tmp_path, timeout=60), *needles)
    assert not list(tmp_path.iterdir())   # nothing written
    assert "\x1e" not in line


def test_resume_refuses_names_that_are_not_utf8(tmp_path, cli):
    """A damaged byte in a stored name came back from h5py as a lone surrogate and the resume wrote it into the
    new file: UnicodeEncodeError after the file was reopened (found by the long results-file fuzz)."""
    from tests.hard.test_fuzz_commands import _killed_run

    blob = bytearray(_killed_run())
    at = blob.find(b"retry")                  # a checkpoint field name
    assert at > 0
    blob[at] = 0x80
    path = tmp_path / "r.h5"
    path.write_bytes(bytes(blob))
    _one_line_error(cli("run", "--resume", str(path)), "`--resume`", "not UTF-8")


def test_work_precision_figure_when_every_run_fails(tmp_path):
    """Every run unstable: the figure says so instead of failing on empty log axes (found by the study fuzz)."""
    from cvtfem.post.integrators import plot_work_precision

    rows = [{"label": "rk4", "method": "rk4", "error": float("inf"), "time": 0.01, "nfev": 20, "h": 0.1}]
    assert plot_work_precision(rows, tmp_path / "w.png").stat().st_size > 1000
