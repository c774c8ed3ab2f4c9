"""Checkpoint and resume of `cvtfem run` (issue 7, deliverable 4: no lost results).

A real ``python -m cvtfem.cli run`` is killed with SIGKILL at a random moment after a checkpoint
is on disk, resumed with ``cvtfem run --resume``, and its series are compared bitwise with an
uninterrupted run: a fixed-step explicit method, an adaptive explicit one (whose step size is
restored) and the implicit methods whose memory the checkpoint holds (trapezoidal: Jacobian,
iteration-matrix step, previous step; Radau: Jacobian, LU flag, controller history, collocation
increments; BDF: difference array, order, equal-step count, Jacobian).
"""
from __future__ import annotations

import random
import subprocess
import sys
import time

import numpy as np
import pytest

from cvtfem.analysis.run import resume_run, run_scene
from cvtfem.errors import InputError
from cvtfem.io.results import ResultsWriter, read_results
from cvtfem.outputs import OutputSpec
from cvtfem.scene.loader import load_scene

UNTIL = 0.05          # s simulated: 5000 rk4 steps, ~1.8 s wall per run (compiled right-hand side)
INTERVAL = 0.005      # s simulated between checkpoints: 9 before the end
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


def _difference(a, b) -> str:
    """Where two results first differ (series, row, time, largest relative difference) and their solver
    statistics: what a failed bitwise comparison reports, since the files do not outlive the test."""
    lines = []
    for name in sorted(a.series):
        x, y = np.asarray(a.series[name]), np.asarray(b.series.get(name, np.array([])))
        if x.shape != y.shape:
            lines.append(f"{name}: shapes {x.shape} and {y.shape}")
        elif not np.array_equal(x, y, equal_nan=True):
            rows = np.flatnonzero(np.any((x != y).reshape(len(x), -1), axis=1))
            rel = np.max(np.abs(x - y) / np.maximum(np.abs(x), 1e-300))
            lines.append(f"{name}: first row {rows[0]} (t = {a.time[rows[0]]:.6g} s), {len(rows)} rows, "
                         f"largest relative difference {rel:.3g}")
    keys = sorted(k for k in set(a.stats) | set(b.stats) if k.startswith(("solver_", "resumed")))
    stats = {k: (a.stats.get(k), b.stats.get(k)) for k in keys}
    return "; ".join(lines[:5]) + f"; stats (reference, resumed) {stats}"


#: implicit runs: a ratio change 2.4 -> 1.0 over the whole run at rtol 1e-7 keeps every method busy
#: (0.2 s simulated: 1.3 s wall BDF .. 3.3 s trapezoidal), so the kill (<= 0.3 s after checkpoint 2 of 10) comes first
IMPLICIT_UNTIL, IMPLICIT_INTERVAL = 0.2, 0.02
IMPLICIT_SCENE = """preset = "band-4dof"
[solver]
method = "{method}"
rtol = 1e-7
atol = 1e-9
[cvt.regime]
kind = "ratio-change"
end_value = 1.0
ramp_time = 0.2
[output]
checkpoint_interval = {interval}
"""


