"""Forced response: FRF against time integration, direct against modal, unbalance against the Jeffcott closed form."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.modal.forced import (ModalBasis, displacement, frf_direct, frf_modal, orbit, unbalance_response,
                                 velocity)
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def friswell():
    """Friswell 5.9.1 with Rayleigh damping (zeta ~ 1-5 % in the lower modes)."""
    m = build_model(load_scene("friswell_5_9_1"))
    return m, m.C + 2.0 * m.M + 2e-5 * m.K


@pytest.fixture(scope="module")
def sheave():
    return build_model(load_scene("cvt_sheave_shaft"))


def test_frf_equals_steady_state_of_time_integration(friswell):
    """From the FRF's steady state, solve_ivp (DOP853, rtol 1e-11) must stay on it: any error of the amplitude or
    phase would start a free vibration that shows over three periods (lateral block, 28 DOF, spinning)."""
    m, C = friswell
    n, speed = m.n_dof, 300.0
    lat = np.flatnonzero(np.isin(m.dof_kind, [0, 1, 3, 4]))
    f = np.zeros(n)
    f[6 * 2] = 1e3  # 1 kN in x at the first disk
    Ms, Ks, Ds = (X[lat][:, lat].toarray() for X in (m.M, m.K, C + speed * m.G))
    Minv = np.linalg.inv(Ms)
    k = len(lat)
    A = np.block([[np.zeros((k, k)), np.eye(k)], [-Minv @ Ks, -Minv @ Ds]])
    b = np.concatenate([np.zeros(k), Minv @ f[lat]])
    every = displacement(lat, n)
    probe = [np.searchsorted(lat, d) for d in (6 * 2, 6 * 2 + 1, 6 * 4)]
    for w in (40.0, 90.0, 180.0, 420.0, 900.0):
        X = frf_direct(m.M, m.K, C, m.G, f, every, [w], speed)[0, :, 0]
        sol = solve_ivp(lambda t, x: A @ x + b * np.cos(w * t), (0.0, 3 * 2 * np.pi / w),
                        np.concatenate([X.real, (1j * w * X).real]), method="DOP853", rtol=1e-11, atol=1e-16,
                        dense_output=True)
        t = np.linspace(2, 3, 200) * 2 * np.pi / w
        steady = (X[probe, None] * np.exp(1j * w * t)).real
        err = np.abs(sol.sol(t)[probe] - steady).max() / np.abs(X[probe]).max()
        assert err < 1e-4, (w, err)


@pytest.mark.parametrize("n_modes", [4, 8, 12])
def test_modal_equals_direct_below_highest_mode(friswell, sheave, n_modes):
    """Complex-mode superposition with static correction within 1e-3 of direct solves up to 0.9 x the highest
    retained mode (gyroscopic, non-proportional bearing damping); without the correction it is worse."""
    m, C = friswell
    for model, Cm, node in ((m, C, 2), (sheave, sheave.C, 4)):
        n = model.n_dof
        f = np.zeros(n)
        f[6 * node] = 1.0
        out = displacement([6 * node, 6 * node + 1], n)
        basis = ModalBasis(model.M, model.K, Cm, model.G, f, n_modes)
        w = np.linspace(1.0, 0.9 * basis.wmax(400.0), 300)
        Hd = frf_direct(model.M, model.K, Cm, model.G, f, out, w, 400.0)
        err = np.linalg.norm(basis.frf(out, w, 400.0) - Hd, axis=(1, 2)) / np.linalg.norm(Hd, axis=(1, 2))
        plain = frf_modal(model.M, model.K, Cm, model.G, f, out, w, 400.0, n_modes, residual=False)
        err0 = np.linalg.norm(plain - Hd, axis=(1, 2)) / np.linalg.norm(Hd, axis=(1, 2))
        assert err.max() < 1e-3, (model.n_dof, err.max())
        assert err0.max() > 3 * err.max()


def test_rest_basis_is_exact_for_undamped_nonrotating(friswell):
    """C = G = 0: the real modes are the modes; all 28 lateral modes make the modal FRF exact."""
    m, _ = friswell
    n = m.n_dof
    f = np.zeros(n)
    f[6 * 3 + 1] = 1.0
    zero = sp.csr_matrix((n, n))
    out = displacement([6 * 2, 6 * 4 + 1], n)
    w = np.array([10.0, 150.0, 500.0, 2000.0])
    Hd = frf_direct(m.M, m.K, zero, zero, f, out, w)
    Hm = frf_modal(m.M, m.K, zero, zero, f, out, w, n_modes=28, modes="complex")
    assert np.abs(Hm - Hd).max() < 1e-9 * np.abs(Hd).max()


def test_bearing_forces_balance_static_load_and_velocity_output(friswell):
    """At w = 0 the bearings carry the applied force; velocities are i w times displacements."""
    m, C = friswell
    n = m.n_dof
    f = np.zeros(n)
    f[6 * 3] = 500.0
    D, V = m.bearing_force_map()
    from cvtfem.modal.forced import OutputMap

    bearing = OutputMap(D, V, ())
    H = frf_direct(m.M, m.K, C, m.G, f, bearing, [0.0], 100.0)[0, :, 0]
    assert abs(H[0::2].sum() - 500.0) < 1e-9 * 500.0  # the forces the bearings carry: the load
    assert np.abs(H[1::2].sum()) < 1e-9 * 500.0
    w = [33.0, 333.0]
    Hx = frf_direct(m.M, m.K, C, m.G, f, displacement([18], n), w, 100.0)
    Hv = frf_direct(m.M, m.K, C, m.G, f, velocity([18], n), w, 100.0)
    assert np.allclose(Hv, 1j * np.array(w)[:, None, None] * Hx, rtol=1e-12, atol=0)


def test_jeffcott_unbalance_closed_form():
    """m x'' + c x' + k x = me W^2 e^{i W t} (forward): |x| = me W^2 / |k - m W^2 + i c W|, 90 deg lag at
    W = wn, peak at wn / sqrt(1 - 2 zeta^2), circular forward orbit."""
    mass, k, zeta, me = 10.0, 4e6, 0.05, 1e-3
    wn = np.sqrt(k / mass)
    c = 2 * zeta * wn * mass
    M, K, C = (sp.identity(2, format="csr") * v for v in (mass, k, c))
    G = sp.csr_matrix((2, 2))
    load = me * np.array([1.0, -1j])
    s = np.linspace(0.0, 2 * wn, 4001)
    s = np.sort(np.append(s, wn))
    xy = unbalance_response(M, K, C, G, load, displacement([0, 1], 2), s)
    exact = me * s**2 / (k - mass * s**2 + 1j * c * s)
    assert np.allclose(xy[:, 0], exact, rtol=1e-12, atol=0)
    i = np.flatnonzero(s == wn)[0]
    assert np.degrees(np.angle(xy[i, 0])) == pytest.approx(-90.0, abs=1e-9)
    peak = wn / np.sqrt(1 - 2 * zeta**2)
    assert abs(s[np.argmax(np.abs(xy[:, 0]))] - peak) <= s[2] - s[1]
    major, minor = orbit(xy[:, 0], xy[:, 1])
    assert np.allclose(minor, major, rtol=1e-12) and np.all(minor >= 0)


def test_isotropic_rotor_unbalance_is_forward_circular_and_peaks_at_forward_criticals(friswell):
    """Friswell (isotropic bearings): a forward unbalance load drives only forward whirl (circular orbits), and the
    response peaks at the 1x forward critical speeds (830 and 2756 rpm), not the backward ones (825, 2488 rpm)."""
    m, _ = friswell
    s = np.linspace(50, 4000, 3951) * np.pi / 30
    xy = unbalance_response(m.M, m.K, m.C + 1e-6 * m.K, m.G, m.unbalance_load(2, 1e-4, 0.3),
                            displacement([12, 13], m.n_dof), s)
    major, minor = orbit(xy[:, 0], xy[:, 1])
    assert np.allclose(minor, major, rtol=1e-9)
    from scipy.signal import find_peaks

    peaks = s[find_peaks(major)[0]] * 30 / np.pi
    assert np.allclose(peaks, [830, 2756], atol=2.0)


def test_bad_input(friswell):
    m, C = friswell
    with pytest.raises(InputError):
        frf_direct(m.M, m.K, C, m.G, np.zeros(5), displacement([0], m.n_dof), [1.0])
    with pytest.raises(InputError):
        frf_direct(m.M, m.K, C, m.G, np.ones(m.n_dof), displacement([0], m.n_dof), [-1.0])
    with pytest.raises(InputError):
        ModalBasis(m.M, m.K, C, m.G, np.ones(m.n_dof), 4, modes="wrong")
    with pytest.raises(InputError):
        m.unbalance_load(7, 1e-4, 0.0)
