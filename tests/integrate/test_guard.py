"""Run guards (issue 7): the growth guard in adaptive runs and through the scipy adapter, and the
local-error monitor of fixed-step runs, checked against closed forms."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cvtfem.errors import InputError
from cvtfem.integrate import CvtfemSolver, solve
from cvtfem.integrate.controller import error_norm
from cvtfem.integrate.guards import GrowthGuard

K = 1e14   # m/s^2 of a force switched on at T_ON


def switched(t_on: float):
    """``x' = K`` for ``t >= t_on``, else 0: the exact solution is ``1 + K (t - t_on)^+``."""
    return lambda t, y: np.full_like(y, K if t >= t_on else 0.0)


FOOLED = ("instability (dopri45): |x| grew by a factor 4.6e+13 in one accepted step (component 0), from 1 to "
          "4.6e+13 (more than growth_limit = 1e+08 times the largest |x| so far) at t = 1 s with adaptive step "
          "h = 1 s: the error estimate did not reject it (a blow-up, or a discontinuity the embedded estimate "
          "cannot see); tighten rtol/atol or limit the step (growth_limit=None disables this check)")


def test_adaptive_step_that_fools_the_error_estimate_is_stopped():
    """A force switched on at t = 0.5 inside a first step [0, 1] of DOPRI45: the stages at c >= 4/5 see it,
    and their embedded weights nearly cancel (sum of b - b_low over stages 4..7 is 0.003 against
    sum b = 0.46), so the step passes rtol = 1e-2 although it is 8 % off the exact 1 + K/2. The guard
    stops it: 4.6e13 in one accepted step against the largest |x| = 1 so far."""
    res = solve(switched(0.5), (0.0, 2.0), [1.0], method="dopri45", h=1.0, adaptive=True, rtol=1e-2)
    assert res.status == -1 and list(res.t) == [0.0]
    assert res.message == FOOLED
    off = solve(switched(0.5), (0.0, 2.0), [1.0], method="dopri45", h=1.0, adaptive=True, rtol=1e-2,
                growth_limit=None)
    assert off.status == 0 and off.t[1] == 1.0
    x1, exact = off.y[0, 1], 1 + K * 0.5
    assert abs(x1 - exact) / exact == pytest.approx(0.0808, abs=1e-3)   # accepted, 8x its rtol off
    # the same through the scipy adapter: a failed step with the same text
    sol = solve_ivp(switched(0.5), (0.0, 2.0), [1.0], method=CvtfemSolver, cvtfem_method="dopri45", rtol=1e-2,
                    first_step=1.0)
    assert sol.status == -1 and sol.message == FOOLED


def test_adapter_fixed_step_reports_instability():
    """CvtfemSolver with a fixed RK4 step far above the stability limit fails at the first step."""
    sol = solve_ivp(lambda t, y: -1e8 * y, (0.0, 0.01), [1.0], method=CvtfemSolver, cvtfem_method="rk4", h=1e-3)
    assert sol.status == -1
    assert sol.message.startswith("instability (rk4): |x| grew by a factor 4.17e+18 in one step (component 0)")
    assert sol.message.endswith("h is beyond the method's stability region; reduce h or use an implicit or "
                                "stabilized method (growth_limit=None disables this check)")
    with pytest.raises(InputError, match="`growth_limit` must be a number > 1"):
        CvtfemSolver(lambda t, y: -y, 0.0, [1.0], 1.0, cvtfem_method="rk4", h=0.1, growth_limit=1.0)


@pytest.mark.parametrize("method,rtol", [("dopri45", 1e-8), ("sw24", 1e-6), ("gbs", 1e-8)])
def test_legitimate_exponential_growth_runs_to_the_end(method, rtol):
    """y' = y over 60 s grows by e^60 = 1.1e26: spread over many accepted steps, each compared with the
    largest |y| so far, so the default guard never trips; the end value is the closed form (the global
    relative error of y' = y grows like t x the local one: 60 s x rtol x a few hundred steps' worth)."""
    res = solve(lambda t, y: y, (0.0, 60.0), [1.0], method=method, rtol=rtol, atol=1e-9)
    assert res.status == 0, res.message
    assert res.y[0, -1] == pytest.approx(math.exp(60.0), rel=1e4 * rtol)
    steps = np.diff(np.log(res.y[0]))
    assert steps.max() < math.log(1e8)   # the largest one-step growth, far below the limit


@pytest.mark.parametrize("method", ["dopri45", "gbs"])
def test_growth_towards_a_blow_up_is_not_an_instability(method):
    """y' = y^2 to t = 1 - 1e-6 (y = 1/(1 - t) reaches 1e6): correct, accurate, never tripped."""
    res = solve(lambda t, y: y * y, (0.0, 1 - 1e-6), [1.0], method=method, rtol=1e-8, atol=1e-12)
    assert res.status == 0, res.message
    assert res.y[0, -1] == pytest.approx(1e6, rel=1e-3)


