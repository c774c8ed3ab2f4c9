"""Issue 18: every analysis command on mutated presets ends in a result or in one line with exit 2 (input)
or 3 (numerics) — never a traceback, never a hang, never a non-finite value in a results file of a run
that exits 0.  The same for `cvtfem study` on mutated cheap arguments, and for `cvtfem show` and
`cvtfem run --resume` on valid, truncated, overwritten, restructured, garbage and missing results files.
A fast profile runs in `make test`, the long one (2,000 examples each) in `make test-slow`."""
from __future__ import annotations

import contextlib
import copy
import functools
import io
import math
import re
import signal
import tempfile
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cvtfem.cli import main
from cvtfem.scene.loader import preset_text, resolve_presets

pytestmark = pytest.mark.hard

#: Command, preset mutated, cheap arguments.
COMMANDS = {"run": ("band-4dof", ["--until", "0.002", "--results", "r.h5"]),
            "modes": ("friswell_5_9_1", []),
            "campbell": ("friswell_5_9_1", ["--speeds", "0:3000rpm:3"]),
            "periodic": ("engine_gear_train", ["--sweep", "12:13:2", "--harmonics", "6"])}
#: The presets resolved into whole documents, less the provenance key ``preset``: written back with it, a document whose
#: mutation deletes a table would take that table from the preset again (band-4dof without its ``cvt`` became
#: reference_cvt's variant (e) transmission, a legitimate run of hours: reported as a hang).
BASES = {name: {k: v for k, v in resolve_presets(tomllib.loads(preset_text(preset))).items() if k != "preset"}
         for name, (preset, _) in COMMANDS.items()}
VALUES = st.one_of(st.sampled_from([0, -1, 10 ** 9, 1e300, 1e-300, -0.0, "x", True, [1, 2], {"a": 1}]),
                   st.floats(allow_nan=True, allow_infinity=True), st.integers(-10 ** 6, 10 ** 6))
HANG = 60  # s: an example running longer is a hang ...
#: ... plus this per output row the mutated scene asks for: a run's every row is a model evaluation and a write
#: (36 us per band-4dof row measured; a mutated `output.step` times 1e-6 asks for 2e6 rows, legitimate work of a
#: minute or more that the fixed alarm reported as a hang on a loaded machine)
ROW_TIME = 1e-4  # s


def _paths(node):
    if isinstance(node, dict):
        for key, value in node.items():
            yield node, key
            yield from _paths(value)
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield node, i
            yield from _paths(value)


def _mutate(doc, data):
    pairs = list(_paths(doc))
    container, key = pairs[data.draw(st.integers(0, len(pairs) - 1))]
    value = container[key]
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    action = data.draw(st.sampled_from(["value", "sign", "scale", "zero", "delete"]))
    if action == "value":   # a copy: the sampled [1, 2] and {"a": 1} are shared objects, and a second mutation
        container[key] = copy.deepcopy(data.draw(VALUES))   # inside one would make it contain itself
    elif action == "sign" and number:
        container[key] = -value
    elif action == "scale" and number:
        container[key] = type(value)(value * 10 ** data.draw(st.integers(-12, 12)))
    elif action == "zero" and number:
        container[key] = type(value)(0)
    elif action == "delete" and isinstance(container, dict):
        del container[key]


class _Hang(Exception):
    pass


def _alarm(*_):
    raise _Hang


def _rows(doc, until: float) -> float:
    """The output rows a run of the scene ``doc`` to ``until`` s asks for (0 for a step the schema refuses)."""
    output = doc.get("output")
    step = output.get("step", 1e-3) if isinstance(output, dict) else None
    if isinstance(step, bool) or not isinstance(step, (int, float)) or not 0 < step < float("inf"):
        return 0.0
    return until / step


