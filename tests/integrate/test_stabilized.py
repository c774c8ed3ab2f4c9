"""RKC: stability length, spectral-radius estimate, automatic stage selection (spec §11.6)."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.integrate.base import Stepper
from cvtfem.integrate.stabilized import _chebyshev, rkc_stability_length, spectral_radius
from cvtfem.integrate.study import amplification, real_stability_length
from cvtfem.integrate.system import as_system
from cvtfem.problems import heat1d


@pytest.mark.parametrize("s", [10, 20, 50, 100])
def test_rkc_stability_length_matches_published(s):
    """Measured by stepping x' = -x x for a grid of x: beta(s) ~ 0.653 s^2 (Sommeijer, Shampine
    & Verwer 1997, eps = 2/13) within 1 %."""
    beta = real_stability_length("rkc", x_max=0.8 * s * s, n=40 * s * s, stages=s)
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
    fewer RHS calls than RK4 at its stability limit."""
    p = heat1d(N=200, t_end=0.1)
    ref = p.reference()
    res = solve(**p.solve_kwargs(), method="rkc", rtol=1e-4, atol=1e-7)
    err = np.max(np.abs(res.y[:, -1] - ref)) / np.max(np.abs(ref))
    assert res.success and err < 1e-3
    h_rk4 = 2.78 / p.info["rho"]
    nfev_rk4 = 4 * int(np.ceil(0.1 / h_rk4))
    assert res.stats["nfev"] * 10 < nfev_rk4
