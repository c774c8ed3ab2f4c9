"""Checkpoint and resume of `cvtfem run` (issue 7, deliverable 4: no lost results).

A real ``python -m cvtfem.cli run`` is killed with SIGKILL at a random moment after a checkpoint
is on disk, resumed with ``cvtfem run --resume``, and its series are compared with an
uninterrupted run: bitwise for a fixed-step explicit method and an adaptive explicit one (whose
step size is restored), within the solver tolerance for an implicit method that restarts its
Jacobian and step history.
"""
from __future__ import annotations

import random
import subprocess
import sys
import time

import numpy as np
import pytest

from cvtfem.analysis.run import resume_run, run_scene
from cvtfem.elements.base import OutputSpec
from cvtfem.errors import InputError
from cvtfem.io.results import ResultsWriter, read_results
from cvtfem.scene.loader import load_scene

UNTIL = 0.025         # s simulated: 2500 rk4 steps, ~2.5 s wall per run
INTERVAL = 0.005      # s simulated between checkpoints: 4 before the end, ~0.5 s wall apart
SCENE = f"""preset = "band-4dof"
[solver]
method = "rk4"
h = 1e-5
[output]
checkpoint_interval = {INTERVAL}
"""


def _series_equal(a, b) -> bool:
    return np.array_equal(a.time, b.time) and a.series.keys() == b.series.keys() and all(
        np.array_equal(a.series[n], b.series[n], equal_nan=True) for n in a.series)


def test_killed_run_resumes_bitwise(tmp_path, cli):
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(SCENE, encoding="utf-8")
    ref_path, path = tmp_path / "ref.h5", tmp_path / "killed.h5"
    run_scene(load_scene(scene_file), until=UNTIL, results=ref_path, show_progress=False)

    rng = random.Random()
    after, delay = rng.randint(1, 2), rng.uniform(0.0, 0.3)  # kill after checkpoint `after` + delay s
    proc = subprocess.Popen([sys.executable, "-m", "cvtfem.cli", "run", str(scene_file), "--until", str(UNTIL),
                             "--results", str(path), "--report-checkpoints"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        for seq in range(1, after + 1):
            line = proc.stdout.readline()
            assert line.startswith(f"checkpoint {seq} at t = "), (line, proc.stderr.read() if not line else "")
        time.sleep(delay)
    finally:
        proc.kill()  # SIGKILL
        proc.wait(timeout=30)
    where = f"(killed {delay:.3f} s after checkpoint {after})"
    assert proc.returncode == -9, where

    killed = read_results(path)  # what was written before the kill stays readable
    assert killed.attrs["status"] == "running", where
    assert killed.time.size >= round(after * INTERVAL / 1e-3), where
    shown = cli("show", str(path))
    assert shown.returncode == 0 and "status: running" in shown.stdout, shown.stderr

    resumed = cli("run", "--resume", str(path), "--report-checkpoints")
    assert resumed.returncode == 0, resumed.stderr + where
    assert "Traceback" not in resumed.stderr
    ref, res = read_results(ref_path), read_results(path)
    assert res.attrs["status"] == "finished" and res.attrs["resumed"] == 1
    assert res.time.size == ref.time.size == round(UNTIL / 1e-3) + 1
    assert _series_equal(ref, res), where
    assert res.stats["solver_steps"] == ref.stats["solver_steps"]
    assert 0 < res.stats["resumed_from_t"] < UNTIL

    again = cli("run", "--resume", str(path))  # a finished run is not resumed (and never overwritten)
    assert again.returncode == 2 and "unfinished run" in again.stderr and "Traceback" not in again.stderr
    assert _series_equal(ref, read_results(path))


class _Stop(Exception):
    pass


def _interrupted(scene, path, stop_at: int, until: float):
    """Run until checkpoint ``stop_at`` is on disk, then fail (as Ctrl-C would): the file is left 'failed'."""
    def stop(t, seq):
        if seq == stop_at:
            raise _Stop(t)

    with pytest.raises(_Stop):
        run_scene(scene, until=until, results=path, show_progress=False, on_checkpoint=stop)
    assert read_results(path).attrs["status"] == "failed"


@pytest.mark.parametrize("method", ["RK45", pytest.param("dopri45", marks=pytest.mark.slow)])
def test_adaptive_explicit_resumes_bitwise(tmp_path, method):
    """Explicit Runge-Kutta methods carry no memory but the step size, which the checkpoint restores."""
    scene = load_scene("band-4dof", {"solver": {"method": method}, "output": {"checkpoint_interval": 0.005}})
    ref = run_scene(scene, until=0.015, results=tmp_path / "ref.h5", show_progress=False)
    _interrupted(scene, tmp_path / "r.h5", 1, 0.015)
    res = resume_run(tmp_path / "r.h5", show_progress=False)
    assert _series_equal(read_results(tmp_path / "ref.h5"), read_results(tmp_path / "r.h5"))
    assert res.ratio == ref.ratio and res.efficiency == ref.efficiency and res.solver["steps"] == ref.solver["steps"]


@pytest.mark.parametrize("method", ["trapezoidal", "BDF", "Radau"])
def test_implicit_resumes_within_tolerance(tmp_path, method):
    """Implicit methods restart their Jacobian / step history: same results to the solver tolerance."""
    scene = load_scene("band-4dof", {"solver": {"method": method}, "output": {"checkpoint_interval": 0.01}})
    rtol = scene.solver.rtol
    ref = run_scene(scene, until=0.05, results=tmp_path / "ref.h5", show_progress=False)
    _interrupted(scene, tmp_path / "r.h5", 2, 0.05)
    res = resume_run(tmp_path / "r.h5", show_progress=False)
    a, b = read_results(tmp_path / "ref.h5"), read_results(tmp_path / "r.h5")
    np.testing.assert_array_equal(a.time, b.time)
    for name in ("driving.speed", "driven.speed", "ratio"):
        np.testing.assert_allclose(b.series[name], a.series[name], rtol=rtol, err_msg=name)
    assert abs(res.ratio - ref.ratio) <= rtol * ref.ratio
    assert abs(res.efficiency - ref.efficiency) <= rtol


def test_resume_refuses_file_without_checkpoint(tmp_path, cli):
    """An interrupted run whose scene has `output.checkpoint_interval = 0` cannot be resumed."""
    path = tmp_path / "nock.h5"
    scene = load_scene("band-4dof")  # checkpoint_interval = 0
    with pytest.raises(_Stop):
        with ResultsWriter(path, scene.to_toml(), "run", [OutputSpec("x", "m", "x")]) as w:
            w.append(0.0, {"x": 1.0})
            raise _Stop  # closes the file as "failed", as Ctrl-C would
    with pytest.raises(InputError, match="must hold a checkpoint"):
        resume_run(path, show_progress=False)
    res = cli("run", "--resume", str(path))
    assert res.returncode == 2 and "must hold a checkpoint" in res.stderr and "checkpoint_interval" in res.stderr
    assert "Traceback" not in res.stderr
    assert read_results(path).time.size == 1  # untouched


def test_resume_argument_errors(tmp_path, cli):
    res = cli("run", "band-4dof", "--resume", str(tmp_path / "x.h5"))
    assert res.returncode == 2 and "cannot be combined with --resume" in res.stderr
    res = cli("run", "--resume", str(tmp_path / "missing.h5"))
    assert res.returncode == 2 and "must be an existing results file" in res.stderr
    res = cli("run")
    assert res.returncode == 2 and "`SCENE` is required" in res.stderr
