"""H2 refined biconvex kinematics (contact-models digest §5, §10.4 items 8 and 9)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from cvtfem.elements.contact.hertz import hertz_force, hertz_potential, normal_force, normal_stiffness
from cvtfem.elements.contact.pin_axis import pin_axis_contact
from cvtfem.elements.contact.refined import (pin_coefficients, pin_loads, refined_contact, refined_slip,
                                             sheave_coefficients)
from cvtfem.errors import NumericalError

C = 2.0e10
K = np.array([0.0, 0.0, 1.0])


def _quad(c0, c1, C2, x):
    return c0 + np.sum(c1 * x, -1) + 0.5 * np.einsum("...i,...ij,...j->...", x, C2, x)


def _poses(profile, n, seed, tilt=5e-3, side=1.0):
    """Crowned pin faces (R_tau 0.1-1 m, R_n 10-40 mm) at the pin-axis end near a tilted sheave."""
    rng = np.random.default_rng(seed)
    R_c = rng.normal(size=(n, 3)) * 1e-4
    gamma = rng.normal(size=(n, 2)) * tilt
    r, phi = rng.uniform(0.036, 0.088, n), rng.uniform(0, 2 * np.pi, n)
    x0 = R_c[:, :2] + np.stack([r * np.cos(phi), r * np.sin(phi)], -1)
    z_pin = R_c[:, 2] + side * (profile(r)[0] + rng.uniform(-3e-5, 3e-5, n))
    slope = rng.normal(size=(n, 2)) * tilt
    psi = phi + np.pi / 2 + rng.normal(size=n) * 0.05       # pin along the circumference
    tau = np.stack([np.cos(psi), np.sin(psi)], -1)
    Bcal = np.zeros((n, 2, 2))
    Bcal[:, 0, 0] = 1 / rng.uniform(0.1, 1.0, n)
    Bcal[:, 1, 1] = 1 / rng.uniform(0.01, 0.04, n)
    return dict(R_c=R_c, gamma=gamma, x0=x0, z_pin=z_pin, slope=slope, tau=tau, Bcal=Bcal,
                beta0=np.zeros(n), beta=np.zeros((n, 2)), side=side)


def _coefficients(profile, p):
    sh = sheave_coefficients(p["x0"], p["R_c"], p["gamma"], profile, p["side"])
    pin = pin_coefficients(p["z_pin"], p["slope"], p["tau"], p["beta0"], p["beta"], p["Bcal"], p["side"])
    return (*sh, *pin)


def test_closed_form_is_the_maximum_of_the_height_difference(profile):
    """Delta = max_x (z_pul - z_pin) and x_* its argmax, against scipy's BFGS on 100 random poses;
    the normals of both quadratics are antiparallel at x_* (digest §5.3)."""
    p = _poses(profile, 100, 1)
    coef = _coefficients(profile, p)
    sh, pin = coef[:3], coef[3:]
    con = refined_contact(p["x0"], *coef)
    for i in range(100):
        args = [tuple(c[i] for c in sh), tuple(c[i] for c in pin)]
        gap = lambda x: _quad(*args[1], x * 1e-3) - _quad(*args[0], x * 1e-3)     # noqa: E731
        res = minimize(gap, np.zeros(2), method="BFGS", options=dict(gtol=1e-14))
        assert -res.fun == pytest.approx(con.delta[i], abs=1e-12)
        assert np.allclose(res.x * 1e-3, con.offset[i], atol=1e-7)
    g_pul = sh[1] + np.einsum("nij,nj->ni", sh[2], con.offset)
    g_pin = pin[1] + np.einsum("nij,nj->ni", pin[2], con.offset)
    assert np.allclose(g_pul, g_pin, atol=1e-14)
    assert np.allclose(con.normal, np.concatenate([-g_pul, np.ones((100, 1))], 1)
                       / np.sqrt(1 + np.sum(g_pul ** 2, 1))[:, None], atol=1e-15)


def _exact_sheave_height(profile, R_c, gamma, x):
    """Height of the tilted sheave surface above the in-plane point x, by a 1-D solve along k."""
    theta = np.concatenate([np.stack([-gamma[:, 1], gamma[:, 0]], -1), np.zeros((len(x), 1))], 1)  # gamma = theta x k
    P = Rotation.from_rotvec(theta).as_matrix()
    z = np.zeros(len(x))
    for _ in range(50):      # fixed point on the body-frame height
        d = np.einsum("nji,nj->ni", P, np.concatenate([x - R_c[:, :2], (z - R_c[:, 2])[:, None]], 1))
        f, fp, _ = profile(np.hypot(d[:, 0], d[:, 1]))
        z = z - (d[:, 2] - f) / (P[:, 2, 2] - fp * (P[:, 2, 0] * d[:, 0] + P[:, 2, 1] * d[:, 1])
                                 / np.hypot(d[:, 0], d[:, 1]))
    return z


def test_sheave_coefficients_approximate_the_tilted_surface_to_second_order(profile):
    """(1.343) drops O(|gamma|^2, |x|^3): halving the tilt and the offset divides the height error by >= 4."""
    errs = []
    for s in (1.0, 0.5, 0.25):
        p = _poses(profile, 200, 2, tilt=2e-2 * s)
        rng = np.random.default_rng(3)
        x = rng.normal(size=(200, 2)) * 2e-3 * s
        sh = sheave_coefficients(p["x0"], p["R_c"], p["gamma"], profile)
        exact = _exact_sheave_height(profile, p["R_c"], p["gamma"], p["x0"] + x)
        errs.append(np.max(np.abs(_quad(*sh, x) - exact)))
    assert errs[0] / errs[1] > 3.5 and errs[1] / errs[2] > 3.5, errs


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_forces_are_minus_the_gradient_of_the_potential_for_translations(profile, side):
    """-dPi/d(translation) of pin and sheave = +-N (k - g_*) (envelope theorem, digest §10.2), by
    central differences to 1e-6 relative on 100 random poses: translating a graph
    z = q(x) by t gives z = q(x - t_perp) + t_3, so the coefficients shift exactly (by the
    mirrored t for side -1)."""
    n = 100
    p = _poses(profile, n, 4, side=side)
    mirror = np.array([1.0, 1.0, side])
    coef = _coefficients(profile, p)
    sh, pin = coef[:3], coef[3:]

    def shifted(c, t):
        c0, c1, C2 = c
        Ct = np.einsum("nij,nj->ni", C2, t[:, :2])
        return (c0 + t[:, 2] - np.sum(c1 * t[:, :2], 1) + 0.5 * np.sum(t[:, :2] * Ct, 1), c1 - Ct, C2)

    def potential(t_pul, t_pin):
        con = refined_contact(p["x0"], *shifted(sh, t_pul * mirror), *shifted(pin, t_pin * mirror), side)
        return hertz_potential(con.delta, C)

    con = refined_contact(p["x0"], *sh, *pin, side)
    N = hertz_force(con.delta, C)[0]
    F = normal_force(con.grad, N)
    on = con.delta > 2e-6
    assert on.sum() > 30
    h, zero = 1e-9, np.zeros((n, 3))
    for j in range(3):
        e = np.zeros((n, 3))
        e[:, j] = h
        fd_pin = -(potential(zero, e) - potential(zero, -e)) / (2 * h)
        fd_pul = -(potential(e, zero) - potential(-e, zero)) / (2 * h)
        scale = np.linalg.norm(F, axis=1)
        assert np.all(np.abs(F[on, j] - fd_pin[on]) <= 1e-6 * scale[on])
        assert np.all(np.abs(-F[on, j] - fd_pul[on]) <= 1e-6 * scale[on])
    assert np.allclose(F, (N * np.linalg.norm(con.grad, axis=1))[:, None] * con.normal, atol=1e-12 * np.max(N))
    assert np.all(side * con.normal[:, 2] > 0.9)
    # translational stiffness: the moving contact point, dx_* = (B - A)^-1 B dt
    def force(t_pul, t_pin):
        c = refined_contact(p["x0"], *shifted(sh, t_pul * mirror), *shifted(pin, t_pin * mirror), side)
        return normal_force(c.grad, hertz_force(c.delta, C)[0])

    Kpp = normal_stiffness(con.grad, con.hessian, *hertz_force(con.delta, C))
    dN = hertz_force(con.delta, C)[1]
    h = 1e-10
    for j in range(3):
        e = np.zeros((n, 3))
        e[:, j] = h
        fd_pin = (force(zero, e) - force(zero, -e)) / (2 * h)
        fd_pul = (force(e, zero) - force(-e, zero)) / (2 * h)
        assert np.all(np.abs(Kpp[on, :, j] - fd_pin[on]) <= 1e-6 * dN[on, None])
        assert np.all(np.abs(-Kpp[on, :, j] - fd_pul[on]) <= 1e-6 * dN[on, None])
        grad = lambda t: refined_contact(p["x0"], *sh, *shifted(pin, t * mirror), side).grad   # noqa: E731
        dg = (grad(e * 1e3) - grad(-e * 1e3)) / (2e3 * h)
        assert np.all(np.abs(con.hessian[:, :, j] - dg) <= 1e-6 * np.abs(con.hessian).max(axis=(1, 2))[:, None])


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_matching_slopes_reduce_to_the_pin_axis_point_model(profile, side):
    """a_vec = b_vec (a face with the sheave's slope, untilted): x_* = 0 and Delta, normal and
    force are those of H1 at the pin-axis point (digest §10.4 item 8)."""
    n = 50
    p = _poses(profile, n, 5, tilt=0.0, side=side)
    r = np.linalg.norm(p["x0"] - p["R_c"][:, :2], axis=1)
    e = (p["x0"] - p["R_c"][:, :2]) / r[:, None]
    c, s = p["tau"][:, 0], p["tau"][:, 1]
    p["beta"] = np.einsum("nji,nj->ni", np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2),
                          profile(r)[1][:, None] * e)            # P_phi^T (f' e_r)
    con = refined_contact(p["x0"], *_coefficients(profile, p), side)
    # round-off of a_vec - b_vec (1e-17) over the smallest eigenvalue of B - A (about 1 1/m)
    assert np.allclose(con.offset, 0.0, atol=1e-16)
    R_pin = np.concatenate([p["x0"], p["z_pin"][:, None]], 1)
    h1 = pin_axis_contact(R_pin, p["R_c"], np.zeros((n, 3)), profile, side)
    # the torus meridian is w - Rt with Rt = 0.6 m: its round-off is ulp(0.6) = 1.1e-16 m
    assert np.allclose(con.delta, h1.delta, rtol=0, atol=4.5e-16)
    assert np.allclose(con.normal, h1.normal, atol=1e-15)
    N = hertz_force(con.delta, C)[0]
    assert np.allclose(normal_force(con.grad, N), normal_force(h1.grad, N), rtol=0, atol=1e-12 * max(N.max(), 1.0))


def test_opposite_side_is_the_mirror_image(profile):
    """A configuration and its mirror z -> -z (sheave side -1, tilts and slopes reversed) have the
    same penetration and offset, mirrored contact point, normal and force."""
    n = 50
    p = _poses(profile, n, 9)
    q = dict(p, R_c=p["R_c"] * [1.0, 1.0, -1.0], gamma=-p["gamma"], z_pin=-p["z_pin"], slope=-p["slope"],
             side=-1.0)
    a = refined_contact(p["x0"], *_coefficients(profile, p))
    b = refined_contact(q["x0"], *_coefficients(profile, q), -1.0)
    mirror = np.array([1.0, 1.0, -1.0])
    assert np.array_equal(a.delta, b.delta) and np.array_equal(a.offset, b.offset)
    assert np.array_equal(a.point * mirror, b.point) and np.array_equal(a.normal * mirror, b.normal)
    N = hertz_force(a.delta, C)[0]
    assert np.array_equal(normal_force(a.grad, N) * mirror, normal_force(b.grad, N))


def test_very_curved_face_tends_to_the_pin_axis_point():
    """As the face curvature B grows past the sheave's |A| (<= 5 1/m) the contact point tends to
    the axis end, |x_*| ~ |a_vec - b_vec| / B, and Delta to the H1 penetration."""
    from tests.elements.contact.conftest import cone
    n = 20
    p = _poses(cone, n, 6, tilt=0.0)
    R_pin = np.concatenate([p["x0"], p["z_pin"][:, None]], 1)
    h1 = pin_axis_contact(R_pin, p["R_c"], np.zeros((n, 3)), cone)
    offs, gaps = [], []
    for scale in (1e2, 1e3, 1e4):
        con = refined_contact(p["x0"], *_coefficients(cone, dict(p, Bcal=p["Bcal"] * scale)))
        offs.append(np.linalg.norm(con.offset, axis=1))
        gaps.append(np.max(np.abs(con.delta - h1.delta)))
    assert np.allclose(offs[0] / offs[1], 10.0, rtol=0.06) and np.allclose(offs[1] / offs[2], 10.0, rtol=0.006)
    assert gaps[0] / gaps[1] == pytest.approx(10.0, rel=0.06) and gaps[1] / gaps[2] == pytest.approx(10.0, rel=0.006)


def test_pin_tilted_about_tau_gets_a_restoring_moment():
    """Digest §6 item 2, §10.4 item 8: a pin whose axis tilts radially by s (rotation about tau) on a
    cone moves its contact point by (f' + s) R_n radially; at fixed N the bending moment
    Q'_p = (rho x F) x k changes by -R_n N s (1 + tan^2 gamma / 2) e_r (restoring; the tan^2 term
    is the lever of the axial contact-point height rho_z, whose odd part is -s tan gamma R_n / 2)."""
    from tests.elements.contact.conftest import TAN_GAMMA, cone
    n, N, Rn = 8, 1e3, 0.02
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    e_r = np.stack([np.cos(phi), np.sin(phi)], -1)
    x0 = 0.06 * e_r
    tau = np.stack([-np.sin(phi), np.cos(phi)], -1)
    Bcal = np.broadcast_to(np.diag([0.0, 1 / Rn]), (n, 2, 2))     # cylindrical face, curved along n_perp
    z_pin = cone(0.06)[0] - 1e-5
    Q = []
    for s in (-1e-3, 1e-3):
        pin = pin_coefficients(np.full(n, z_pin), s * e_r, tau, np.zeros(n), np.zeros((n, 2)), Bcal)
        con = refined_contact(x0, *sheave_coefficients(x0, np.zeros((n, 3)), np.zeros((n, 2)), cone), *pin)
        assert np.allclose(np.sum(con.offset * e_r, 1), (s - TAN_GAMMA) * Rn, rtol=1e-12)
        R_pin = np.concatenate([x0, np.full((n, 1), z_pin)], 1)
        slope3 = np.concatenate([s * e_r, np.zeros((n, 1))], 1)
        n_perp = np.concatenate([np.stack([-tau[:, 1], tau[:, 0]], -1), np.zeros((n, 1))], 1)
        Q.append(pin_loads(normal_force(con.grad, np.full(n, N)), con.point - R_pin, slope3, np.zeros(n), n_perp)[1])
    dQ = (Q[1] - Q[0])[:, :2]
    assert np.allclose(np.sum(dQ * e_r, 1), -Rn * N * 2e-3 * (1 + TAN_GAMMA ** 2 / 2), rtol=1e-9)
    assert np.allclose(np.sum(dQ * tau, 1), 0.0, atol=1e-14)   # round-off of moments N |x_*| ~ 4 N m


def test_recentred_face_off_the_axis_end():
    """beta0 != 0: the re-centred b_vec matches the gradient of the rotated face (digest §5.4, reviewed):
    error 5e-6 (not 1.6e-4) for beta0 = 0.5 mm, R_n = 20 mm, slope 0.02."""
    beta0, Rn, sl = 0.5e-3, 0.02, 0.02
    Bcal = np.diag([0.0, 1 / Rn])[None]
    tau = np.array([[1.0, 0.0]])
    slope = np.array([[0.0, sl]])
    b, bv, _ = pin_coefficients(np.zeros(1), slope, tau, np.array([beta0]), np.zeros((1, 2)), Bcal)
    # exact: face z = beta0 + y^2/(2 Rn) in the pin frame, rotated so that its axis k gets slope (0, sl)
    th = np.array([[sl, 0.0, 0.0]])            # rotation about x: k -> (0, -sin, cos) ... choose sign below
    P = Rotation.from_rotvec(-th).as_matrix()                          # k -> (0, sin sl, cos sl): slope +sl in y
    assert P[0, 1, 2] / P[0, 2, 2] == pytest.approx(np.tan(sl))
    y = np.linspace(-3e-3, 3e-3, 20001)
    face = np.stack([0 * y, y, beta0 + y ** 2 / (2 * Rn)], -1) @ P[0].T
    i = np.argmin(np.abs(face[:, 1]))
    grad = np.gradient(face[:, 2], face[:, 1])[i]
    assert abs(bv[0, 1] - grad) < 2e-5


def test_point_loads_and_slip_power():
    """Q_p, Q'_p and Q_phi do the virtual work F . dR_* of (1.350), and with the slip at R_* the
    friction power is F . v_r (digest §5.5–5.6)."""
    rng = np.random.default_rng(8)
    n = 50
    F = rng.normal(size=(n, 3))
    rho = rng.normal(size=(n, 3)) * 1e-3
    u1 = np.concatenate([rng.normal(size=(n, 2)) * 1e-2, np.zeros((n, 1))], 1)
    H = rng.uniform(-3e-3, 3e-3, n)
    n_perp = np.concatenate([rng.normal(size=(n, 2)), np.zeros((n, 1))], 1)
    n_perp /= np.linalg.norm(n_perp, axis=1, keepdims=True)
    du, du1, dphi = rng.normal(size=(n, 3)), np.concatenate([rng.normal(size=(n, 2)), np.zeros((n, 1))], 1), \
        rng.normal(size=n)
    Qp, Q1, Qphi = pin_loads(F, rho, u1, H, n_perp)
    dR = du + np.cross(np.cross(K, du1), rho) + (np.cross(K + u1, rho) + H[:, None] * n_perp) * dphi[:, None]
    assert np.allclose(np.sum(Qp * du + Q1 * du1, 1) + Qphi * dphi, np.sum(F * dR, 1), rtol=1e-12, atol=1e-15)
    with pytest.raises(NumericalError):
        refined_contact(np.zeros((1, 2)), np.zeros(1), np.zeros((1, 2)), np.eye(2)[None], np.zeros(1),
                        np.zeros((1, 2)), 0.5 * np.eye(2)[None])
    # slip: rigid motion shared by both bodies gives zero slip
    from cvtfem.elements.contact.refined import RefinedContact
    R_s = rng.normal(size=(n, 3)) * 0.05
    nrm = np.tile(K, (n, 1))
    con = RefinedContact(np.zeros(n), np.zeros((n, 2)), R_s, -nrm, np.zeros((n, 3, 3)), nrm)
    R_pin, R_c = R_s - rho, rng.normal(size=(n, 3)) * 1e-3
    w, v0 = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    slip = refined_slip(con, R_pin, v0 + np.cross(w, R_pin - R_c), w, R_c, v0, w)
    assert np.allclose(slip, 0.0, atol=1e-15)


def test_batched_equals_one_contact_at_a_time(profile):
    """Digest §10.4 item 10: H1 and H2 over 30 contacts equal the same contacts one by one."""
    n = 30
    p = _poses(profile, n, 12)
    con = refined_contact(p["x0"], *_coefficients(profile, p))
    R_pin = np.concatenate([p["x0"], p["z_pin"][:, None]], 1)
    theta = np.concatenate([p["gamma"][:, ::-1] * [-1.0, 1.0], np.zeros((n, 1))], 1)
    h1 = pin_axis_contact(R_pin, p["R_c"], theta, profile)
    for i in range(0, n, 7):
        q = {k: (v[i:i + 1] if isinstance(v, np.ndarray) else v) for k, v in p.items()}
        one = refined_contact(q["x0"], *_coefficients(profile, q))
        for a, b in zip((con.delta, con.point, con.grad, con.hessian), (one.delta, one.point, one.grad, one.hessian)):
            assert np.allclose(a[i], b[0], rtol=1e-15, atol=0)
        h1_one = pin_axis_contact(R_pin[i:i + 1], p["R_c"][i:i + 1], theta[i:i + 1], profile)
        for a, b in zip((h1.delta, h1.grad, h1.hessian), (h1_one.delta, h1_one.grad, h1_one.hessian)):
            assert np.allclose(a[i], b[0], rtol=1e-15, atol=0)
