"""Test problems: analytic Jacobians, closed forms and friction laws are what they claim."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.integrate.base import Stepper
from cvtfem.integrate.jacobian import JacobianProvider
from cvtfem.integrate.system import as_system
from cvtfem import problems as P


@pytest.mark.parametrize("make,x", [(P.hires, np.linspace(0.1, 0.9, 8)), (P.limit_cycle, np.array([0.3, -0.7])),
                                    (P.van_der_pol, np.array([1.5, -0.4])), (P.oscillator, np.array([0.2, 1.0])),
                                    (lambda: P.van_der_pol_stiff(eps=1e-2), np.array([1.5, -0.4]))])
def test_analytic_jacobian_matches_finite_differences(make, x):
    p = make()
    J = np.asarray(p.jac(0.0, x))
    Jfd = JacobianProvider(Stepper(as_system(p.fun, x, n2=p.n2)))(0.0, x)
    assert np.allclose(J, Jfd, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("name", ["oscillator", "limit_cycle", "prothero_robinson"])
def test_closed_forms_solve_their_odes(name):
    p = P.PROBLEMS[name]()
    t, dt = 0.7, 1e-6
    deriv = (p.exact(t + dt) - p.exact(t - dt)) / (2 * dt)
    assert np.allclose(deriv, p.fun(t, p.exact(t)), rtol=1e-7, atol=1e-7)


def test_heat_semi_discrete_exact_solution():
    p = P.heat1d(N=50)
    t, dt = 0.01, 1e-7
    deriv = (p.exact(t + dt) - p.exact(t - dt)) / (2 * dt)
    assert np.allclose(deriv, p.fun(t, p.exact(t)), rtol=1e-6, atol=1e-6)
    assert abs(p.info["rho"] - 4 * 51 ** 2) < 1e-9


def test_pleiades_conserves_energy():
    p = P.pleiades()
    m = np.arange(1, 8.0)

    def energy(s):
        x, y, vx, vy = s[:7], s[7:14], s[14:21], s[21:]
        kin = 0.5 * np.sum(m * (vx ** 2 + vy ** 2))
        r = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
        iu = np.triu_indices(7, 1)
        return kin - np.sum((m[:, None] * m[None, :])[iu] / r[iu])
    res = solve(**p.solve_kwargs(), method="dopri78", rtol=1e-11, atol=1e-11)
    assert abs(energy(res.y[:, -1]) / energy(p.y0) - 1) < 1e-8


def test_friction_laws_continuity():
    """nonsmooth is C0 at v0; smooth is C1 at (1 +- eps) v0 (errata #3: not C2)."""
    f0, v0, eps = 0.3, 1e-3, 0.1
    f = lambda v, law: P.mechanics.friction_coefficient(v, f0, v0, law, eps)  # noqa: E731
    d = 1e-12
    assert abs(f(v0 - d, "nonsmooth") - f(v0 + d, "nonsmooth")) < 1e-8
    for vb in ((1 - eps) * v0, (1 + eps) * v0):
        assert abs(f(vb - d, "smooth") - f(vb + d, "smooth")) < 1e-8
        slope_l = (f(vb - d, "smooth") - f(vb - 1e-9, "smooth")) / (1e-9 - d)
        slope_r = (f(vb + 1e-9, "smooth") - f(vb + d, "smooth")) / (1e-9 - d)
        assert abs(slope_l - slope_r) < 1e-3 * f0 / v0
    with pytest.raises(InputError):
        P.sliding_point(law="cubic")


def test_bouncing_ball_closed_form_consistent_with_free_fall():
    p = P.bouncing_ball(x0=2.0, v0=1.0, g=9.81)
    t1 = p.info["impacts"](1)[0]
    assert abs(2.0 + 1.0 * t1 - 0.5 * 9.81 * t1 ** 2) < 1e-12


def test_robertson_jacobian_central_differences():
    """The right-hand side is quadratic, so central differences are exact up to round-off (forward
    differences are off by 3e7 * delta in the y2 column)."""
    p = P.robertson()
    y, d = np.array([0.7, 2e-5, 0.3]), 1e-6
    fd = np.column_stack([(p.fun(0, y + d * e) - p.fun(0, y - d * e)) / (2 * d) for e in np.eye(3)])
    assert np.allclose(p.jac(0.0, y), fd, rtol=1e-8, atol=1e-8)


def test_robertson_rhs_conserves_mass():
    """``y1 + y2 + y3`` is invariant: the right-hand side sums to zero (to round-off) anywhere."""
    p = P.robertson()
    for y in (np.array([1.0, 0, 0]), np.array([0.3, 3.6e-5, 0.7]), np.array([1e-8, 1e-13, 1.0])):
        f = p.fun(0.0, y)
        assert abs(f.sum()) <= 1e-12 * np.abs(f).max()