def _kill_and_resume(tmp_path, cli, text: str, until: float, interval: float, rows: int):
    """Uninterrupted reference, then a subprocess killed at a random moment between checkpoint 2 or 3 and
    the next one, resumed with the CLI; returns (reference, resumed) results and where it was killed."""
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(text, encoding="utf-8")
    ref_path, path = tmp_path / "ref.h5", tmp_path / "killed.h5"
    run_scene(load_scene(scene_file), until=until, results=ref_path, show_progress=False)

    rng = random.Random()
    after = rng.randint(2, 3)  # kill after checkpoint `after`, before the next one (the run has >= 8 more)
    proc = subprocess.Popen([sys.executable, "-m", "cvtfem.cli", "run", str(scene_file), "--until", str(until),
                             "--results", str(path), "--report-checkpoints"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        stamps = []
        for seq in range(1, after + 1):
            line = proc.stdout.readline()
            stamps.append(time.perf_counter())
            assert line.startswith(f"checkpoint {seq} at t = "), (line, proc.stderr.read() if not line else "")
        # a random moment within the wall time between two checkpoints: mid-run however fast the machine
        delay = rng.uniform(0.0, 0.9 * (stamps[1] - stamps[0]))
        time.sleep(delay)
    finally:
        proc.kill()  # SIGKILL
        proc.wait(timeout=30)
    where = f"(killed {delay:.3f} s after checkpoint {after})"
    assert proc.returncode == -9, where

    killed = read_results(path)  # what was written before the kill stays readable
    assert killed.attrs["status"] == "running", where
    assert killed.time.size >= round(after * interval / 1e-3), where
    shown = cli("show", str(path))
    assert shown.returncode == 0 and "status: running" in shown.stdout, shown.stderr

    resumed = cli("run", "--resume", str(path), "--report-checkpoints")
    assert resumed.returncode == 0, resumed.stderr + where
    assert "Traceback" not in resumed.stderr
    ref, res = read_results(ref_path), read_results(path)
    assert res.attrs["status"] == "finished" and res.attrs["resumed"] == 1
    assert res.time.size == ref.time.size == rows
    assert 0 < res.stats["resumed_from_t"] < until
    return ref, res, where


def test_killed_run_resumes_bitwise(tmp_path, cli):
    ref, res, where = _kill_and_resume(tmp_path, cli, SCENE, UNTIL, INTERVAL, round(UNTIL / 1e-3) + 1)
    assert _series_equal(ref, res), where
    assert res.stats["solver_steps"] == ref.stats["solver_steps"]
    path = res.path
    again = cli("run", "--resume", str(path))  # a finished run is not resumed without --until (nor overwritten)
    assert again.returncode == 2 and "unfinished run" in again.stderr and "--until" in again.stderr
    assert "Traceback" not in again.stderr
    assert _series_equal(ref, read_results(path))


@pytest.mark.slow
@pytest.mark.timeout(300)
@pytest.mark.parametrize("method", ["trapezoidal", "Radau", "BDF"])
def test_killed_implicit_run_resumes_bitwise(tmp_path, cli, method):
    """SIGKILL at a random moment: the resumed run equals the uninterrupted one bit for bit, with the
    same step, RHS, Jacobian and LU counts (the integrator memory travels in the checkpoint)."""
    text = IMPLICIT_SCENE.format(method=method, interval=IMPLICIT_INTERVAL)
    ref, res, where = _kill_and_resume(tmp_path, cli, text, IMPLICIT_UNTIL, IMPLICIT_INTERVAL,
                                       round(IMPLICIT_UNTIL / 1e-3) + 1)
    assert _series_equal(ref, res), f"{where}: {_difference(ref, res)}"
    for key in ("solver_steps", "solver_nfev", "solver_njev", "solver_nlu"):
        assert res.stats[key] == ref.stats[key], (key, where)


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
def test_implicit_resumes_bitwise(tmp_path, method):
    """Implicit methods: the checkpoint carries their Jacobian, step history and controller state
    (each method's ``state()``/``restore()``), so the resumed series and every counter equal the uninterrupted run's.
    Without it (a fresh solver at the checkpoint) the series differ in the 4th digit (trapezoidal 4e-4,
    BDF 2e-3 rad/s in the driving speed)."""
    scene = load_scene("band-4dof", {"solver": {"method": method}, "output": {"checkpoint_interval": 0.01}})
    ref = run_scene(scene, until=0.05, results=tmp_path / "ref.h5", show_progress=False)
    _interrupted(scene, tmp_path / "r.h5", 2, 0.05)
    res = resume_run(tmp_path / "r.h5", show_progress=False)
    assert _series_equal(read_results(tmp_path / "ref.h5"), read_results(tmp_path / "r.h5"))
    assert res.solver == ref.solver and res.ratio == ref.ratio and res.efficiency == ref.efficiency


class _Memory(dict):
    """A method's exported memory (named arrays); ``size``: its floats."""

    @property
    def size(self) -> int:
        return sum(v.size for v in self.values())


def export_state(method, solver, n, n2):
    """The memory a checkpoint holds of a :class:`CvtfemSolver`: its method's and its step-size controller's
    (:meth:`NativeEngine.state`)."""
    return _Memory(solver.stepping.engine.state(solver.t, solver.y))


def import_state(method, solver, mem, n, n2):
    solver.stepping.engine.restore(mem, solver.t, solver.y)


def state_size(method, n, n2):
    from cvtfem.integrate.stepping import memory_fields

    return sum(size for _, size in memory_fields(method, n, n2))


def test_solver_state_round_trip_restores_the_lu(tmp_path):
    """Export/import of the theta family rebuilds the iteration matrix from the saved Jacobian and
    h alpha: the next steps of a restored solver equal the original's bit for bit, at the same cost."""
    from cvtfem.integrate import CvtfemSolver

    A = np.array([[0.0, 1.0], [-1e4, -10.0]])

    def build():
        return CvtfemSolver(lambda t, y: A @ y + np.array([0.0, np.sin(50 * t)]), 0.0, np.array([1.0, 0.0]), 1.0,
                            cvtfem_method="trapezoidal", rtol=1e-6, atol=1e-9, n2=1)
    a = build()
    for _ in range(5):
        a.step()
    vec = export_state("trapezoidal", a, 2, 1)
    # gamma, lu_valid, prev_h, prev_f (2), hist_t (2), hist_x (2 x 2), J (2 x 2), f_start (2), newton_stale,
    # newton_eta, controller (4)
    assert vec.size == state_size("trapezoidal", 2, 1) == 3 + 2 + 2 + 4 + 4 + 2 + 2 + 4
    b = CvtfemSolver(a.fun, a.t, a.y, 1.0, cvtfem_method="trapezoidal", rtol=1e-6, atol=1e-9, n2=1,
                     first_step=a.h_next)
    import_state("trapezoidal", b, vec, 2, 1)
    before = {c: (a.stats.counts[c], b.stats.counts[c]) for c in ("nfev", "njev", "nlu")}
    for _ in range(3):
        a.step(), b.step()
        assert a.t == b.t and np.array_equal(a.y, b.y)
    for c, (na, nb) in before.items():   # same work after the restore: LU, Jacobian, F(t, x) reused alike
        assert a.stats.counts[c] - na == b.stats.counts[c] - nb, c



def test_theta_state_restores_newton_memory_at_every_step():
    """Adaptive trapezoidal on band-4dof (started off the targets): a solver rebuilt from the exported
    state after any of 60 steps continues bit for bit for 3 steps. The Newton solver's memory is part of
    that state: with its stale-Jacobian flag and contraction estimate reset instead, 10 of the 60
    restarts diverge from the uninterrupted run (measured)."""
    from cvtfem.integrate import CvtfemSolver
    from cvtfem.machines.cvt import closed_loop

    loop = closed_loop(load_scene("band-4dof"))
    n, n2 = loop.size, loop.model.n2

    def build(t, y, h=None):
        return CvtfemSolver(loop.rhs, t, y, 0.2, cvtfem_method="trapezoidal", rtol=1e-3, atol=1e-5, n2=n2,
                            jac=loop.jac, first_step=h)

    a = build(0.0, loop.initial_state(ratio=2.3, speed_factor=0.96))
    traj, saved = [], []
    for _ in range(63):
        a.step()
        traj.append((a.t, a.y.copy()))
        saved.append((a.t, a.y.copy(), a.h_next, export_state("trapezoidal", a, n, n2)))
    differ = {False: 0, True: 0}
    for i, (t, y, h, vec) in enumerate(saved[:60]):
        for reset_newton in (False, True):
            b = build(t, y, h)
            import_state("trapezoidal", b, vec, n, n2)
            if reset_newton:
                b.stepper.newton.stale, b.stepper.newton._eta = False, 1.0
            same = True
            for t_ref, y_ref in traj[i + 1:i + 4]:
                b.step()
                same &= b.t == t_ref and np.array_equal(b.y, y_ref)
            differ[reset_newton] += not same
    assert differ[False] == 0
    assert differ[True] > 0   # the Newton memory matters, so the test can fail without it

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


def test_finished_run_extended_equals_one_longer_run(tmp_path, cli):
    """`cvtfem run --resume FILE --until T` continues a finished run: its series equal those of one run to T
    bitwise (rk4 restarts from the newest checkpoint, the rows after it are recomputed), and the summary's
    efficiency is the work ratio over the samples since that checkpoint (the last 50 ms began before it)."""
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(SCENE, encoding="utf-8")
    ref_path, path = tmp_path / "ref.h5", tmp_path / "ext.h5"
    run_scene(load_scene(scene_file), until=UNTIL, results=ref_path, show_progress=False)
    first = cli("run", str(scene_file), "--until", str(0.6 * UNTIL), "--results", str(path))
    assert first.returncode == 0, first.stderr
    short = read_results(path)
    assert short.attrs["status"] == "finished" and short.time[-1] == pytest.approx(0.6 * UNTIL)
    summary = resume_run(path, show_progress=False, until=UNTIL)
    ref, res = read_results(ref_path), read_results(path)
    assert res.attrs["status"] == "finished" and res.attrs["resumed"] == 1
    assert _series_equal(ref, res), _difference(ref, res)
    t_ck = res.stats["resumed_from_t"]
    assert 0.5 * UNTIL < t_ck < 0.6 * UNTIL                      # the newest checkpoint of the short run
    j = int(np.searchsorted(res.time, t_ck, side="right"))       # the first sample the resumed run wrote
    W = res.series["work"]
    assert summary.efficiency == pytest.approx((W[-1, 1] - W[j, 1]) / (W[-1, 0] - W[j, 0]), rel=1e-12)


def test_a_resume_does_not_solve_the_start_state(tmp_path, monkeypatch):
    """A resumed run continues from its checkpoint: the model's start state (a chain's quasi-static solve, minutes on
    elastic shafts; twice per resume before session 15) is never solved, and the series equal one run's bitwise."""
    from cvtfem.machines.band_cvt import BandCVT

    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(SCENE, encoding="utf-8")
    ref_path, path = tmp_path / "ref.h5", tmp_path / "part.h5"
    run_scene(load_scene(scene_file), until=UNTIL, results=ref_path, show_progress=False)
    run_scene(load_scene(scene_file), until=0.6 * UNTIL, results=path, show_progress=False)

    def refuse(self, *args, **kwargs):
        raise AssertionError("the start state was solved on a resume")

    monkeypatch.setattr(BandCVT, "initial_state", refuse)
    monkeypatch.setattr(BandCVT, "start", refuse)
    resume_run(path, show_progress=False, until=UNTIL)
    ref, res = read_results(ref_path), read_results(path)
    assert res.attrs["status"] == "finished" and _series_equal(ref, res), _difference(ref, res)


def test_extension_before_the_checkpoint_is_refused_untouched(tmp_path, cli):
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(SCENE, encoding="utf-8")
    path = tmp_path / "run.h5"
    run_scene(load_scene(scene_file), until=0.02, results=path, show_progress=False)
    before = read_results(path)
    res = cli("run", "--resume", str(path), "--until", "0.01")
    assert res.returncode == 2 and "`--until`" in res.stderr and "after the newest checkpoint" in res.stderr
    assert "Traceback" not in res.stderr
    after = read_results(path)
    assert after.attrs["status"] == "finished" and "resumed" not in after.attrs
    assert _series_equal(before, after)


def test_resume_argument_errors(tmp_path, cli):
    res = cli("run", "--resume", str(tmp_path / "x.h5"), "--results", "y.h5")
    assert res.returncode == 2 and "`--results` cannot be combined with --resume" in res.stderr
    res = cli("run", "--resume", str(tmp_path / "missing.h5"))
    assert res.returncode == 2 and "must be an existing results file" in res.stderr
    res = cli("run")
    assert res.returncode == 2 and "`SCENE` is required" in res.stderr


CHANGED = """preset = "band-4dof"
title = "{title}"
[solver]
method = "{method}"
[cvt.regime]
torque = {torque}
[output]
checkpoint_interval = 0.005
"""


def _cli(capsys, *args):
    """``cvtfem ARGS`` in this process: (exit status, stderr lines)."""
    from cvtfem.cli import main

    code = main(list(args))
    return code, capsys.readouterr().err.strip().splitlines()


def test_resume_with_a_changed_scene(tmp_path, capsys):
    """Issue 18: SCENE with --resume must be the stored scene (its title aside), unless --resume-changed."""
    def scene(title="a", method="RK45", torque=200.0):
        path = tmp_path / f"{title}-{method}-{torque}.toml"
        path.write_text(CHANGED.format(title=title, method=method, torque=torque))
        return str(path)

    base = scene()
    _interrupted(load_scene(base), tmp_path / "r.h5", 1, 0.015)
    before = read_results(tmp_path / "r.h5")
    code, err = _cli(capsys, "run", scene(torque=250.0), "--resume", str(tmp_path / "r.h5"))
    assert code == 2 and len(err) == 1, err
    assert "`cvt.regime.torque` is 200.0 in the results file, 250.0 in SCENE" in err[0]
    assert "--resume-changed" in err[0]
    after = read_results(tmp_path / "r.h5")
    assert after.attrs["status"] == "failed" and _series_equal(before, after)   # untouched
    # another method changes the checkpoint's layout: refused even with --resume-changed
    code, err = _cli(capsys, "run", scene(method="BDF"), "--resume", str(tmp_path / "r.h5"), "--resume-changed")
    assert code == 2 and len(err) == 1 and "must give the state layout of the run in" in err[0], err
    assert _series_equal(before, read_results(tmp_path / "r.h5"))   # untouched
    code, err = _cli(capsys, "run", "--resume", str(tmp_path / "r.h5"), "--resume-changed")
    assert code == 2 and len(err) == 1 and "`--resume-changed`" in err[0] and "needs SCENE" in err[0], err
    # a new title only: resumed as without SCENE, bitwise the uninterrupted run
    ref = run_scene(load_scene(base), until=0.015, results=tmp_path / "ref.h5", show_progress=False)
    _interrupted(load_scene(base), tmp_path / "same.h5", 1, 0.015)
    code, err = _cli(capsys, "run", scene(title="renamed"), "--resume", str(tmp_path / "same.h5"))
    assert code == 0 and err == [], err
    assert _series_equal(read_results(tmp_path / "ref.h5"), read_results(tmp_path / "same.h5"))
    # with --resume-changed: the rows up to the checkpoint stay, the run continues at the new torque
    code, err = _cli(capsys, "run", scene(torque=250.0), "--resume", str(tmp_path / "r.h5"), "--resume-changed")
    assert code == 0 and err == [], err
    res = read_results(tmp_path / "r.h5")
    t_ck = res.stats["resumed_from_t"]
    assert res.attrs["status"] == "finished" and "torque = 250.0" in res.scene_toml
    assert res.stats["scene_changed"] == "`cvt.regime.torque` is 200.0 in the results file, 250.0 in SCENE"
    kept = before.time <= t_ck
    ref = read_results(tmp_path / "ref.h5")
    np.testing.assert_array_equal(res.series["driving.torque"][:kept.sum()], ref.series["driving.torque"][:kept.sum()])
    assert np.all(res.series["driving.torque"][res.time > t_ck] == 250.0)
    assert ref.series["driving.torque"][-1] == 200.0


ELASTIC = """preset = ["chain-S2", "shafts-elastic"]
[cvt.regime]
torque = {torque}
[solver]
method = "rk4"
h = 2e-7
[output]
step = 1e-5
checkpoint_interval = 2e-5
"""


def test_elastic_resume_keeps_the_stored_face_reference(tmp_path, monkeypatch):
    """On elastic shafts the run stores its faces' reference ``z_ref`` (``*.face_reference``, every row the run's
    constant); a resume reads it instead of solving the rigid start again: with that solve refused it equals one
    run bitwise, and with --resume-changed (a new torque, whose own start would put the faces elsewhere) the faces
    stay where the run had them."""
    from cvtfem.machines.chain_cvt_elastic import ElasticChainCVT
    from cvtfem.machines.cvt import chain_loop

    def scene(torque):
        path = tmp_path / f"e{torque}.toml"
        path.write_text(ELASTIC.format(torque=torque), encoding="utf-8")
        return load_scene(path)

    ref_path, path = tmp_path / "ref.h5", tmp_path / "part.h5"
    run_scene(scene(200.0), until=6e-5, results=ref_path, show_progress=False)
    run_scene(scene(200.0), until=4e-5, results=path, show_progress=False)
    ref = read_results(ref_path)
    stored = np.stack([ref.series["driving.face_reference"], ref.series["driven.face_reference"]], axis=1)
    assert np.all(stored == stored[0]) and np.all(np.abs(stored[0]) > 1.0)       # constant (toroidal faces' z_ref)
    np.testing.assert_array_equal(stored[0], chain_loop(scene(200.0)).face_ref)
    moved = chain_loop(scene(150.0)).face_ref
    assert np.abs(moved - stored[0]).max() > 1e-7                              # another torque, other faces

    def refuse(self, *args, **kwargs):
        raise AssertionError("the rigid start was solved on a resume")

    monkeypatch.setattr(ElasticChainCVT, "_rigid_static_state", refuse)
    resume_run(path, show_progress=False, until=6e-5)
    res = read_results(path)
    assert res.attrs["status"] == "finished" and _series_equal(ref, res), _difference(ref, res)
    resume_run(path, show_progress=False, until=8e-5, scene=scene(150.0), changed=True)
    res = read_results(path)
    assert res.attrs["status"] == "finished" and "torque = 150.0" in res.scene_toml
    after = np.stack([res.series["driving.face_reference"], res.series["driven.face_reference"]], axis=1)
    assert np.all(after == stored[0])
