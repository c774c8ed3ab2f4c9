"""H1 contact at the pin-axis point and the sheave's generalized forces (contact-models digest §4.1,
§4.2, §4.4, §10.4 items 2 and 9)."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.contact.friction import friction_force
from cvtfem.elements.contact.hertz import hertz_force, hertz_potential, normal_force, normal_stiffness
from cvtfem.elements.contact.pin_axis import pin_axis_contact, pin_axis_slip
from scipy.spatial.transform import Rotation

from cvtfem.elements.contact.sheave import rotate, sheave_generalized, tilt_forces

C = 2.0e10      # N/m^1.5


def _states(profile, n, seed, side=1.0):
    """Pin-axis points within +-30 um of a tilted, displaced sheave (Delta in -30..30 um)."""
    rng = np.random.default_rng(seed)
    R_c = rng.normal(size=(n, 3)) * 1e-4
    theta = np.concatenate([rng.normal(size=(n, 2)) * 5e-3, np.zeros((n, 1))], 1)
    r, phi = rng.uniform(0.036, 0.088, n), rng.uniform(0, 2 * np.pi, n)
    z = side * (profile(r)[0] + rng.uniform(-3e-5, 3e-5, n))
    local = np.stack([r * np.cos(phi), r * np.sin(phi), z], -1)
    return R_c + np.einsum("nij,nj->ni", rotation(theta), local), R_c, theta


def rotation(theta):
    return Rotation.from_rotvec(theta).as_matrix()


def tangent_operator(theta):
    """T = E + (1 - cos t)/t^2 Theta + (t - sin t)/t^3 Theta^2 (t = |theta| > 0)."""
    t = np.linalg.norm(theta, axis=-1)[:, None, None]
    W = np.cross(theta[:, None, :], -np.eye(3)[None])        # Theta = theta x: W v = theta x v
    return np.eye(3) + (1 - np.cos(t)) / t ** 2 * W + (t - np.sin(t)) / t ** 3 * (W @ W)


def test_rotation_and_tilt_forces_against_scipy():
    """rotate = scipy's rotation-vector matrix (also transposed); tilt_forces(M) . e_j = M . o_j with
    (o_j x) = dP/dtheta_j P^T from central differences of scipy's matrices, |theta| 1e-9 ... 2."""
    rng = np.random.default_rng(0)
    theta = rng.normal(size=(20, 3)) * np.geomspace(1e-9, 2.0, 20)[:, None]
    v = rng.normal(size=(20, 3))
    P = rotation(theta)
    assert np.allclose(rotate(theta, v), np.einsum("nij,nj->ni", P, v), rtol=0, atol=1e-15 * 4)
    assert np.allclose(rotate(theta, v, inverse=True), np.einsum("nji,nj->ni", P, v), rtol=0, atol=1e-15 * 4)
    M = rng.normal(size=(20, 3))
    Q = tilt_forces(theta, M)
    h = 1e-6
    for j in range(3):
        d = np.zeros(3)
        d[j] = h
        W = (rotation(theta + d) - rotation(theta - d)) / (2 * h) @ np.swapaxes(P, 1, 2)
        o = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], -1)
        assert np.allclose(Q[:, j], np.sum(M * o, axis=1), rtol=0, atol=1e-9)
    big = np.linalg.norm(theta, axis=1) > 1e-3
    assert np.allclose(Q[big], np.einsum("nji,nj->ni", tangent_operator(theta[big]), M[big]), atol=1e-14)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_normal_forces_are_minus_the_gradient_of_the_potential(profile, side):
    """Forces on pin, sheave translation and sheave tilt equal -dPi/dq, Pi = 2/5 c Delta^{5/2}, by
    central differences to 1e-6 relative, on 200 random states (tilted, displaced sheave)."""
    n = 200
    R_pin, R_c, theta = _states(profile, n, 1, side)

    def potential(Rp, Rc, th):
        return hertz_potential(pin_axis_contact(Rp, Rc, th, profile, side).delta, C)

    con = pin_axis_contact(R_pin, R_c, theta, profile, side)
    N = hertz_force(con.delta, C)[0]
    F = normal_force(con.grad, N)
    F_c, Q_theta, Q_phi = sheave_generalized(F, con.arm, theta)
    on = con.delta > 2e-6     # away from the C1 point at onset
    assert on.sum() > 50
    scale = np.linalg.norm(F, axis=1)
    h = 1e-9
    for q, Q in ((0, F), (1, F_c), (2, Q_theta)):
        for j in range(3):
            args_p = [R_pin.copy(), R_c.copy(), theta.copy()]
            args_m = [R_pin.copy(), R_c.copy(), theta.copy()]
            args_p[q][:, j] += h
            args_m[q][:, j] -= h
            fd = -(potential(*args_p) - potential(*args_m)) / (2 * h)
            lever = 1.0 if q < 2 else 0.1
            assert np.all(np.abs(Q[on, j] - fd[on]) <= 1e-6 * scale[on] * lever), (q, j)
    assert np.all(np.abs(Q_phi) <= 1e-12 * scale * 0.1)      # axisymmetric sheave: Q_phi = 0
    # the force is along the outward normal, |F| = N sqrt(1 + f'^2) (digest §4.2 [D])
    fp = profile(con.radius)[1]
    assert np.allclose(F, (N * np.sqrt(1 + fp ** 2))[:, None] * con.normal, rtol=0, atol=1e-12 * scale.max())
    assert np.all(side * con.normal[:, 2] > 0.9)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_translational_stiffness_equals_differences_of_the_force(profile, side):
    """normal_stiffness = dF/dR_pin = -dF/dR_c by central differences (1e-6 of |dN| |grad|^2)."""
    n = 200
    R_pin, R_c, theta = _states(profile, n, 7, side)

    def force(Rp, Rc):
        con = pin_axis_contact(Rp, Rc, theta, profile, side)
        return normal_force(con.grad, hertz_force(con.delta, C)[0])

    con = pin_axis_contact(R_pin, R_c, theta, profile, side)
    Kpp = normal_stiffness(con.grad, con.hessian, *hertz_force(con.delta, C))
    on = con.delta > 2e-6
    scale = hertz_force(con.delta, C)[1][on]
    h = 1e-10
    for j in range(3):
        e = np.zeros((n, 3))
        e[:, j] = h
        fd_p = (force(R_pin + e, R_c) - force(R_pin - e, R_c)) / (2 * h)
        fd_c = (force(R_pin, R_c + e) - force(R_pin, R_c - e)) / (2 * h)
        assert np.all(np.abs(Kpp[on, :, j] - fd_p[on]) <= 1e-6 * scale[:, None])
        assert np.all(np.abs(-Kpp[on, :, j] - fd_c[on]) <= 1e-6 * scale[:, None])
        # the curvature term N d2Delta/dR^2 is 1e-4 of dN grad grad here: check the Hessian itself
        dg = (pin_axis_contact(R_pin + e * 1e3, R_c, theta, profile, side).grad
              - pin_axis_contact(R_pin - e * 1e3, R_c, theta, profile, side).grad) / (2e3 * h)
        assert np.all(np.abs(con.hessian[:, :, j] - dg) <= 1e-6 * np.abs(con.hessian).max(axis=(1, 2))[:, None])