def test_guard_reference_uses_slope_and_floor():
    """From rest the reference is max(|h F0|, atol): a start from x = 0 with a large force is fine."""
    g = GrowthGuard(1e8, np.zeros(2), 1e-9, "rk4", adaptive=False)
    assert g.check(np.zeros(2), np.array([0.0, 1e6 * 1e-3]), 1e-3, np.array([0.0, 1e6])) is None
    assert g.check(np.zeros(2), np.array([0.0, 1.0]), 1e-3, np.zeros(2)).startswith(
        "instability (rk4): |x| grew by a factor 1e+09 in one step (component 1), from 0 to 1")
    assert GrowthGuard(None, [1.0], 0.0, "rk4", False).check([1.0], [1e300], 1.0) is None


def _true_local_errors(method, h, n_steps):
    """Norms (absolute: atol 1e-6, rtol 1e-12) of the true one-step errors of ``method`` on x'' = -x along its path."""
    res = solve(lambda t, y: np.array([y[1], -y[0]]), (0.0, n_steps * h), [1.0, 0.0], method=method, h=h)
    c, s = math.cos(h), math.sin(h)
    out = []
    for j in range(1, res.y.shape[1]):
        x0, x1 = res.y[:, j - 1], res.y[:, j]
        exact = np.array([c * x0[0] + s * x0[1], -s * x0[0] + c * x0[1]])
        out.append(error_norm(x1 - exact, x0, x1, 1e-12, 1e-6))
    return np.array(out)


@pytest.mark.parametrize("method,h", [("rk4", 0.1), ("rk4", 0.4), ("euler", 0.01)])
def test_step_doubling_estimate_matches_the_true_local_error(method, h):
    """Linear oscillator x'' = -x: the local error of every step has the same size (the flow is a rotation),
    so in an absolute norm (atol 1e-6) the monitor's largest estimate must match the true local error within
    a factor 2; its cost is one step of 2h per ``error_check`` steps."""
    n, every = 100, 4
    true = _true_local_errors(method, h, n)
    res = solve(lambda t, y: np.array([y[1], -y[0]]), (0.0, n * h), [1.0, 0.0], method=method, h=h,
                error_check=every, rtol=1e-12, atol=1e-6)
    st = res.stats
    assert 0.5 < st["err_check_max"] / true.max() < 2.0, (st["err_check_max"], true.max())
    stages = 4 if method == "rk4" else 1
    assert st["nerr_checks"] == n // every and st["nfev_err_check"] == stages * n // every
    assert ("Warning: fixed step too large for the tolerance" in res.message) == (true.max() > 1)


def test_monitor_is_silent_within_tolerance_and_off_by_default():
    """RK4 at h = 0.01 on the oscillator: local error h^5/120 ~ 8e-13 < rtol 1e-6: no warning."""
    f = lambda t, y: np.array([y[1], -y[0]])   # noqa: E731
    res = solve(f, (0.0, 1.0), [1.0, 0.0], method="rk4", h=0.01, error_check=10)
    assert res.status == 0 and res.message == "The solver successfully reached the end of the integration interval."
    assert 0 < res.stats["err_check_max"] < 1e-3
    plain = solve(f, (0.0, 1.0), [1.0, 0.0], method="rk4", h=0.01)
    assert "nerr_checks" not in plain.stats and np.array_equal(plain.y, res.y)   # the check changes nothing


def test_embedded_estimate_costs_nothing():
    """DOPRI45 at a fixed step uses its embedded estimate on the checked steps only: no extra RHS call."""
    f = lambda t, y: np.array([y[1], -y[0]])   # noqa: E731
    res = solve(f, (0.0, 10.0), [1.0, 0.0], method="dopri45", h=0.5, error_check=5)
    plain = solve(f, (0.0, 10.0), [1.0, 0.0], method="dopri45", h=0.5)
    assert res.stats["nfev_err_check"] == 0 and res.stats["nfev"] == plain.stats["nfev"]
    assert res.stats["nerr_checks"] == 4 and np.array_equal(res.y, plain.y)
    assert res.stats["err_check_max"] > 1 and "Warning" in res.message
    with pytest.raises(InputError, match="`error_check` must be a whole number"):
        solve(f, (0.0, 1.0), [1.0, 0.0], method="rk4", h=0.1, error_check=-1)


@pytest.mark.parametrize("method", ["trapezoidal", "implicit-euler", "sw24"])
def test_embedded_check_of_implicit_methods_leaves_the_solution_unchanged(method):
    """Implicit and W-methods compute their estimate only on the checked steps (filtered through their
    current LU, no refactorisation): same states and LU count as without the check. The damped oscillator
    x'' = -1e4 x - 10 x' at h = 1e-3 (h omega = 0.1) is far outside rtol = 1e-6, so the check warns."""
    def f(t, y):
        return np.array([y[1], -1e4 * y[0] - 10 * y[1] + np.sin(50 * t)])

    checked = solve(f, (0.0, 0.1), [1.0, 0.0], method=method, h=1e-3, n2=1, error_check=5)
    plain = solve(f, (0.0, 0.1), [1.0, 0.0], method=method, h=1e-3, n2=1)
    assert np.array_equal(checked.y, plain.y) and checked.stats["nlu"] == plain.stats["nlu"]
    assert checked.stats["nerr_checks"] == 20 and checked.stats["nfev_err_check"] == 0
    assert checked.stats["err_check_max"] > 1 and "Warning: fixed step too large" in checked.message
