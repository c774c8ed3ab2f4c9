"""Guards of `cvtfem run` on the band-4dof model (issue 7): the fixed-step local-error warning and the
failure policy `solver.on_failure` ("stop" keeps the partial results and exits 3, "retry" restarts
from the newest checkpoint with half the step, then with `solver.fallback`)."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.errors import InputError, NumericalError
from cvtfem.io.results import read_results
from cvtfem.scene.loader import load_scene

pytestmark = pytest.mark.hard

#: Torque ramp to ~0 with a vanishing clamping floor: gross slip, the step size collapses (BDF at
#: t = 0.0765 s) and the stall guard stops the run (see test_loworder_hard.py).
STALL = """preset = "band-4dof"
[cvt.regime]
kind = "torque-ramp"
torque = 200.0
end_value = 1e-3
ramp_time = 0.05
min_clamping_force = 1e-9
[output]
checkpoint_interval = 0.01
"""


def _rk4(h: float, **solver):
    return load_scene("band-4dof", {"solver": {"method": "rk4", "h": h, **solver}})


def test_rk4_step_too_large_for_the_tolerance_is_reported():
    """The known defect (docs/low-order.md): RK4 at h = 2e-5 s stays bounded but is wrong (slip of the
    driving arc -0.045 instead of -0.027 m/s at 0.02 s). The default check (every 20 steps, step doubling)
    estimates a local error far above rtol = 1e-3 / atol = 1e-5 at 2e-5 s and stays below it at 1e-5 s;
    its cost is one 2h step (4 RHS calls) per 20 steps of 4 RHS calls each (5 %; 4.7 % of all calls at 0.02 s)."""
    small = run_scene(_rk4(1e-5), until=0.01, show_progress=False)
    large = run_scene(_rk4(2e-5), until=0.01, show_progress=False)
    assert "warning" not in small.solver and small.solver["err_check_max"] < 0.1
    assert small.solver["nerr_checks"] == 1000 // 20 and small.solver["nfev_err_check"] == 4 * 1000 // 20
    assert large.solver["err_check_max"] > 5
    assert large.solver["warning"].startswith("fixed step too large for the tolerance: estimated local error ")
    assert "(rtol = 0.001, atol = 1e-05)" in large.solver["warning"]
    # the warning is right: the large step's slip is off by far more than the small step's
    assert abs(large.slip_speed_m_s[0] - small.slip_speed_m_s[0]) > 1e-3 * abs(small.slip_speed_m_s[0])
    off = run_scene(_rk4(2e-5, error_check=0), until=0.01, show_progress=False)
    assert "nerr_checks" not in off.solver and off.ratio == large.ratio   # the check changes nothing


def test_cli_prints_one_warning_line(tmp_path, cli):
    scene = tmp_path / "rk4.toml"
    scene.write_text('preset = "band-4dof"\n[solver]\nmethod = "rk4"\nh = 2e-5\n', encoding="utf-8")
    res = cli("run", str(scene), "--until", "0.005", "--results", "none")
    assert res.returncode == 0, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if "fixed step too large for the tolerance" in ln]
    assert len(lines) == 1 and lines[0].startswith("WARNING cvtfem.analysis.run: ") and "reduce h" in lines[0]


@pytest.mark.timeout(120)
def test_on_failure_stop_keeps_partial_results(tmp_path, cli):
    """Default policy: the stall is a one-line error with exit status 3; the rows up to the failure stay
    readable and the file says "failed" with the message."""
    scene, path = tmp_path / "stall.toml", tmp_path / "stall.h5"
    scene.write_text(STALL, encoding="utf-8")
    res = cli("run", str(scene), "--until", "0.1", "--results", str(path))
    assert res.returncode == 3 and "Traceback" not in res.stderr
    assert "cvtfem run: error: step size stalled: 50 consecutive BDF steps" in res.stderr
    r = read_results(path)
    assert r.attrs["status"] == "failed" and r.attrs["message"].startswith("step size stalled")
    assert r.time.size == 77 and r.time[-1] == pytest.approx(0.076)   # every sample before t = 0.0765 s
    assert np.all(np.isfinite(r.series["ratio"]))


def test_on_failure_retry_halves_the_step_then_falls_back(tmp_path):
    """A step budget too small for RK4 at 1e-5 s (900 of 1000 steps): the run fails at t = 0.00901 s, retry 1
    restarts at the checkpoint t = 0.00801 s with h = 5e-6 s (needs 400 more steps, fails again at the
    budget), retry 2 continues with Radau from the same checkpoint and finishes; both retries are logged
    in the results file, and the samples before the checkpoint are those of the RK4 run."""
    scene = load_scene("band-4dof", {"solver": {"method": "rk4", "h": 1e-5, "max_steps": 900, "on_failure": "retry",
                                                "max_retries": 2}, "output": {"checkpoint_interval": 0.002}})
    s = run_scene(scene, until=0.01, results=tmp_path / "r.h5", show_progress=False)
    r = read_results(tmp_path / "r.h5")
    assert r.attrs["status"] == "finished" and r.time.size == 11 and s.solver["name"] == "Radau"
    log = r.stats["retry_log"].splitlines()
    assert r.stats["retries"] == 2 and len(log) == 2
    assert log[0].startswith("retry 1 of 2 with rk4, h = 5e-06 s after: step budget `solver.max_steps` = 900 "
                             "exhausted, at t = 0.00901 s, from the checkpoint at t = 0.00801 s")
    assert log[1].startswith("retry 2 of 2 with Radau, rtol = 0.001 after: step budget")
    run_scene(_rk4(1e-5), until=0.01, results=tmp_path / "ref.h5", show_progress=False)
    a = read_results(tmp_path / "ref.h5")
    for name in ("ratio", "driving.speed"):
        np.testing.assert_array_equal(r.series[name][:9], a.series[name][:9])


@pytest.mark.timeout(120)
def test_on_failure_retry_gives_up_after_max_retries(tmp_path):
    """The stall scene with one retry (straight to the fallback) and a fallback that stalls as well (BDF):
    the run fails with the fallback's error; the file is "failed" and logs the retry."""
    scene = load_scene("band-4dof").replace({"cvt": {"regime": {"kind": "torque-ramp", "torque": 200.0,
                                                                "end_value": 1e-3, "ramp_time": 0.05,
                                                                "min_clamping_force": 1e-9}},
                                             "solver": {"on_failure": "retry", "max_retries": 1, "fallback": "BDF"},
                                             "output": {"checkpoint_interval": 0.01}})
    with pytest.raises(NumericalError, match="step size stalled: 50 consecutive BDF steps") as err:
        run_scene(scene, until=0.1, results=tmp_path / "r.h5", show_progress=False)
    r = read_results(tmp_path / "r.h5")
    assert r.attrs["status"] == "failed" and r.attrs["message"] == str(err.value) and r.stats["retries"] == 1
    assert r.stats["retry_log"].startswith("retry 1 of 1 with BDF, rtol = 0.001 after: step size stalled")


