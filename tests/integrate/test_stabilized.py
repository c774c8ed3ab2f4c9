"""RKC: stability length, spectral-radius estimate, automatic stage selection (spec §11.6)."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.integrate.base import Stepper
from cvtfem.integrate.stabilized import _chebyshev, rkc_stability_length, spectral_radius
from cvtfem.integrate.study import amplification, real_stability_length, select_stages
from cvtfem.integrate.system import as_system
from cvtfem.problems import heat1d


@pytest.mark.parametrize("s", [10, 20, 50])
def test_rkc_stability_length_matches_published(s):
    """Measured by stepping x' = -x x for a grid of x: beta(s) ~ 0.653 s^2 (Sommeijer, Shampine
    & Verwer 1997, eps = 2/13) within 1 %."""
    beta = real_stability_length("rkc", x_max=0.8 * s * s, n=20 * s * s, stages=s)
    assert abs(beta / (0.653 * s * s) - 1) < 0.01
    assert beta >= rkc_stability_length(s) * (1 - 1e-9)   # the analytic end point is inside


def test_rkc_damping_inside_the_interval():
    """Where ``w0 + w1 z`` lies in [-1, 1], ``|R| <= a_s + b_s < 1`` (damping eps = 2/13)."""
    s = 10
    w0 = 1 + (2 / 13) / s ** 2
    T, dT, ddT = _chebyshev(s, w0)
    w1 = dT[s] / ddT[s]
    b = ddT[s] / dT[s] ** 2
    bound = 1 - b * T[s] + b
    x = np.linspace((w0 - 1) / w1, (w0 + 1) / w1, 500)
    r = amplification("rkc", -x, stages=s)
    assert np.max(r) <= bound + 1e-12 and bound < 0.96


def test_spectral_radius_of_heat_equation():
    p = heat1d(N=200)
    st = Stepper(as_system(p.fun, p.y0))
    rho = spectral_radius(st.f, 0.0, p.y0, st.f(0.0, p.y0))
    exact = (4 / (1 / 201) ** 2) * np.sin(200 * np.pi / 402) ** 2
    assert abs(rho / exact - 1) < 0.05


def test_automatic_stages_beat_rk4_tenfold():
    """Heat equation N=200: RKC with automatic stage selection at rel. error < 1e-4 uses far
    fewer RHS calls than RK4 at its stability limit (rtol 1e-3: with the proportional tolerance map
    the achieved error is 8e-5)."""
    p = heat1d(N=200, t_end=0.1)
    ref = p.reference()
    res = solve(**p.solve_kwargs(), method="rkc", rtol=1e-3, atol=1e-6)
    err = np.max(np.abs(res.y[:, -1] - ref)) / np.max(np.abs(ref))
    assert res.success and err < 1e-4
    h_rk4 = 2.78 / p.info["rho"]
    nfev_rk4 = 4 * int(np.ceil(0.1 / h_rk4))
    assert res.stats["nfev"] * 10 < nfev_rk4


def test_bisected_h_max_matches_observed_blow_up():
    """Spec §12 case 1: spectrum {-1e8} U {-1e3 +- i 1e6 ...}; h_max by bisection on the
    stability region agrees with the step at which a long fixed-step run blows up."""
    lam = np.concatenate([[-1e8], -1e3 + 1j * np.linspace(-1e6, 1e6, 21)])
    best, hmax = select_stages("rkc", lam, [2, 4, 6, 8, 32], h_hi=1e-4, iters=25)
    assert best == 6                      # minimises stages per simulated second
    # spectral-radius selection would take s ~ sqrt(rho h / 0.653): more stages, no larger h
    assert hmax[32] < 1.05 * hmax[8] and 32 / hmax[32] > 3 * best / hmax[best]
    h = hmax[best]

    def grow(hh):
        res = solve(lambda t, x: lam * x, (0, 3000 * hh), np.ones_like(lam), method="rkc",
                    h=hh, stages=best, t_eval=[3000 * hh])
        return np.max(np.abs(res.y[:, -1])) if res.success else np.inf
    assert grow(0.97 * h) <= 1.0 + 1e-9
    assert grow(1.03 * h) > 10.0


@pytest.mark.parametrize("s", [1, 2, 3, 7, 20, 60])
def test_rkc1_recurrence_gives_the_damped_chebyshev_polynomial_and_its_interval(s):
    """The stages of :func:`rkc1_coefficients` on ``y' = lambda y`` give ``R_s(z) = T_s(w0 + w1 z) / T_s(w0)``
    (first order: ``R_s'(0) = 1``), bounded by one on ``[-1.9 s^2, 0]``, the interval multirate-rk4 counts on."""
    from numpy.polynomial import chebyshev as C

    from cvtfem.integrate.stabilized import RKC1_BETA_PER_S2, RKC1_DAMPING, rkc1_coefficients

    mu, nu, mu_t = rkc1_coefficients(s)
    z = np.linspace(-RKC1_BETA_PER_S2 * s * s, 0.0, 4001)
    y_prev, y = np.ones_like(z), 1 + mu_t[1] * z
    for j in range(2, s + 1):
        y, y_prev = mu[j] * y + nu[j] * y_prev + mu_t[j] * z * y, y
    w0 = 1 + RKC1_DAMPING / s ** 2
    Ts = C.Chebyshev.basis(s)
    w1 = Ts(w0) / Ts.deriv()(w0)
    assert np.allclose(y, Ts(w0 + w1 * z) / Ts(w0), rtol=0, atol=1e-14 * s * s)   # the recurrence's round-off
    assert np.abs(y).max() <= 1.0 + 1e-12
    dz = 1e-6
    assert (1 + mu_t[1] * dz if s == 1 else Ts(w0 + w1 * dz) / Ts(w0)) == pytest.approx(1 + dz, abs=1e-10)
