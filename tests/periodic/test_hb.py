"""Harmonic balance: backlash law, analytic linear response, time-integration cross-checks."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.torsional import BACKLASH, GAP, build_network, link_force
from cvtfem.errors import NumericalError
from cvtfem.periodic.hb import solve_linear, solve_periodic
from cvtfem.periodic.transient import steady_state


def law(l, kind, k_in=0.03, k_out=1.0, h=1.0, zone=0.2):
    one = np.ones(1)
    return link_force(np.atleast_2d(l), np.array([kind]), k_in * one, k_out * one, h * one, zone * one)


@pytest.mark.parametrize("kind", [BACKLASH, GAP])
def test_backlash_law_is_c1_with_bounded_second_derivative(kind):
    l = np.linspace(-2, 2, 400_001)
    f, df = law(l, kind)
    dl = l[1] - l[0]
    # f' is the derivative of f (central differences, O(dl^2) away from the kinks of f')
    fd = np.gradient(f[0], dl)
    assert np.abs(fd - df[0])[1:-1].max() < 1e-4
    # f and f' continuous: no jumps larger than the local slope allows
    assert np.abs(np.diff(f[0])).max() <= 1.0001 * dl
    assert np.abs(np.diff(df[0])).max() <= 5 * 0.97 * dl * 1.0001  # |f''| <= 5 (k_out - k_in) / h
    # gap stiffness inside, contact stiffness outside (erratum 10 #15: the weak spring is in the gap)
    inside = np.abs(l) < 0.4 if kind == BACKLASH else l < 0.9
    assert np.allclose(df[0][inside], 0.03)
    outside = np.abs(l) > 0.6 if kind == BACKLASH else l > 1.1
    assert np.allclose(df[0][outside], 1.0)


def test_backlash_law_matches_source_formula_with_swapped_stiffnesses():
    """B:(18) with c1 = k_gap, c2 = k_contact (spec 8.3, erratum 15)."""
    c1, c2, h = 0.05, 2.0, 0.4
    l = np.array([0.01, 0.1, 0.17, 0.2, 0.23, 0.5, -0.2, -0.5])
    s = np.sign(l)
    a = np.abs(l)
    ref = np.where(a < 0.4 * h, c1 * l,
                   np.where(a <= 0.6 * h, c1 * l + 2.5 * (c2 - c1) / h * (l - 0.4 * h * s) ** 2 * s,
                            c2 * l + (c1 - c2) * h / 2 * s))
    f, _ = law(l, BACKLASH, c1, c2, h)
    assert np.allclose(f[0], ref, rtol=1e-14, atol=1e-16)


def test_linear_one_mass_matches_closed_form():
    m, b, k, F, w = 2.0, 0.3, 50.0, 3.0, 4.0
    net = build_network([m], [b], [0], [-1], [k], orders=(1, 3), Q=[[F, 0.5j * F]])
    sol = solve_linear(net, w, 5)
    for n, Q in ((1, F), (3, 0.5j * F)):
        ref = Q / (k - m * (n * w) ** 2 + 1j * n * w * b)
        assert abs(2 * sol.a[0, 5 + n] - ref) <= 1e-14 * abs(ref)
    assert np.abs(sol.a[0, [5, 5 + 2, 5 + 4]]).max() == 0.0


def gear_pair():
    """Motor - shaft - gear | backlash | gear - shaft - load - soft clamp (spec 12 #12)."""
    Q = np.zeros((4, 2), complex)
    Q[0] = [40.0, 60.0]  # mean and first harmonic of the drive force, N
    return build_network([1.0, 0.5, 0.5, 2.0], [2.0, 1.0, 1.0, 20.0], [0, 1, 2, 3], [1, 2, 3, -1],
                         [2e5, 1e6, 2e5, 5e4], d=[20, 30, 20, 60], law=[0, BACKLASH, 0, 0],
                         k_in=[0, 3e4, 0, 0], h=[0, 2e-4, 0, 0], orders=(0, 1), Q=Q)


def peak_rms(f):
    return np.abs(f).max(axis=1), np.sqrt((f ** 2).mean(axis=1))


def test_newton_converges_quadratically_and_rattles():
    net = gear_pair()
    sol = solve_periodic(net, 107.0, 32)
    assert sol.converged and sol.method == "sweep"
    r = np.array(sol.residuals)
    assert r[-1] <= 1e-10
    assert r[-1] <= 1e-3 * r[-2] ** 1.5  # quadratic end game
    l = (net.incidence() @ sol.displacements())[1]
    assert l.max() > 0 and l.min() < -1e-4  # mesh crosses the gap (h/2 = 1e-4): both flanks hit
    lin = solve_linear(net, 107.0, 32)
    assert peak_rms(sol.link_forces())[0][1] > 1.02 * peak_rms(lin.link_forces())[0][1]


def test_failure_is_reported_not_silent():
    net = gear_pair()
    sol = solve_periodic(net, 107.0, 16, max_iter=1, a0=solve_linear(net, 107.0, 16).a)
    assert not sol.converged and "did not converge" in sol.message
    with pytest.raises(NumericalError, match="omega = 107"):
        solve_periodic(net, 107.0, 16, max_iter=1, a0=sol.a * 0, raise_on_failure=True)


def test_harmonic_truncation_converges():
    net = gear_pair()
    ref = peak_rms(solve_periodic(net, 107.0, 128).link_forces(2048))
    errs = []
    for N in (8, 16, 32, 64):
        got = peak_rms(solve_periodic(net, 107.0, N).link_forces(2048))
        errs.append(max(np.abs(g - r).max() / r.max() for g, r in zip(got, ref)))
    assert all(e2 < e1 for e1, e2 in zip(errs, errs[1:])), errs
    assert errs[-1] < 1e-4


@pytest.mark.slow
@pytest.mark.parametrize("omega", [80.0, 107.0, 130.0], ids=["below", "at", "above"])
def test_agrees_with_time_integration(omega):
    """Peak and RMS of every link force within 1e-3 of DOP853 (rtol 1e-11) at periodic steady state."""
    net = gear_pair()
    sol = solve_periodic(net, omega, 64)
    ti = steady_state(net, omega, rtol=1e-11, atol=1e-14, tol=1e-9, max_periods=400, y0=sol.state())
    for hb_val, ti_val in zip(peak_rms(sol.link_forces(1024)), peak_rms(ti.link_forces)):
        assert np.abs(hb_val - ti_val).max() <= 1e-3 * ti_val.max()
        assert (np.abs(hb_val - ti_val) / ti_val).max() <= 1e-3
