"""Step-size control (issue 19): the floor relative to the current time, no growth after a
rejection, the PI controller."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.integrate.controller import (MAX_FACTOR, SAFETY, PIController, SimpleController, make_controller,
                                         step_floor)
from cvtfem.problems import heat1d, van_der_pol_stiff


def test_floor_is_relative_to_the_current_time():
    """16 spacings of doubles at t: tiny near t = 0 whatever the span's end, 16 eps |t| elsewhere."""
    assert step_floor(0.0) < 1e-300
    assert step_floor(1e-5) < 1e-19
    for t in (1.0, 3.7e4, 1e11):
        assert 8 * np.finfo(float).eps * t <= step_floor(t) <= 16 * np.finfo(float).eps * t
        assert t + step_floor(t) > t


def test_no_growth_right_after_a_rejection():
    """Hairer's facmax = 1: an accepted step after a rejected one keeps h even at a tiny error; the
    next accepted one may grow again (up to MAX_FACTOR)."""
    for ctrl in (SimpleController(), PIController()):
        ok, h1 = ctrl.propose(1.0, 4.0, 3)
        assert not ok and h1 < 1.0
        ok, h2 = ctrl.propose(h1, 1e-8, 3)
        assert ok and h2 == h1
        ok, h3 = ctrl.propose(h2, 1e-8, 3)
        assert ok and h3 == pytest.approx(MAX_FACTOR * h2)


def test_pi_controller_tames_step_oscillation_at_the_stability_limit():
    """dopri45 on a mildly stiff heat equation runs at its stability boundary, where the elementary
    controller alternates accept/reject (94 rejections in 572 steps); the PI controller (Gustafsson)
    smooths the step sequence: under a tenth of the rejections (2), fewer RHS calls, a steadier log h,
    the same accuracy."""
    p = heat1d(N=30, t_end=0.5)
    runs = {c: solve(**p.solve_kwargs(), method="dopri45", rtol=1e-4, atol=1e-7, controller=c) for c in ("i", "pi")}
    rough = {c: np.std(np.diff(np.log(np.diff(r.t)))) for c, r in runs.items()}
    assert runs["pi"].stats["nreject"] < runs["i"].stats["nreject"] / 10
    assert runs["pi"].stats["nfev"] < runs["i"].stats["nfev"]
    assert rough["pi"] < rough["i"]
    ex = p.exact(0.5)
    for r in runs.values():
        assert np.max(np.abs(r.y[:, -1] - ex)) < 1e-4 * np.max(np.abs(ex)) * 10


def test_unknown_controller_is_an_input_error():
    with pytest.raises(InputError):
        make_controller("pid")
    with pytest.raises(InputError):
        solve(lambda t, y: -y, (0, 1), [1.0], method="dopri45", controller="pid")


def test_underflow_message_names_t_h_floor_and_cause():
    """y' = y^2, y(0) = 1 blows up at t = 1: the run stops just before it with a message naming the
    time, the last step, the floor and the likely causes."""
    res = solve(lambda t, y: y * y, (0.0, 2.0), [1.0], method="sw24", rtol=1e-6, atol=1e-9,
                jac=lambda t, y: np.array([[2 * y[0]]]))
    assert res.status == -1 and 0.99 < res.t[-1] < 1.0
    msg = res.message
    assert msg.startswith("step size underflow (h = ") and " s) at t = " in msg
    assert "floor" in msg and "singularity" in msg


def test_accepted_step_near_tolerance_shrinks_h():
    """An accepted step with error 0.9 proposes a smaller h (Hairer: facmin..facmax on acceptance), so a
    slowly growing error does not make every other step a rejection."""
    ok, h = SimpleController().propose(1.0, 0.9, 3)
    assert ok and h == pytest.approx(0.9 * 0.9 ** -0.25)


def test_the_quantum_holds_h_except_up_to_the_methods_cap():
    """A proposed growth below the quantum keeps h (the LU or first stage stays valid), unless the grown step would
    reach the method's largest step: then h grows, so a run cannot stay stuck just below its cap."""
    err = (SAFETY / 1.1) ** 4                           # factor 1.1 for q = 3
    ctrl = SimpleController(quantum=1.2)
    assert ctrl.propose(1.0, err, 3) == (True, 1.0)
    ok, h = ctrl.propose(1.0, err, 3, cap=1.05)
    assert ok and h == pytest.approx(1.1)


def test_predictive_controller_on_van_der_pol_transients():
    """Van der Pol (eps = 1e-6) approaches its fast transients with an error that grows 2.7x per step at
    constant h: the elementary controller then rejects every other step, Gustafsson's predictive one
    (rodas4's default) follows the trend: under a fifth of the rejections, the same end state."""
    p = van_der_pol_stiff(1e-6)
    runs = {c: solve(**p.solve_kwargs(), method="rodas4", rtol=1e-4, atol=1e-4, controller=c)
            for c in ("i", "predictive")}
    assert runs["predictive"].stats["nreject"] < runs["i"].stats["nreject"] / 5
    assert np.allclose(runs["predictive"].y[:, -1], runs["i"].y[:, -1], rtol=1e-3)
