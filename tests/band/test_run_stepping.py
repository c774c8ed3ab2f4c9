"""`cvtfem run` and `solve()` step through the same loop (issue 12): the same series bit for bit, scene
events (`[[solver.event]]`) located as `solve()` locates them, and a run interrupted after the checkpoint
before its terminal event resumes to the same bits."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from cvtfem.analysis.run import _Run, resume_run, run_scene
from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.io.results import read_results
from cvtfem.scene.loader import load_scene
from tests.hard.test_resume import _interrupted, _series_equal

RATIO_CHANGE = {"kind": "ratio-change", "end_value": 1.0, "ramp_time": 0.2}
EVENT = {"output": "ratio", "value": 2.3, "direction": "falling", "name": "ratio 2.3"}


def _scene(method: str, rtol: float, atol: float, **extra):
    return load_scene("band-4dof", {"solver": {"method": method, "rtol": rtol, "atol": atol, "event": [EVENT]},
                                    "cvt": {"regime": RATIO_CHANGE}, **extra})


def _solve(scene, until, **kw):
    """`solve()` on the run's own loop, initial state and event indicators."""
    run = _Run(scene, until)
    x0 = run.loop.initial_state()
    run.check_events(x0)
    sol = scene.solver
    return run, solve(run.loop.rhs, (0.0, until), x0, method=sol.method, rtol=sol.rtol, atol=sol.atol,
                      jac=run.loop.jac, n2=run.loop.model.n2, events=run.events, **kw)


@pytest.mark.parametrize("method", ["trapezoidal", "Radau"])
def test_run_and_solve_give_the_same_bits(tmp_path, method):
    """The results file's series are the outputs of `solve(loop.rhs, ..., t_eval=the output grid)` bit for bit."""
    scene = load_scene("band-4dof", {"solver": {"method": method}})
    run_scene(scene, until=0.02, results=tmp_path / "r.h5", show_progress=False)
    res = read_results(tmp_path / "r.h5")
    run = _Run(scene, 0.02)
    x0 = run.loop.initial_state()
    sol = solve(run.loop.rhs, (0.0, 0.02), x0, method=method, rtol=scene.solver.rtol, atol=scene.solver.atol,
                jac=run.loop.jac, n2=run.loop.model.n2, t_eval=res.time)
    assert sol.success and np.array_equal(sol.t, res.time)
    for name in ("driving.speed", "driven.speed", "ratio", "band.slip_speed", "energy"):
        ours = np.array([np.ravel(run.loop.outputs(t, x)[name]) for t, x in zip(sol.t, sol.y.T)])
        assert np.array_equal(ours.reshape(res.series[name].shape), res.series[name]), name


def test_terminal_event_ends_the_run_at_the_crossing(tmp_path):
    """ratio falling through 2.3 during a ratio change: the run ends there, with the same time bit for bit
    as `solve()` at the run's own settings, and a tight `solve()` (rtol 1e-11) puts the ratio at that time
    2.3 to within the run's rtol 1e-9; the results file records the event and ends on it.

    The crossing is slow (d ratio/dt = -1.14 1/s at t = 0.107 s), so the time itself is only fixed to about
    2.3 rtol / 1.14 = 2e-9 s (19 rtol relative): measured 4.6e-11 s on OpenBLAS's Haswell kernels and
    4.9e-10 s on Sandybridge, that is 0.02 and 0.24 of the bound on the ratio."""
    scene = _scene("Radau", 1e-9, 1e-11)
    summary = run_scene(scene, until=0.2, results=tmp_path / "r.h5", show_progress=False)
    res = read_results(tmp_path / "r.h5")
    t_event = res.stats["event_t"]
    assert res.stats["event_name"] == "ratio 2.3" and res.attrs["status"] == "finished"
    assert res.time[-1] == t_event and summary.simulated_time_s == t_event
    assert abs(res.series["ratio"][-1, 0] - 2.3) < 1e-12 * 2.3       # ends on its own crossing
    with h5py.File(tmp_path / "r.h5", "r") as f:
        assert np.array_equal(f["event.0.times"][()], [t_event]) and f["event.0.times"].attrs["unit"] == "s"
    _, same = _solve(scene, 0.2)
    assert same.status == 1 and same.t_events[0][0] == t_event
    before = t_event - np.array([1e-4, 5e-5])  # s, both before either crossing
    run, tight = _solve(_scene("Radau", 1e-11, 1e-13), 0.2, t_eval=before)
    ratio = [float(np.ravel(run.loop.outputs(t, x)["ratio"])[0]) for t, x in zip(tight.t, tight.y.T)]
    slope = (ratio[1] - ratio[0]) / (before[1] - before[0])  # 1/s
    assert tight.status == 1 and -1.2 < slope < -1.0
    assert abs(slope * (t_event - tight.t_events[0][0])) < 1e-9 * 2.3


def test_run_interrupted_before_the_event_resumes_bitwise(tmp_path):
    """Interrupted after the checkpoint preceding the event (t = 0.1 s, event at 0.1068 s): the resumed run
    ends at the same event time with the same series and counters."""
    scene = _scene("Radau", 1e-7, 1e-9, output={"checkpoint_interval": 0.01})
    ref = run_scene(scene, until=0.2, results=tmp_path / "ref.h5", show_progress=False)
    first = read_results(tmp_path / "ref.h5")
    before = int(first.stats["event_t"] // 0.01)
    _interrupted(scene, tmp_path / "r.h5", before, 0.2)
    res = resume_run(tmp_path / "r.h5", show_progress=False)
    again = read_results(tmp_path / "r.h5")
    assert 0 < again.stats["resumed_from_t"] < first.stats["event_t"]
    assert again.stats["event_t"] == first.stats["event_t"] and _series_equal(first, again)
    assert res.solver == ref.solver


def test_event_on_an_unknown_or_vector_output_is_refused():
    for output, rule in (("nope", "must be an output of this model"), ("power", "must be a scalar output")):
        scene = load_scene("band-4dof", {"solver": {"event": [{"output": output, "value": 1.0}]}})
        with pytest.raises(InputError, match=rule) as err:
            run_scene(scene, until=0.001, show_progress=False)
        assert err.value.where == "solver.event[0].output"