def test_scipy_stepper_fooled_by_a_switched_force_is_stopped(monkeypatch):
    """The growth guard of `cvtfem run` for scipy steppers: the band-4dof right-hand side plus a force of
    1e20 switched on at t = 0.0100005 s in the last state (a discontinuity RK45's embedded estimate does
    not see at rtol 1e-2): the accepted step that jumps from 734 to 1.6e15 stops the run with the guard's
    message, its component, time and step."""
    import cvtfem.analysis.run as run_mod

    make = run_mod.make_stepper

    def switched(method, fun, *args, **kwargs):
        def fun_on(t, y):
            f = np.array(fun(t, y), dtype=float)
            f[-1] += 1e20 if t >= 0.0100005 else 0.0
            return f
        return make(method, fun_on, *args, **kwargs)

    monkeypatch.setattr(run_mod, "make_stepper", switched)
    scene = load_scene("band-4dof", {"solver": {"method": "RK45", "rtol": 1e-2}})
    with pytest.raises(NumericalError) as err:
        run_scene(scene, until=0.02, show_progress=False)
    text = str(err.value)
    assert text.startswith("RK45 failed: instability (RK45): |x| grew by a factor 2.18e+12 in one accepted step "
                           "(component 15), from 734 to 1.6e+15 (more than growth_limit = 1e+08 times the largest "
                           "|x| so far) at t = 0.010014 s with adaptive step h = 1.77e-05 s: the error estimate did "
                           "not reject it")
    assert err.value.t == pytest.approx(0.010014, abs=1e-6) and err.value.component == "band model band-4dof"


def test_fallback_without_error_estimate_is_refused(tmp_path):
    scene = load_scene("band-4dof", {"solver": {"on_failure": "retry", "fallback": "rk4"}})
    with pytest.raises(InputError, match="`solver.fallback` must be a method with an error estimate"):
        run_scene(scene, until=0.01, results=tmp_path / "r.h5", show_progress=False)
    assert not (tmp_path / "r.h5").exists()


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_on_failure_retry_gets_past_a_stall_with_radau(tmp_path):
    """The stall scene with `on_failure = "retry"`: BDF at half the tolerances stalls at the same place
    (t = 0.07651 s), Radau from the checkpoint t = 0.0732 s gets through the gross-slip phase (~2000 steps)
    and finishes at the held ratio 2.401 (target 2.4)."""
    scene = load_scene("band-4dof").replace({"cvt": {"regime": {"kind": "torque-ramp", "torque": 200.0,
                                                                "end_value": 1e-3, "ramp_time": 0.05,
                                                                "min_clamping_force": 1e-9}},
                                             "solver": {"on_failure": "retry", "max_retries": 2},
                                             "output": {"checkpoint_interval": 0.01}})
    s = run_scene(scene, until=0.1, results=tmp_path / "r.h5", show_progress=False)
    r = read_results(tmp_path / "r.h5")
    assert r.attrs["status"] == "finished" and r.time.size == 101 and r.stats["retries"] == 2
    assert "retry 2 of 2 with Radau" in r.stats["retry_log"] and "step size stalled" in r.stats["retry_log"]
    assert s.ratio == pytest.approx(2.4, abs=2e-3) and np.all(np.isfinite(r.series["ratio"]))