def test_penetration_of_an_untilted_sheave_is_1_321(profile):
    R_pin, R_c, _ = _states(profile, 50, 2)
    con = pin_axis_contact(R_pin, R_c, np.zeros((50, 3)), profile)
    r = np.hypot(*(R_pin - R_c)[:, :2].T)
    assert np.allclose(con.delta, profile(r)[0] + R_c[:, 2] - R_pin[:, 2], rtol=0, atol=1e-18)
    assert np.allclose(con.radius, r, rtol=1e-15)


def test_friction_power_equals_generalized_power(profile):
    """Friction at the pin-axis point: sum Q_i q_i' = F . v_r = -f N |v_r| <= 0 (1.328)-(1.329),
    with omega = T(theta) theta' + P(theta) k phi'."""
    n = 100
    rng = np.random.default_rng(4)
    R_pin, R_c, theta = _states(profile, n, 3)
    con = pin_axis_contact(R_pin, R_c, theta, profile)
    v_pin, v_c = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 0.01
    theta_d, phi_d = rng.normal(size=(n, 3)) * 0.1, rng.normal(size=n) * 300.0
    omega = np.einsum("nij,nj->ni", tangent_operator(theta), theta_d) \
        + np.einsum("nij,j->ni", rotation(theta), [0.0, 0.0, 1.0]) * phi_d[:, None]
    v_r = pin_axis_slip(con, v_pin, v_c, omega)
    assert np.allclose(np.sum(v_r * con.normal, axis=1), 0.0, atol=1e-13 * 30)
    N = np.full(n, 1e3)
    F, _ = friction_force(v_r, N, 0.1, 1e-3, "smooth", 0.2)
    F_c, Q_theta, Q_phi = sheave_generalized(F, con.arm, theta)
    power = np.sum(F * v_pin + F_c * v_c + Q_theta * theta_d, axis=1) + Q_phi * phi_d
    assert np.allclose(power, np.sum(F * v_r, axis=1), rtol=1e-12, atol=1e-12 * 100)
    assert np.all(power <= 0.0)


