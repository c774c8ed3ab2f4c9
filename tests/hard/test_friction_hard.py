"""Hard cases of the regularised friction law (issue 7): zero slip at the kink, stick-slip,
a tiny saturation speed v0 (friction eigenvalue -1e8 1/s).

The reference is the Coulomb limit of the sliding point on a moving belt
(:func:`cvtfem.problems.sliding_point`, ``m u'' = -k u + N f(v_r) sign(v_r)``, ``v_r = V - u'``):
from rest it slips, ``u = u_s (1 - cos omega t)``, until ``u' = V`` at ``t_s = asin(V / (u_s omega)) / omega``,
then runs a
stick-slip cycle whose slip phases are harmonic about ``u_s = f0 N / k`` with amplitude
``V / omega`` (``omega = sqrt(k/m)``), so ``u`` stays in ``[u_s - V/omega, u_s + V/omega]``
and ``u'`` in ``[-V, V]``. Regularisation shifts these bounds by ``O(v0 / omega)``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cvtfem.elements.contact.friction import LAWS, friction_coefficient, friction_vector
from cvtfem.integrate import solve
from cvtfem.problems import sliding_point
from cvtfem.problems.mechanics import friction_coefficient as table21_coefficient

pytestmark = pytest.mark.hard

# sliding_point defaults: m = 1 kg, k = 100 N/m, N = 10 N, f0 = 0.3, V = 0.1 m/s
M, K, N, F0, V = 1.0, 100.0, 10.0, 0.3, 0.1
OMEGA = math.sqrt(K / M)
U_S = F0 * N / K                      # 0.03 m, centre of the slip oscillation
AMP = V / OMEGA                       # 0.01 m
T_STICK = math.asin(V / (U_S * OMEGA)) / OMEGA   # first stick: 0.3 sin(10 t) = V, 0.0340 s


@pytest.mark.parametrize("law", LAWS)
def test_zero_slip_at_the_kink_is_finite_and_continuous(law):
    """f(v_r) t at v_r = 0 (the 0/0 of t = v_r/|v_r|) is exactly 0, the slope there is f0/v0,
    and the law is continuous across |v_r| = v0 (the kink of (1.48))."""
    f0, v0 = 0.09, 1e-9
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        zero = friction_vector(np.zeros((3, 4)), f0, v0, law, axis=0)
        assert np.array_equal(zero, np.zeros((3, 4)))
        tiny = np.array([[1e-300, 0.0, -1e-300], [0.0, 1e-300, 0.0], [0.0, 0.0, 0.0]])
        # far below v0 every law is linear, with its slope f'(0) (f0/v0; 1.5 f0/v0 for "smoothed")
        slope = friction_coefficient(1e-9 * v0, f0, v0, law) / (1e-9 * v0)
        assert slope == pytest.approx(f0 / v0 * (1.5 if law == "smoothed" else 1.0), rel=1e-9)
        assert np.allclose(friction_vector(tiny, f0, v0, law, axis=0), slope * tiny, rtol=1e-9, atol=0)
        below, above = v0 * (1 - 1e-12), v0 * (1 + 1e-12)
        fb, fa = friction_coefficient(np.array([below, above]), f0, v0, law)
    assert abs(fa - fb) < 1e-9 * f0
    # the vector form agrees with the scalar one in every direction, also at the kink
    rng = np.random.default_rng(7)
    d = rng.normal(size=(3, 200))
    d /= np.linalg.norm(d, axis=0)
    speeds = v0 * np.concatenate([[0.0, 1.0, 1.0 - 1e-15, 1.0 + 1e-15], np.geomspace(1e-6, 1e6, 196)])
    vec = friction_vector(d * speeds, f0, v0, law, axis=0)
    assert np.all(np.isfinite(vec))
    assert np.allclose(np.linalg.norm(vec, axis=0), friction_coefficient(speeds, f0, v0, law), rtol=1e-12, atol=0)
    assert np.all(np.linalg.norm(vec, axis=0) <= f0 * (1 + 1e-15))


def test_smooth_table21_law_is_c1_at_both_blend_ends():
    """The C1 blend of spec Table 2.1 matches value and slope at (1 -/+ eps) v0."""
    f0, v0, eps = 0.3, 1e-3, 0.1
    for v_edge, slope in (((1 - eps) * v0, f0 / v0), ((1 + eps) * v0, 0.0)):
        dv = 1e-9 * v0
        left = (table21_coefficient(v_edge, f0, v0, "smooth", eps)
                - table21_coefficient(v_edge - dv, f0, v0, "smooth", eps)) / dv
        right = (table21_coefficient(v_edge + dv, f0, v0, "smooth", eps)
                 - table21_coefficient(v_edge, f0, v0, "smooth", eps)) / dv
        assert left == pytest.approx(slope, abs=1e-4 * f0 / v0)
        assert right == pytest.approx(slope, abs=1e-4 * f0 / v0)


T_CYCLE = 0.4    # s: first stick at 0.034 s, release at u = u_s near 0.32 s, then periodic
T_END = T_CYCLE + 2 * math.pi / OMEGA + 0.05    # one full slip period (0.628 s) after T_CYCLE


def _run(v0, method, **kw):
    p = sliding_point(law="smooth", v0=v0, t_end=T_END)
    return solve(**p.solve_kwargs(), method=method, t_eval=np.linspace(0.0, T_END, 4001), **kw)


def _cycle(res):
    m = res.t > T_CYCLE
    return res.y[0, m].min(), res.y[0, m].max(), res.y[1, m].min(), res.y[1, m].max()


@pytest.mark.timeout(60)
def test_stick_slip_cycle_matches_the_coulomb_limit():
    """v0 = 1 mm/s: the stick-slip cycle bounds are the Coulomb ones shifted by about v0/omega."""
    v0 = 1e-3
    res = _run(v0, "Radau", rtol=1e-6, atol=1e-9)
    assert res.status == 0 and np.all(np.isfinite(res.y))
    u_lo, u_hi, v_lo, v_hi = _cycle(res)
    for got, coulomb in ((u_lo, U_S - AMP), (u_hi, U_S + AMP)):
        assert abs(got - coulomb) < 2 * v0 / OMEGA
    assert abs(v_lo + V) < 2 * v0 and abs(v_hi - V) < 2 * v0


@pytest.mark.timeout(60)
def test_tiny_v0_friction_eigenvalue_1e8_implicit_adaptive_converges_to_coulomb():
    """v0 = 3e-8 m/s makes dF_v/dv = -N f0 / (m v0) = -1e8 1/s in stick; Radau stays stable and
    lands within 1e-5 m of the Coulomb bounds (100x closer than with v0 = 1 mm/s)."""
    v0 = 3e-8
    p = sliding_point(law="smooth", v0=v0)
    x_stick = np.array([U_S - 0.005, V])
    dv = 1e-10
    lam = (p.fun(0.0, x_stick + [0, dv])[1] - p.fun(0.0, x_stick - [0, dv])[1]) / (2 * dv)
    assert lam == pytest.approx(-N * F0 / (M * v0), rel=1e-3)
    res = _run(v0, "Radau", rtol=1e-6, atol=1e-9)
    assert res.status == 0 and np.all(np.isfinite(res.y))
    u_lo, u_hi, v_lo, v_hi = _cycle(res)
    assert abs(u_lo - (U_S - AMP)) < 1e-5 and abs(u_hi - (U_S + AMP)) < 1e-5
    assert abs(v_lo + V) < 1e-4 and abs(v_hi - V) < 1e-4


@pytest.mark.timeout(60)
@pytest.mark.parametrize("newton", ["const", "exact"])
def test_tiny_v0_fixed_step_implicit_euler_fails_clearly_at_the_first_stick(newton):
    """Implicit Euler at h = 1 ms (h lambda = -1e5): Newton cannot enter the 6e-9 m/s wide stick
    band; the run stops within two steps of the analytic stick onset t_s = asin(1/3)/10 = 0.0340 s,
    with a message naming the Newton variant, the time and the step, after a Jacobian refresh."""
    res = solve(**sliding_point(law="smooth", v0=3e-8, t_end=1.0).solve_kwargs(), method="implicit-euler",
                h=1e-3, newton=newton)
    assert res.status == -1 and not res.success
    assert f"Newton ({newton}) diverged" in res.message and "with fixed step h = 0.001 s" in res.message
    t_fail = res.t[-1] + 1e-3
    # the failing step is the one where the (lagging, O(h)) implicit-Euler velocity reaches V
    assert T_STICK <= t_fail <= T_STICK + 2e-3
    assert f"at t = {t_fail:.6g} s" in res.message
    assert res.stats["nnewton_fail"] >= 1
    if newton == "const":         # the frozen matrix was rebuilt before giving up (spec 4.3)
        assert res.stats["njac_refresh"] >= 1
    assert np.all(np.isfinite(res.y))
    # the part that was integrated is the analytic slip phase u = u_s (1 - cos w t)
    assert np.allclose(res.y[0], U_S * (1 - np.cos(OMEGA * res.t)), atol=2e-3 * U_S + 0.5 * 1e-3 * V)


@pytest.mark.timeout(60)
def test_explicit_step_far_above_the_friction_stability_limit_stays_bounded():
    """RK4 at h = 1 ms is 3.6e4 x above its linear limit 2.785 / 1e8 s in stick, but the
    saturating law bounds the chatter: the cycle stays within one belt step h V of Coulomb."""
    h = 1e-3
    res = _run(3e-8, "rk4", h=h)
    assert res.status == 0 and np.all(np.isfinite(res.y))
    u_lo, u_hi, v_lo, v_hi = _cycle(res)
    assert abs(u_lo - (U_S - AMP)) < h * V and abs(u_hi - (U_S + AMP)) < h * V
    assert np.all(np.abs(res.y[1]) <= V * (1 + 0.01))
