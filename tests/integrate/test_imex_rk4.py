"""The IMEX schemes of strang-friction (``imex-rk4``, ``imex-rk4-2``: RK4 on ``f_E``, a stiffly accurate ESDIRK on
``f_I`` through the system's backward-Euler solve): order 2 on a damped oscillator with its damping as ``f_I``
against the closed form, the stiff limit (damping 1e8 times the step's inverse) stable and on the slow manifold, and
on the stiff tanh friction of test_imex.py convergence to the unsplit solution with the energy balance closing."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.integrate.imex import IMEX_RK4_IMPLICIT
from cvtfem.integrate.system import OdeSystem, StiffSplit
from tests.integrate.test_imex import SYSTEM, X0, assert_balance
from tests.integrate.test_imex import reference  # noqa: F401 - the fixture

SCHEMES = tuple(IMEX_RK4_IMPLICIT)
W2 = 9.0                                                # 1/s^2: the spring


def oscillator(g):
    """``u'' = -W2 u - g u'`` split as ``f_E = (v, -W2 u)``, ``f_I = (0, -g v)`` (its backward Euler in closed
    form; ``hold``: the held acceleration, no work row)."""
    def explicit(t, x):
        return np.array([x[1], -W2 * x[0]])

    def solve_I(t, x, h):
        return np.array([x[0], x[1] / (1 + h * g)]), 1

    def hold(x, d):
        return np.array([0.0, d[1]])

    return OdeSystem(fun=lambda t, x: np.array([x[1], -W2 * x[0] - g * x[1]]), n=2, n2=1,
                     split=StiffSplit(explicit, solve_I, hold))


def exact(g, t):
    """``u(t)`` from ``u = 1, u' = 0`` (underdamped)."""
    w = np.sqrt(W2 - g * g / 4)
    return np.exp(-g * t / 2) * (np.cos(w * t) + g / (2 * w) * np.sin(w * t))


@pytest.mark.parametrize("scheme", SCHEMES)
def test_order_two_on_a_damped_oscillator(scheme):
    hs = [0.02 / 2 ** k for k in range(4)]
    errs = [abs(solve(oscillator(1.5), (0.0, 2.0), np.array([1.0, 0.0]), method="strang-friction", h=h,
                      scheme=scheme).y[0, -1] - exact(1.5, 2.0)) for h in hs]
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 1.9 < order < 2.2, (errs, order)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_stiff_damping_is_stable_and_on_the_slow_manifold(scheme):
    """``g = 1e6``, ``h = 0.01``: ``h g = 1e4``; the overdamped solution creeps as ``u' = -W2 u / g``; the step's
    stiff part is damped out (``R(inf) = 0``): ``|u'|`` stays at the slow manifold's ``W2 u / g``."""
    g = 1e6
    y = solve(oscillator(g), (0.0, 1.0), np.array([1.0, 0.0]), method="strang-friction", h=0.01, scheme=scheme).y
    u = y[0, -1]
    assert u == pytest.approx(np.exp(-W2 / g), rel=1e-6)
    assert abs(y[1, -1]) <= 2 * W2 / g


@pytest.mark.parametrize("scheme", SCHEMES)
def test_stiff_friction_converges_and_closes_the_energy_balance(reference, scheme):  # noqa: F811
    """The tanh friction of test_imex.py (``|lambda| = 2e5`` 1/s) at steps 80 down to 0.6 times its explicit limit:
    the errors (m, m/s) fall from about 1e-3 to below 2e-6, at a fitted order above 1.2 (the stick-slip kinks scatter
    the single ratios, and the stiff steps reduce the order: 6.9e-4, 4.3e-4, 5.3e-4, 1.1e-4, 3.3e-5, 5.1e-6, 6.2e-6,
    8.2e-7 for imex-rk4); the drive's work = stored energy change + booked dissipation (the stages' friction rates
    carry the power of their forces) to test_imex.py's bound."""
    hs = [4e-4 / 2 ** k for k in range(8)]
    errs = [np.abs(solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", h=h, scheme=scheme).y[:2, -1]
                   - reference[:2]).max() for h in hs]
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert order > 1.2 and errs[-1] < 2e-6 and max(errs) < 2e-3, (errs, order)
    assert_balance(scheme)