def test_grazing_is_finite():
    """Digest §10.4 item 2: Delta = +-1e-9 m and exactly 0 give finite N, dN/dDelta."""
    con_r = np.array([0.05, 0.05, 0.05])
    f = lambda r: (-0.1 * r, np.full(np.shape(r), -0.1), np.zeros(np.shape(r)))   # noqa: E731
    R_pin = np.stack([con_r, 0 * con_r, -0.1 * con_r - np.array([1e-9, 0.0, -1e-9])], -1)
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        con = pin_axis_contact(R_pin, np.zeros((3, 3)), np.zeros((3, 3)), f)
        N, dN = hertz_force(con.delta, C)
        F = normal_force(con.grad, N)
    assert np.allclose(con.delta, [1e-9, 0.0, -1e-9], rtol=1e-6, atol=1e-20)
    assert np.all(np.isfinite(F)) and N[1] == N[2] == dN[1] == dN[2] == 0.0


def test_high_speed_entry_frictionless_is_elastic():
    """Digest §10.4 item 4: a 5 g pin end entering a 10-degree cone at 55 m/s along the normal,
    frictionless H1: the penetration peaks at (5 m v^2 / (4 c))^{2/5} (energy: the forces are the
    exact gradient of 2/5 c Delta^{5/2}), no tunnelling, and it leaves with its entry speed."""
    from scipy.integrate import solve_ivp

    from tests.elements.contact.conftest import cone
    m, v, c = 5e-3, 55.0, 5e10
    R0 = np.array([[0.06, 0.0, cone(0.06)[0] + 1e-6]])
    n0 = pin_axis_contact(R0, np.zeros((1, 3)), np.zeros((1, 3)), cone).normal[0]
    zero = np.zeros((1, 3))

    def rhs(t, y):
        con = pin_axis_contact(y[None, :3], zero, zero, cone)
        return np.concatenate([y[3:], normal_force(con.grad, hertz_force(con.delta, c)[0])[0] / m])

    def deepest(t, y):
        return np.dot(pin_axis_contact(y[None, :3], zero, zero, cone).grad[0], y[3:])
    deepest.direction = -1

    y0 = np.concatenate([R0[0], -v * n0])
    sol = solve_ivp(rhs, (0.0, 2e-5), y0, method="DOP853", rtol=1e-12, atol=1e-15, events=deepest)
    assert sol.status == 0 and len(sol.t_events[0]) == 1
    d_max = pin_axis_contact(sol.y_events[0][:, :3], zero, zero, cone).delta[0]
    assert d_max == pytest.approx((5 * m * v ** 2 / (4 * c)) ** 0.4, rel=1e-7)
    v_out = sol.y[3:, -1]
    assert np.dot(v_out, n0) == pytest.approx(v, rel=1e-8)
    assert np.linalg.norm(v_out - np.dot(v_out, n0) * n0) < 1e-8 * v
