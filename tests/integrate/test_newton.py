"""Theta-method and its Newton family (spec §4.2-4.3, §12 case 6)."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.problems import coupled_oscillators, sliding_point, van_der_pol

VARIANTS = ["exact", "const", "broyden", "fake-broyden", "hart", "trim"]


@pytest.mark.parametrize("variant", VARIANTS)
def test_newton_variants_agree_at_convergence(variant):
    """All variants solve the same step equations, so trajectories agree to the Newton tolerance."""
    p = van_der_pol(mu=5.0, t_end=1.0)
    ref = solve(**p.solve_kwargs(), method="trapezoidal", h=5e-3, newton="exact")
    res = solve(**p.solve_kwargs(), method="trapezoidal", h=5e-3, newton=variant, trim_threshold=1e-6)
    assert res.success
    assert np.max(np.abs(res.y[:, -1] - ref.y[:, -1])) < 1e-7
    st = res.stats
    if variant == "exact":
        assert st["njev"] == st["nlu"] >= st["nsteps"]
    if variant in ("const", "hart"):   # hart updates its factors instead of refactorising
        assert st["njev"] < st["nsteps"] / 10 and st["nlu"] < st["nsteps"] / 10


@pytest.mark.parametrize("variant", ["const", "hart", "fake-broyden"])
def test_trapezoid_matches_reference_on_second_order_system(variant):
    """Velocity-only Newton system (2.17) with u eliminated, sparse (80 unknowns > DENSE_MAX):
    compare with DOP853."""
    p = coupled_oscillators(n=80, t_end=2.0)
    res = solve(**p.solve_kwargs(), method="trapezoidal", h=2e-3, newton=variant)
    ref = solve(p.fun, p.t_span, p.y0, method="DOP853", rtol=1e-12, atol=1e-12)
    err = np.max(np.abs(res.y[:, -1] - ref.y[:, -1]))
    assert err < 2e-5
    # the reduced unknowns are the 80 velocities: LU size n - n2, Jacobian by 3 colours
    assert res.stats["nfev_jac"] % 3 == 0


def test_trapezoid_is_a_stable_stiff_solver_on_sliding_point():
    """Stick phase: dF_v/dv = -3000 1/s; trapezoid at h = 1e-3 (explicit limit ~7e-4)."""
    p = sliding_point(law="smooth", t_end=0.5)
    res = solve(**p.solve_kwargs(), method="trapezoidal", h=1e-3)
    ref = solve(**p.solve_kwargs(), method="Radau", rtol=1e-10, atol=1e-12)
    assert res.success and np.max(np.abs(res.y[:, -1] - ref.y[:, -1])) < 1e-3


def test_newton_divergence_fails_loudly():
    """A huge step on a stiff nonlinear problem: Newton diverges, the fixed-step run reports it."""
    p = van_der_pol(mu=1000.0, t_end=3000.0)
    res = solve(**p.solve_kwargs(), method="trapezoidal", h=1000.0, newton="const",
                newton_max_iter=3)
    if not res.success:
        assert "Newton" in res.message and "diverged" in res.message
    assert res.stats["njac_refresh"] >= 1 or res.stats["nnewton_fail"] >= 1
