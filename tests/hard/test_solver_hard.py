"""Solver edges (issue 7): a fixed step far above the stability limit, Newton divergence,
step-size underflow, a singular or ill-conditioned mass matrix.

Each case ends in a clear failure with a closed-form explanation: the failure time, the
failure kind and the returned (finite) part of the solution are checked against analytic values.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cvtfem.errors import InputError, NumericalError
from cvtfem.integrate import solve
from cvtfem.modal import ModalProblem

pytestmark = pytest.mark.hard

LAM = -1e8          # 1/s, the friction eigenvalue of spec numerics §11.6


def rk4_factor(z: float) -> float:
    """Stability function of RK4, ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``."""
    return 1 + z + z * z / 2 + z ** 3 / 6 + z ** 4 / 24


@pytest.mark.timeout(60)
def test_fixed_step_far_above_the_stability_limit_stops_at_overflow():
    """RK4 at h = 1e-3 s on y' = -1e8 y (h lambda = -1e5, limit -2.785): |y| grows by R(z) = 4.2e18
    per step, exactly as the amplification factor says, and the run stops with status -1 at the
    first non-finite state (step 17, since 17 log10 R > 308), returning only finite values.
    This is the behaviour with the growth guard disabled (``growth_limit=None``); by default the
    run stops after the first step (next test)."""
    h = 1e-3
    R = rk4_factor(LAM * h)
    n_overflow = math.ceil(math.log(np.finfo(float).max) / math.log(R))
    res = solve(lambda t, y: LAM * y, (0.0, 1.0), [1.0], method="rk4", h=h, growth_limit=None)
    assert res.status == -1 and not res.success
    assert res.message == f"non-finite state in component 0 at t = {n_overflow * h:.6g} s with fixed step h = 0.001 s"
    assert len(res.t) == n_overflow and np.all(np.isfinite(res.y))
    assert np.allclose(res.y[0], R ** np.arange(n_overflow), rtol=1e-12)
    with pytest.raises(NumericalError, match="non-finite state in component 0") as err:
        solve(lambda t, y: LAM * y, (0.0, 1.0), [1.0], method="rk4", h=h, growth_limit=None,
              raise_on_failure=True)
    assert err.value.t == pytest.approx((n_overflow - 1) * h) and err.value.component == "rk4"


INSTABILITY = ("instability (rk4): |x| grew by a factor 4.17e+18 in one step (component 0), from 1 to 4.17e+18 "
               "(more than growth_limit = 1e+08 times the largest |x| so far) at t = 0.001 s with "
               "fixed step h = 0.001 s: h is beyond the method's stability region; reduce h or use an "
               "implicit or stabilized method (growth_limit=None disables this check)")


def test_fixed_step_instability_is_reported_by_default():
    """Issue 7: 'detected and reported, not silently diverging'. RK4 at h = 1e-3 s on
    y' = -1e8 y to t = 0.01 s (ten steps, 4e185 at the end, below overflow) used to return
    status 0; the default growth guard (growth_limit = 1e8) stops it after the first step,
    naming the method, t, h and the amplification R(-1e5) = 4.17e18, with the hint."""
    R = rk4_factor(LAM * 1e-3)
    assert R == pytest.approx(4.16650e18, rel=1e-5)
    res = solve(lambda t, y: LAM * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3)
    assert res.status == -1 and not res.success and list(res.t) == [0.0]
    assert res.message == INSTABILITY
    factor = float(res.message.split("by a factor ")[1].split()[0])
    assert factor == pytest.approx(R, rel=1e-3)
    with pytest.raises(NumericalError, match=r"instability \(rk4\)") as err:
        solve(lambda t, y: LAM * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3, raise_on_failure=True)
    assert err.value.t == 0.0 and err.value.component == "rk4"
    # without the guard the ten steps reach R^10 = 1.6e186 and report success
    off = solve(lambda t, y: LAM * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3, growth_limit=None)
    assert off.status == 0 and off.y[0, -1] == pytest.approx(R ** 10, rel=1e-12)


def test_growth_guard_keeps_stable_and_growing_runs():
    """The guard compares one step with the largest state so far, not with the start: a stable
    stiff-ish step (h lambda = -0.1) and a legitimately growing solution (y' = 20 y, e^20 = 4.9e8
    over the run, growth 1.22 per step) run to the end with the RK4 closed form R(z)^n; a start
    from rest (y = 0) driven by a large force is not an instability either."""
    ok = solve(lambda t, y: -100.0 * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3)
    assert ok.status == 0
    assert ok.y[0, -1] == pytest.approx(rk4_factor(-0.1) ** 10, rel=1e-12)
    grow = solve(lambda t, y: 20.0 * y, (0.0, 1.0), [1.0], method="rk4", h=1e-2)
    assert grow.status == 0 and grow.y[0, -1] > 1e8
    assert grow.y[0, -1] == pytest.approx(rk4_factor(0.2) ** 100, rel=1e-12)
    # from rest, x'' = 1e6 (constant force): exact for RK4, u = 5e5 t^2, v = 1e6 t
    rest = solve(lambda t, y: np.array([y[1], 1e6]), (0.0, 0.01), [0.0, 0.0], method="rk4", h=1e-3)
    assert rest.status == 0
    assert rest.y[:, -1] == pytest.approx([5e5 * 0.01 ** 2, 1e6 * 0.01], rel=1e-12)


def test_growth_limit_reports_the_unstable_fixed_step_at_once():
    """An explicit ``growth_limit`` works like the default; a limit so large that no finite
    step exceeds it leaves the overflow check; invalid limits are input errors."""
    res = solve(lambda t, y: LAM * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3, growth_limit=1e8)
    assert res.status == -1 and list(res.t) == [0.0]
    assert res.message == INSTABILITY
    # every step grows by R = 4.17e18 against the largest state so far (the previous one), and
    # the reference also holds |h F0| = 1e5 |y|: a limit of 1e19 never trips, the run ends at R^10
    res = solve(lambda t, y: LAM * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3, growth_limit=1e19)
    assert res.status == 0 and res.y[0, -1] == pytest.approx(rk4_factor(LAM * 1e-3) ** 10, rel=1e-12)
    with pytest.raises(InputError, match="`growth_limit` must be a number > 1"):
        solve(lambda t, y: -y, (0.0, 1.0), [1.0], method="rk4", h=0.1, growth_limit=0.5)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("newton", ["const", "exact", "broyden"])
def test_newton_divergence_refreshes_then_fails_clearly(newton):
    """Implicit Euler on y' = y^2, y(0) = 1 with h = 2: G(y) = y - 1 - 2 y^2 has no real root
    (discriminant 1 - 8 < 0), so no Newton variant can converge: the run must stop at the first
    step with a message naming the variant, the residual, the time and the step."""
    res = solve(lambda t, y: y * y, (0.0, 4.0), [1.0], method="implicit-euler", h=2.0, newton=newton)
    assert res.status == -1
    assert res.message.startswith(f"Newton ({newton}) diverged: |G| = ")
    assert res.message.endswith("at t = 2 s with fixed step h = 2 s")
    # |G| can never drop below min over y of (2 y^2 - y + 1) = 7/8
    g_min = float(res.message.split("|G| = ")[1].split()[0])
    assert g_min >= 0.875 * (1 - 1e-3)
    assert res.stats["nnewton_fail"] == 1 and list(res.t) == [0.0]
    if newton != "exact":
        assert res.stats["njac_refresh"] == 1
    with pytest.raises(NumericalError, match="diverged"):
        solve(lambda t, y: y * y, (0.0, 4.0), [1.0], method="implicit-euler", h=2.0, newton=newton,
              raise_on_failure=True)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method, rtol", [("dopri45", 1e-8), ("trapezoidal", 1e-6), ("sw24", 1e-6)])
def test_step_size_underflow_at_a_finite_time_blow_up(method, rtol):
    """y' = y^2, y(0) = 1 blows up at t = 1 (y = 1/(1 - t)): adaptive runs shrink h until it
    underflows just before t = 1 and report it; everything returned follows the exact solution."""
    res = solve(lambda t, y: y * y, (0.0, 2.0), [1.0], method=method, rtol=rtol, atol=1e-2 * rtol)
    assert res.status == -1 and res.message.startswith("step size underflow (h = ")
    t_end = res.t[-1]
    assert 1.0 - 1e-3 < t_end <= 1.0 + 1e-8
    assert f"at t = {t_end:.6g} s" in res.message
    assert np.all(np.isfinite(res.y))
    # local errors grow along the variational equation d' = 2 y d, so the relative global error
    # grows like y = 1/(1-t); it stays below 1e3 rtol y (measured: 0.06 (dopri45), 77 (trapezoid),
    # 64 (sw24) rtol y)
    early = res.t < 0.999
    y_exact = 1 / (1 - res.t[early])
    assert np.all(np.abs(res.y[0, early] / y_exact - 1) <= 1e3 * rtol * y_exact)



@pytest.mark.timeout(60)
@pytest.mark.parametrize("method", ["rkc", "rock2", "rock4", "dumka3"])
def test_stabilized_methods_at_a_finite_time_blow_up(method):
    """y' = y^2 with the stabilized methods: the power iteration near the pole once returned NaN (RKC
    crashed with a raw ValueError) and divided by zero on one equation; now a non-finite estimate is a
    rejected attempt and the run ends in a reported step-size underflow. Their error estimates accept a
    last step just across the pole (measured t_end - 1: 1.1e-6 ROCK2, 1.5e-6 ROCK4, 7e-7 DUMKA3, 7.3e-5
    RKC at rtol 1e-6), so t_end is bounded by 1e-4, not by round-off as for DOPRI45."""
    rtol = 1e-6
    with np.errstate(all="raise"):
        res = solve(lambda t, y: y * y, (0.0, 2.0), [1.0], method=method, rtol=rtol, atol=1e-2 * rtol)
    assert res.status == -1 and res.message.startswith("step size underflow (h = ")
    assert 1.0 - 1e-3 < res.t[-1] < 1.0 + 1e-4 and np.all(np.isfinite(res.y))
    early = res.t < 0.999
    y_exact = 1 / (1 - res.t[early])
    assert np.all(np.abs(res.y[0, early] / y_exact - 1) <= 1e3 * rtol * y_exact)


@pytest.mark.parametrize("method", ["rkc", "rock2", "rock4", "dumka3"])
def test_stabilized_methods_on_one_growing_equation(method):
    """y' = y (positive eigenvalue, one equation): F and the power iteration's rough start vector may
    cancel exactly; the estimate falls back to the rough vector (no division by zero) and the run
    follows e^t."""
    with np.errstate(all="raise"):
        res = solve(lambda t, y: y, (0.0, 5.0), [1.0], method=method, rtol=1e-6)
    assert res.success and abs(res.y[0, -1] / np.exp(5.0) - 1) < 1e-3


def test_invalid_step_sizes_are_input_errors():
    for h in (0.0, -1e-3, math.nan, math.inf):
        with pytest.raises(InputError, match="`h` must be a positive step size in s"):
            solve(lambda t, y: -y, (0.0, 1.0), [1.0], method="rk4", h=h)


def _chain(n: int, k: float = 1e4) -> np.ndarray:
    """Stiffness of n masses in a fixed-fixed spring chain (springs k)."""
    return k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))


@pytest.mark.parametrize("m_last", [0.0, -1.0])
def test_singular_or_indefinite_mass_matrix_is_a_clear_modal_error(m_last):
    n = 4
    M = np.diag([1.0, 1.0, 1.0, m_last])
    Z = np.zeros((n, n))
    prob = ModalProblem(M, _chain(n), Z, Z, np.full(n, 2))
    with pytest.raises(NumericalError, match=r"mass matrix is not positive definite \(a DOF without inertia\?\)"):
        prob.solve(0.0, 3)


def test_ill_conditioned_mass_matrix_keeps_the_physical_modes():
    """A DOF 1e-6 as heavy as the others (cond(M) = 1e6): the three low modes converge to those of
    the statically condensed chain (the light DOF follows x4 = x3 / 2), the fourth is
    sqrt(2 k / m4) ~ 1.41e5 rad/s."""
    n, k, m4 = 4, 1e4, 1e-6
    M = np.diag([1.0, 1.0, 1.0, m4])
    Z = np.zeros((n, n))
    modes = ModalProblem(M, _chain(n, k), Z, Z, np.full(n, 2)).solve(0.0, 4)      # axial DOFs
    K = _chain(n, k)
    Kc = K[:3, :3] - np.outer(K[:3, 3], K[3, :3]) / K[3, 3]      # static condensation
    w_condensed = np.sqrt(np.linalg.eigvalsh(Kc))
    assert np.allclose(modes.wd[:3], w_condensed, rtol=1e-5)
    assert modes.wd[3] == pytest.approx(math.sqrt(2 * k / m4), rel=1e-3)


def test_unpaired_lateral_dofs_are_an_input_error():
    """Whirl classification pairs u1 with u2 (and theta1 with theta2): four u1 DOFs without
    partners used to crash inside the whirl code with a numpy broadcasting ValueError."""
    n = 4
    Z = np.zeros((n, n))
    with pytest.raises(InputError, match="`dof_kind`.*must pair every lateral DOF"):
        ModalProblem(np.eye(n), _chain(n), Z, Z, np.zeros(n, int))