def _main(argv: list[str], what, rows: float = 0.0) -> tuple[int, list[str]]:
    """``cvtfem ARGV`` in this process under the hang alarm (:data:`HANG` plus :data:`ROW_TIME` per output row
    asked for): (exit status, stderr lines); argparse's exit counts."""
    err = io.StringIO()
    budget = HANG + math.ceil(ROW_TIME * min(rows, 1e7))   # more than 1e7 rows: refused by `cvtfem run`
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(budget)
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as stop:   # argparse: unknown option, missing value, wrong type
                code = stop.code
    except _Hang:
        pytest.fail(f"{argv[0]} hung (> {budget} s) on {what}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    lines = err.getvalue().strip().splitlines()
    assert code in (0, 2, 3), (argv, code, err.getvalue()[-2000:])
    if code:
        assert len(lines) == 1 and re.match(r"cvtfem( [\w-]+)*: error: ", lines[0]), (argv, lines)
    return code, lines


def _check(data):
    command = data.draw(st.sampled_from(sorted(COMMANDS)))
    doc = copy.deepcopy(BASES[command])
    for _ in range(data.draw(st.integers(1, 2))):
        _mutate(doc, data)
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        try:
            Path("s.toml").write_text(tomli_w.dumps(doc))
        except (TypeError, ValueError, OverflowError):   # not representable in TOML: nothing to test
            return
        # Floquet stability (3 of the 4 s of a periodic call here) runs in one example of ten
        extra = ["--no-stability"] if command == "periodic" and data.draw(st.integers(0, 9)) else []
        rows = _rows(doc, float(COMMANDS[command][1][1])) if command == "run" else 0.0
        code, _ = _main([command, "s.toml", *COMMANDS[command][1], *extra], doc, rows)
        if command == "run" and code == 0:
            from cvtfem.io.results import read_results

            series = read_results("r.h5").series
            assert all(np.isfinite(v).all() for v in series.values()), command


@settings(max_examples=24, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(data=st.data())
def test_commands_on_mutated_presets(data):
    _check(data)


@pytest.mark.slow
@settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_commands_on_mutated_presets_long(data):
    _check(data)




#: `cvtfem study` subcommands with cheap valid arguments (each well under a second), mutated by the fuzz.
STUDIES = {"stability": ["--methods", "rk4,euler", "--n", "9", "--extent", "3", "--png", "s.png"],
           "order": ["--problem", "oscillator", "--methods", "rk4", "--hs", "0.2:0.05:3", "--png", "o.png",
                     "--csv", "o.csv"],
           "work": ["--problem", "oscillator", "--methods", "rk4,dopri45", "--steps", "0.1,0.05", "--repeats", "1",
                    "--png", "w.png", "--csv", "w.csv"],
           "heat": ["--N", "10", "--repeats", "1", "--target", "1e-3", "--methods", "BDF,dopri45", "--csv", "h.csv"]}
ARGUMENTS = st.one_of(st.sampled_from(["", "0", "-1", "nan", "inf", "-inf", "1e300", "1e-300", "x", ",", ":", "1:2",
                                       "3:1:2", "0.2:0.05:100000000", "a=b", "rk4:h=x", "gbs:stages=0", "100000000",
                                       "2.5", "1e-3", "Radau", "/", "d/", "rk4,rk4,rk4", "--log", "--bogus"]),
                      st.text(max_size=12), st.floats().map(repr))


def _check_study(data):
    name = data.draw(st.sampled_from(sorted(STUDIES)))
    args = list(STUDIES[name])
    for _ in range(data.draw(st.integers(1, 2))):
        action = data.draw(st.sampled_from(["replace", "delete", "append"]))
        i = data.draw(st.integers(0, len(args) - 1)) if args else 0
        if action == "replace" and args:
            args[i] = data.draw(ARGUMENTS)
        elif action == "delete" and args:
            del args[i]
        else:
            args.append(data.draw(ARGUMENTS))
    if any("\x00" in a for a in args):   # not representable in a command line
        return
    if name == "heat" and "--N" not in args:   # the default N = 1000 is the full benchmark (minutes, not a hang)
        args += ["--N", "10"]
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        _main(["study", name, *args], args)


@settings(max_examples=24, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(data=st.data())
def test_study_on_mutated_arguments(data):
    _check_study(data)


@pytest.mark.slow
@settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_study_on_mutated_arguments_long(data):
    _check_study(data)


class _Stop(Exception):
    pass


@functools.cache
def _killed_run() -> bytes:
    """The bytes of a results file of a band-4dof run stopped after its second checkpoint (resumable)."""
    from cvtfem.analysis.run import run_scene
    from cvtfem.scene.loader import load_scene

    def stop(t, seq):
        if seq == 2:
            raise _Stop

    scene = load_scene("band-4dof", {"solver": {"method": "RK45"}, "output": {"checkpoint_interval": 0.001}})
    with tempfile.TemporaryDirectory() as tmp:
        with contextlib.suppress(_Stop):
            run_scene(scene, until=0.004, results=Path(tmp) / "r.h5", show_progress=False, on_checkpoint=stop)
        return (Path(tmp) / "r.h5").read_bytes()


def _replace(f, name, **dataset):
    del f[name]
    f.create_dataset(name, **dataset)


#: Edits of a results file's structure, each keeping it a readable HDF5 file.
RESTRUCTURE = {
    "no time": lambda f: f["series"].__delitem__("time"),
    "series a dataset": lambda f: _replace(f, "series", data=[1.0, 2.0]),
    "no series": lambda f: f.__delitem__("series"),
    "scene a number": lambda f: _replace(f, "scene", data=5),
    "scene not UTF-8": lambda f: _replace(f, "scene", data=np.bytes_(b"\xff\xfe")),
    "scene two strings": lambda f: _replace(f, "scene", data=["a", "b"]),
    "scene not TOML": lambda f: _replace(f, "scene", data="x = [[[", dtype=h5py.string_dtype()),
    "series 3-D": lambda f: f["series"].create_dataset("bad", data=np.zeros((2, 2, 2))),
    "series of text": lambda f: f["series"].create_dataset("bad", data=["a", "b"]),
    "series a group": lambda f: f["series"].create_group("bad"),
    "time 2-D": lambda f: _replace(f, "series/time", data=np.zeros((3, 2))),
    "no series at all": lambda f: [f["series"].__delitem__(k) for k in list(f["series"])],
    "stats a dataset": lambda f: _replace(f, "stats", data=1),
    "status an array": lambda f: f.attrs.__setitem__("status", np.arange(3)),
    "kind a number": lambda f: f.attrs.__setitem__("kind", 3),
    "finished": lambda f: f.attrs.__setitem__("status", "finished"),
    "no checkpoint": lambda f: f.__delitem__("checkpoint"),
    "NaN rows": lambda f: f["series"]["ratio"].__setitem__(slice(None), np.nan),
}


def _check_results_file(data):
    base = _killed_run()
    kind = data.draw(st.sampled_from(["valid", "truncated", "overwritten", "restructured", "garbage", "empty",
                                      "missing", "directory"]))
    command = data.draw(st.sampled_from([["show"], ["show", "--scene"], ["run", "--resume"]]))
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        path = Path("r.h5")
        if kind == "truncated":
            path.write_bytes(base[:data.draw(st.integers(0, len(base) - 1))])
        elif kind == "overwritten":
            blob = bytearray(base)
            at = data.draw(st.integers(0, len(blob) - 1))
            chunk = data.draw(st.binary(min_size=1, max_size=256))
            blob[at:at + len(chunk)] = chunk
            path.write_bytes(bytes(blob[:len(base)]))
        elif kind == "garbage":
            path.write_bytes(data.draw(st.binary(max_size=4096)))
        elif kind == "empty":
            path.write_bytes(b"")
        elif kind == "directory":
            path.mkdir()
        elif kind != "missing":
            path.write_bytes(base)
        if kind == "restructured":
            edit = data.draw(st.sampled_from(sorted(RESTRUCTURE)))
            with h5py.File(path, "r+") as f:
                RESTRUCTURE[edit](f)
            kind += f" ({edit})"
        code, _ = _main([*command, str(path)], kind)
        if command[0] == "run" and code == 0:   # a resumed run that finishes holds finite values only
            from cvtfem.io.results import read_results

            assert all(np.isfinite(v).all() for v in read_results(path).series.values()), kind


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(data=st.data())
def test_show_and_resume_on_damaged_results_files(data):
    _check_results_file(data)


@pytest.mark.slow
@settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_show_and_resume_on_damaged_results_files_long(data):
    _check_results_file(data)
