"""S1, S2, S3 families: forces against energy and Rayleigh gradients, mass against quadrature of T,
Jacobian against differences, a tensioned straight segment, conservation and power balance."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve

from cvtfem.elements.chain.geometry import chain_geometry, reference_geometry, ring_positions, REFERENCE_SECTION
from cvtfem.elements.chain.symmetric import (ChainDamping, ChainS1, ChainS2, ChainS3, damping_from_ratio,
                                             END_SLOPE_FACTOR)
from cvtfem.integrate import solve

FAMILIES = (ChainS1, ChainS2, ChainS3)
DAMPED = dataclasses.replace(damping_from_ratio(reference_geometry(), 0.05), b_joint=0.01)


def kx(v):
    return np.stack([-v[:, 1], v[:, 0]], axis=1)


def state(fam, rng, pos=1e-5, slope=1e-3, speed=1.0, spin=0.0):
    """Pins on the unstretched ring, randomly displaced; velocities random plus a rigid spin (rad/s)."""
    g, n = fam.geom, fam.n
    x, _ = ring_positions(g.L)
    q = fam.join(x + pos * rng.standard_normal((n, 2)), g.l / 2 + pos * 0.01 * rng.standard_normal(n),
                 slope * rng.standard_normal((n, 2)))
    qd = fam.join(spin * kx(x) + speed * rng.standard_normal((n, 2)), 0.01 * speed * rng.standard_normal(n),
                  100 * slope * speed * rng.standard_normal((n, 2)))
    return q, qd


def gradient(f, x, h):
    """Central differences of a scalar function, step ``h`` per coordinate."""
    g = np.empty_like(x)
    for j in range(len(x)):
        e = np.zeros_like(x)
        e[j] = h[j]
        g[j] = (f(x + e) - f(x - e)) / (2 * h[j])
    return g


def steps(fam, h_pos=1e-9, h_slope=1e-9):
    return fam.join(np.full((fam.n, 2), h_pos), np.full(fam.n, h_pos), np.full((fam.n, 2), h_slope))


def blockwise_error(fam, a, b):
    """Largest relative difference over the coordinate blocks (each relative to its own largest entry)."""
    return max(np.abs(x - y).max() / np.abs(y).max() for x, y in zip(fam.split(a), fam.split(b)) if x is not None)


def geometries():
    """Reference chain (randomised pitch) and, to expose the small pin-bending terms, the same pins without plates."""
    g = reference_geometry(randomised=True, seed=5)
    return {"reference": g, "pins-only": dataclasses.replace(g, c_plate=np.zeros_like(g.c_plate))}


CASES = [(F, "reference") for F in FAMILIES] + [(ChainS3, "pins-only")]   # only S3 has pin-bending terms


@pytest.mark.parametrize("Family, which", CASES)
def test_elastic_forces_are_minus_the_energy_gradient(Family, which):
    fam = Family(geometries()[which], DAMPED)
    q, _ = state(fam, np.random.default_rng(1))
    err = blockwise_error(fam, fam.elastic_forces(q), -gradient(fam.potential_energy, q, steps(fam)))
    assert err < 1e-6, err


@pytest.mark.parametrize("Family, which", CASES)
def test_dissipative_forces_are_minus_the_rayleigh_gradient(Family, which):
    damping = DAMPED if which == "reference" else dataclasses.replace(DAMPED, b_joint=0.0)
    fam = Family(geometries()[which], damping)
    q, qd = state(fam, np.random.default_rng(2), spin=50.0)
    Qd = fam.dissipative_forces(q, qd)
    # Phi is quadratic in the velocities: central differences are exact but for round-off, so take large steps
    err = blockwise_error(fam, Qd, -gradient(lambda v: fam.rayleigh(q, v), qd, steps(fam, 1e-2, 1e-1)))
    assert err < 1e-6, err
    # Euler's identity for a Rayleigh function quadratic in the velocities (§8.5 test 2)
    assert np.isclose(qd @ Qd, -2 * fam.rayleigh(q, qd), rtol=1e-12)


def test_joint_damping_dissipates_only_relative_link_rotation():
    """A rigid rotation of the whole ring: no joint rate, no joint force; the printed (1.93) would give one."""
    fam = ChainS1(reference_geometry(randomised=True), ChainDamping(b_joint=0.05))
    x, _ = ring_positions(fam.geom.L)
    q, qd = fam.join(x), fam.join(80.0 * kx(x))
    assert np.abs(fam.dissipative_forces(q, qd)).max() < 1e-12 * 0.05 * 80 / 0.009
    assert np.abs(fam.outputs(q, qd)["chain.joint_rate"]).max() < 1e-11


@pytest.mark.parametrize("Family", FAMILIES)
def test_mass_matrix_is_the_quadrature_of_the_kinetic_energy(Family):
    fam = Family(reference_geometry(randomised=True), DAMPED)
    _, qd = state(fam, np.random.default_rng(3))
    ud, u3d, upd = fam.split(qd)
    m, l = fam.geom.m_eff, fam.geom.l
    if Family is ChainS1:                                  # lumped at the pin middle (1.67)
        T = 0.5 * (m * (ud ** 2).sum(1)).sum()
    else:                                                  # rho = m / l along the axis, Gauss-Legendre in xi
        xi, w = np.polynomial.legendre.leggauss(6)
        upd = np.zeros_like(ud) if upd is None else upd
        h = 0.5 * l * (xi ** 2 - 1)                        # (1.96b)
        Ud = ud[:, None, :] + h[None, :, None] * upd[:, None, :]
        speed2 = (Ud ** 2).sum(2) + (xi[None, :] * u3d[:, None]) ** 2
        T = 0.5 * (m / 2 * (speed2 * w).sum(1)).sum()
    assert np.isclose(fam.kinetic_energy(qd), T, rtol=1e-13)
    f = np.random.default_rng(4).standard_normal(fam.size)
    np.testing.assert_allclose(fam.solve_mass(fam.mass_matrix() @ f), f, rtol=1e-10, atol=1e-12)
    M = fam.mass_matrix().tocoo()                          # couples only coordinates of one pin
    pin = np.empty(fam.size, int)
    pin[fam.dof_index] = np.arange(fam.n)[:, None]
    assert np.all(pin[M.row] == pin[M.col])


@pytest.mark.parametrize("Family", FAMILIES)
def test_jacobian_blocks_equal_differences(Family):
    fam = Family(reference_geometry(randomised=True), DAMPED)
    q, qd = state(fam, np.random.default_rng(5), spin=30.0)
    K, C = fam.jacobian(q, qd)
    for wrt, J, h in ((0, K, steps(fam, 1e-9, 1e-8)), (1, C, steps(fam, 1e-4, 1e-3))):
        fd = np.empty((fam.size, fam.size))
        for j in range(fam.size):
            e = np.zeros(fam.size)
            e[j] = h[j]
            args_p, args_m = ((q + e, qd), (q - e, qd)) if wrt == 0 else ((q, qd + e), (q, qd - e))
            fd[:, j] = (fam.forces(*args_p) - fam.forces(*args_m)) / (2 * h[j])
        Jd = J.toarray()
        assert not np.any(fd[~fam.jac_sparsity.toarray()])          # the pattern holds every dependence
        scale = np.abs(Jd).max(axis=1, keepdims=True)                 # row-wise: mixed units per block
        assert np.abs(Jd - fd).max() < 1e-6 * np.abs(Jd).max()
        assert (np.abs(Jd - fd) / scale).max() < 1e-5, (np.abs(Jd - fd) / scale).max()
    Ke = fam.jacobian(q, np.zeros_like(qd))[0]
    if Family is not ChainS3:                    # elastic stiffness is minus a Hessian: symmetric
        assert abs(Ke - Ke.T).max() < 1e-12 * abs(Ke).max()


@pytest.mark.parametrize("Family", FAMILIES)
def test_straight_segment_under_end_tension_carries_it_in_every_link(Family):
    """Open 9-pin chain along x1, pin 0 held, pin 8 pulled with T: Newton on the analytic Jacobian."""
    T = 3000.0
    g = chain_geometry(9, 0.033, 0.009, 12, 1.4e9, 9 * 0.0179, REFERENCE_SECTION, c_pin=2.0e8, closed=False)
    fam = Family(g, DAMPED)
    n = fam.n
    x = np.stack([np.arange(n) * 0.009 * (1 + T / 1.4e9 / 0.009), np.zeros(n)], axis=1)
    q = fam.join(x, np.full(n, g.l / 2), np.zeros((n, 2)))
    F = np.zeros((n, 3))
    F[-1, 0] = T / 2                                          # mirror-symmetric: T/2 on each end of the pin
    Qext = fam.external_forces(F)
    free = np.setdiff1d(np.arange(fam.size), fam.dof_index[0, :2])
    zero = np.zeros(fam.size)
    for _ in range(20):
        r = (fam.forces(q, zero) + Qext)[free]
        K = fam.jacobian(q, zero)[0][free][:, free]
        dq = spsolve(K.tocsc(), -r)
        q[free] += dq
        if np.abs(dq).max() < 1e-16:
            break
    r = (fam.forces(q, zero) + Qext)[free]
    assert np.abs(r).max() < 1e-9 * T
    u, _, up = fam.split(q)
    tt = (u[1:] - u[:-1]) / 0.009
    N = fam.outputs(q, zero)["chain.link_tension"][:-1]
    force = N[:, None] * tt                                   # force of each link on its rear pin
    if Family is ChainS3:
        D = 0.5 * 0.009 * ((tt ** 2).sum(1) - 1)
        Dp = (tt * (up[1:] - up[:-1])).sum(1)
        Np = fam.geom.c1_link[:-1] * D + fam.geom.c2_link[:-1] * Dp
        force = force + Np[:, None] * (up[1:] - up[:-1]) / 0.009
    np.testing.assert_allclose(force[:, 0], T, rtol=1e-10)
    assert np.abs(force[:, 1]).max() < 1e-10 * T
    if Family is not ChainS3:                                 # N |tt| = T: N is T to first order in the strain
        np.testing.assert_allclose(N * np.linalg.norm(tt, axis=1), T, rtol=1e-10)


def ring_rhs(fam):
    n2 = fam.size

    def rhs(t, y):
        q, qd = y[:n2], y[n2:2 * n2]
        out = np.empty_like(y)
        out[:n2] = qd
        out[n2:2 * n2] = fam.solve_mass(fam.forces(q, qd))
        if len(y) > 2 * n2:
            out[2 * n2:] = 2 * fam.rayleigh(q, qd)            # dissipated energy
        return out
    return rhs


def free_ring_run(fam, periods, rng, damped=False, speed=10.0):
    """A ring running at ``speed`` (m/s) with random displacements and velocities, over ``periods``
    periods of its lowest link (longitudinal) mode ``2 sqrt(c/m) sin(pi/n)``."""
    g = fam.geom
    _, R = ring_positions(g.L)
    q, qd = state(fam, rng, pos=2e-6, slope=2e-4, speed=0.3, spin=speed / R)
    omega1 = 2 * np.sqrt(g.c_link.mean() / g.m_eff.mean()) * np.sin(np.pi / fam.n)
    y0 = np.concatenate([q, qd] + ([[0.0]] if damped else []))
    t_end = periods * 2 * np.pi / omega1
    res = solve(ring_rhs(fam), (0.0, t_end), y0, method="dopri78", rtol=1e-10, atol=1e-14, n2=fam.size)
    assert res.success
    return res


def small_ring():
    """Three pins of the reference chain (pitch 9 mm, same pins and plates): a triangle."""
    return chain_geometry(3, 0.033, 0.009, 12, 1.4e9, 3 * 1.5 / 84, REFERENCE_SECTION, c_pin=2.0e8)


def conservation(fam, res):
    n2 = fam.size
    E = np.array([fam.energy(y[:n2], y[n2:2 * n2]) for y in res.y.T])
    P = np.array([fam.linear_momentum(y[n2:2 * n2]) for y in res.y.T])
    H = np.array([fam.angular_momentum(y[:n2], y[n2:2 * n2]) for y in res.y.T])
    p_scale = fam.geom.m_eff.sum() * 10.0
    h_scale = abs(H[0])
    return (np.abs(E - E[0]).max() / E[0], np.abs(P - P[0]).max() / p_scale, np.abs(H - H[0]).max() / h_scale)


@pytest.mark.parametrize("Family", FAMILIES)
def test_free_ring_conserves_momentum_and_energy(Family):
    """3-pin ring (the default-suite twin of the 84-pin test), dissipation off, 100 periods."""
    g = small_ring()
    fam = Family(g)
    dE, dP, dH = conservation(fam, free_ring_run(fam, 100, np.random.default_rng(6)))
    assert dE < 1e-6 and dP < 1e-12 and dH < 1e-12, (dE, dP, dH)


@pytest.mark.slow
@pytest.mark.parametrize("Family", FAMILIES)
def test_reference_ring_conserves_momentum_and_energy(Family):
    fam = Family(reference_geometry(randomised=True))
    dE, dP, dH = conservation(fam, free_ring_run(fam, 100, np.random.default_rng(7)))
    assert dE < 1e-6 and dP < 1e-12 and dH < 1e-12, (dE, dP, dH)


@pytest.mark.parametrize("Family", FAMILIES)
def test_energy_falls_at_the_rate_two_phi(Family):
    """Damped 3-pin ring vibrating about rest: E(t) + int 2 Phi dt stays E(0) along the run (power balance)."""
    g = small_ring()
    fam = Family(g, dataclasses.replace(damping_from_ratio(g, 0.05), b_joint=0.01))
    res = free_ring_run(fam, 10, np.random.default_rng(8), damped=True, speed=0.0)
    n2 = fam.size
    E = np.array([fam.energy(y[:n2], y[n2:2 * n2]) for y in res.y.T])
    W = res.y[-1]
    assert W[-1] > 0.01 * E[0]                               # damping did work worth measuring
    assert np.abs(E + W - E[0]).max() < 1e-6 * W[-1], np.abs(E + W - E[0]).max() / W[-1]


def test_end_moment_load_uses_the_true_end_slope():
    """Virtual work of a mirror-symmetric end moment pair: 2 M . d(theta_end), theta_end = 2 k x u' (§3.8)."""
    fam = ChainS3(reference_geometry())
    rng = np.random.default_rng(9)
    M = rng.standard_normal((fam.n, 2))
    dup = rng.standard_normal((fam.n, 2))
    Q = fam.external_forces(np.zeros((fam.n, 3)), M)
    work = 2 * (M * (END_SLOPE_FACTOR * kx(dup))).sum()
    assert np.isclose(fam.split(Q)[2].ravel() @ dup.ravel(), work, rtol=1e-14)
    assert END_SLOPE_FACTOR == 2.0


def test_s3_bending_moment_and_plate_tensions():
    """Pure bending of one pin: moment a . kappa with kappa = (4/l) k x u'; plate tensions sum to N."""
    g = reference_geometry()
    fam = ChainS3(g)
    x, _ = ring_positions(g.L)
    up = np.zeros((fam.n, 2))
    tau = np.array([0.0, 1.0])                       # pin 0 on the x1 axis: its bisector is +x2
    up[0] = 1e-3 * tau                               # deflection along the chain direction costs A_tau
    q = fam.join(x * (1 + 1e-4), np.full(fam.n, g.l / 2), up)
    out = fam.outputs(q, np.zeros_like(q))
    M0 = out["chain.pin_bending_moment"][:2]
    assert np.isclose(M0[1], g.A_tau * 4 / g.l * 1e-3, rtol=1e-6) and abs(M0[0]) < 1e-9
    plates = out["chain.plate_tension"].reshape(fam.n, -1)
    np.testing.assert_allclose(plates.sum(1), out["chain.link_tension"], rtol=1e-12)
