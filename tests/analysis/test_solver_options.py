"""The scene key ``solver.options``: a method's own options reach its stepper through ``cvtfem run``; an option the
method does not take, a malformed pair or a bad value is an InputError naming the key, before any results file."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.errors import InputError
from cvtfem.integrate.methods import parse_options
from cvtfem.scene.loader import load_scene


def _gbs(options, tmp_path=None):
    scene = load_scene("band-4dof", {"solver": {"method": "gbs", "h": 2e-5, "options": options}})
    return run_scene(scene, until=0.004, show_progress=False,
                     results=None if tmp_path is None else tmp_path / "r.h5")


def test_options_reach_the_method():
    """GBS extrapolates over 4 stages by default (17 RHS calls a step); with ``stages=2`` it takes 5 a step and its
    run differs (within its lower order's error), and ``stages=4`` is the default run bit for bit."""
    default, two, four = _gbs([]), _gbs(["stages=2"]), _gbs(["stages=4"])
    steps = default.solver["steps"]
    assert default.solver["nfev"] == 1 + 17 * steps and two.solver["nfev"] == 1 + 5 * steps
    assert four.solver["nfev"] == default.solver["nfev"] and four.ratio == default.ratio
    assert two.ratio != default.ratio and two.ratio == pytest.approx(default.ratio, rel=2e-3)


@pytest.mark.parametrize("options, value, rule", [
    (["scheme=imex-rk4"], "scheme=imex-rk4", "must be an option of 'gbs': sequence, stages"),
    (["stages"], "stages", "options must be key=value"),
    (["sequence=fibonacci"], "sequence=fibonacci", "sequence"),
])
def test_bad_options_are_input_errors_before_any_results(tmp_path, options, value, rule):
    with pytest.raises(InputError) as err:
        _gbs(options, tmp_path)
    assert err.value.where == "solver.options" and err.value.value == value and rule in str(err.value)
    if err.value.value != "sequence=fibonacci":       # the value is the method's to judge: at its construction
        assert not (tmp_path / "r.h5").exists()


def test_scipy_methods_take_no_options():
    scene = load_scene("band-4dof", {"solver": {"method": "RK45", "options": ["first_step=1e-6"]}})
    with pytest.raises(InputError, match="`solver.options` must be an option of 'RK45': it takes none"):
        run_scene(scene, until=0.001, show_progress=False)


def test_parse_options_converts_numbers_and_booleans():
    assert parse_options(["stages=2", "d=0.5", "proportional=False", "scheme=imex-rk4"], "x") == {
        "stages": 2, "d": 0.5, "proportional": False, "scheme": "imex-rk4"}
    with pytest.raises(InputError, match="`x` options must be key=value"):
        parse_options(["=2"], "x")


@pytest.mark.slow
@pytest.mark.timeout(900)
@pytest.mark.parametrize("scheme, bound", [("imex-rk4", 1e-5), ("multirate-rk4", 1e-4), ("preset", 1e-4)])
def test_a_run_with_strang_friction_options_resumes(tmp_path, scheme, bound):
    """Variant (e) on rigid shafts with all friction split off (``strang-friction``, ``scheme``, ``friction=all``, the
    options through the scene): the checkpoint layout is built with the run's split and options, and a run killed at
    30 us and resumed to 60 us follows the uninterrupted run's series within ``bound`` of each series' largest value.
    Not bit for bit: imex-rk4's friction solve starts its Newton from the previous solve's friction acceleration, which
    a checkpoint does not keep, and stops at slip changes below ``ChainHalvesCVT.FRICTION_TOL`` v0 (its chord-step end:
    within 1e-5, 3e-7 before the chord step of session 15); multirate-rk4 restarts its stiffness bound's power iteration
    and builds the first stage's friction set from the positions instead of carrying the last step's (found 2.1e-5, the
    friction power).  ``preset``: the preset's own solver, multirate-rk4 adaptive below its cap (session 19), which
    also restarts its first stage (the last step's end rate is not kept) and continues from the checkpoint's step
    size and controller memory."""
    from cvtfem.analysis.run import resume_run
    from cvtfem.io.results import read_results

    solver = {} if scheme == "preset" else {"solver": {"method": "strang-friction",
                                                      "options": [f"scheme={scheme}", "friction=all"], "h": 2e-6}}
    scene = load_scene("variant-e,regime-chapter2,chain-uniform", {
        "cvt": {"effects": {"shaft_elasticity": False}}, **solver,
        "output": {"step": 1e-5, "checkpoint_interval": 2e-5}})
    run_scene(scene, until=6e-5, results=tmp_path / "full.h5", show_progress=False)
    run_scene(scene, until=3e-5, results=tmp_path / "part.h5", show_progress=False)
    resume_run(tmp_path / "part.h5", until=6e-5, show_progress=False)
    full, part = read_results(tmp_path / "full.h5"), read_results(tmp_path / "part.h5")
    assert np.array_equal(full.time, part.time) and len(full.time) == 7
    for name, a in full.series.items():
        a, b = np.asarray(a), np.asarray(part.series[name])
        assert np.abs(a - b).max() <= bound * np.abs(a).max(), name
