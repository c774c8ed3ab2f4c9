"""solve(): argument validation, option warnings, counters, t_eval, scipy bridge."""
import numpy as np
import pytest

from cvtfem.errors import InputError, NumericalError
from cvtfem.integrate import IgnoredOptionWarning, solve
from cvtfem.problems import heat1d, oscillator


def test_result_shape_and_stats_like_solve_ivp():
    p = oscillator()
    res = solve(**p.solve_kwargs(), method="dopri45", rtol=1e-8, atol=1e-10, t_eval=np.linspace(0, 10, 11))
    assert res.success and res.status == 0 and res.y.shape == (2, 11)
    assert np.allclose(res.t, np.linspace(0, 10, 11))
    # dense output (cubic Hermite) is accurate to O(h^4) between steps
    assert np.max(np.abs(res.y - np.array([p.exact(t) for t in res.t]).T)) < 1e-5
    for key in ("nfev", "njev", "nlu", "nsolve", "nsteps", "nreject", "nnewton", "nevents", "t_total"):
        assert key in res.stats
    # DOPRI45 is FSAL: 6 new RHS calls per attempted step (+ initial-step selection)
    st = res.stats
    assert st["nfev"] <= 6 * (st["nsteps"] + st["nreject"]) + 3


@pytest.mark.parametrize("kw,where", [
    (dict(method="nope"), "method"), (dict(h=-1.0), "h"), (dict(t_span=(1.0, 0.0)), "t_span"),
    (dict(y0=[np.nan, 0.0]), "y0"), (dict(method="rk4"), "method"),
    (dict(method="dumka3", h=0.1, stages=10), "stages"), (dict(method="rk4", h=0.1, bogus=1), "bogus"),
    (dict(method="theta", h=0.1, alpha=2.0), "alpha"), (dict(method="trapezoidal", h=0.1, newton="x"), "newton"),
])
def test_bad_input_names_the_argument(kw, where):
    p = oscillator()
    args = {**p.solve_kwargs(), **kw}
    with pytest.raises(InputError) as err:
        solve(**args)
    assert f"`{where}`" in str(err.value)


def test_ignored_option_warns():
    p = oscillator()
    with pytest.warns(IgnoredOptionWarning, match="`d`"):
        solve(**p.solve_kwargs(), method="rk4", h=0.1, d=0.5)
    with pytest.warns(IgnoredOptionWarning, match="`jac_sparsity`"):
        solve(p.fun, p.t_span, p.y0, method="RK45", jac_sparsity=np.ones((2, 2)))


def test_scipy_bridge_same_result_type_and_counts():
    p = oscillator()
    res = solve(p.fun, p.t_span, p.y0, method="DOP853", rtol=1e-10, atol=1e-12)
    assert res.success and res.method == "DOP853"
    assert np.max(np.abs(res.y[:, -1] - p.exact(10.0))) < 1e-8
    assert res.stats["nfev"] > 0 and res.stats["nsolve"] == -1


def test_fixed_step_blow_up_is_a_failure_status_not_nan():
    """Explicit Euler beyond its stability limit on the heat equation: non-finite -> status -1."""
    p = heat1d(N=50, t_end=10.0)
    res = solve(**p.solve_kwargs(), method="euler", h=1e-2)
    assert res.status == -1 and "non-finite" in res.message
    assert np.all(np.isfinite(res.y))
    with pytest.raises(NumericalError):
        solve(**p.solve_kwargs(), method="euler", h=1e-2, raise_on_failure=True)


def test_fixed_steps_hit_the_end_exactly():
    p = oscillator(t_end=1.0)
    res = solve(**p.solve_kwargs(), method="rk4", h=0.1)
    assert res.t[-1] == 1.0 and len(res.t) == 11 and res.stats["nfev"] == 40


def test_growth_limit_reports_instability_before_overflow():
    """RK4 at h = 1e-3 on y' = -1e8 y: |R| = 4.2e18 per step. The default ``growth_limit`` (1e8)
    reports the first step as an instability; with ``growth_limit=None`` the 10 steps stay below
    overflow and the run ends normally at R^10 (no guard left)."""
    z = -1e8 * 1e-3
    R = 1 + z + z * z / 2 + z ** 3 / 6 + z ** 4 / 24
    for kw in ({}, {"growth_limit": 1e8}):
        res = solve(lambda t, y: -1e8 * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3, **kw)
        assert res.status == -1 and res.message.startswith("instability (rk4)") and len(res.t) == 1
    res = solve(lambda t, y: -1e8 * y, (0.0, 0.01), [1.0], method="rk4", h=1e-3, growth_limit=None)
    assert res.status == 0 and np.all(np.isfinite(res.y))
    assert res.y[0, -1] == pytest.approx(R ** 10, rel=1e-12)
