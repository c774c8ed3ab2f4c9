"""Hertz contact with refined biconvex kinematics, H2 (contact-models digest §5, (1.330)–(1.352)).

Both surfaces are local graphs over the plane normal to ``k``, quadratic about the in-plane pin
point ``x0`` (1.331): sheave ``z = a + a.x + x.A x/2``, pin face ``z = b + b.x + x.B x/2`` with
``B - A`` positive definite. The contact point, penetration (along ``k``) and normal are the
closed form of §5.3; the normal force on the pin, ``side N (k - g_*)`` at ``R_*``, and its
stiffness for translations are :func:`cvtfem.elements.contact.hertz.normal_force` and
``normal_stiffness`` with ``grad`` and ``hessian`` (envelope theorem, digest §10.2). The
coefficients live in the frame of a sheave below the pin: for a sheave on the other side
(``side = -1``, its material on the ``+k`` side) the functions mirror ``z -> -z`` on the way in
and back on the way out. Vectorised over contacts: in-plane vectors ``(n, 2)``, tensors ``(n, 2, 2)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.errors import NumericalError


@dataclass(frozen=True)
class RefinedContact:
    """Closed-form H2 contact (arrays over contacts)."""

    delta: np.ndarray    # (n,) penetration max(z_pul - z_pin) along k (m)
    offset: np.ndarray   # (n, 2) contact point relative to x0, x_hat_* (m)
    point: np.ndarray    # (n, 3) contact point R_* (m), mid-way between the surfaces
    grad: np.ndarray     # (n, 3) dDelta/d(pin translation) = -side (k - g_*) (-), g_* the common slope
    hessian: np.ndarray  # (n, 3, 3) d2 Delta/d(pin translation)^2 (1/m): in-plane A (B - A)^-1 B
    normal: np.ndarray   # (n, 3) outward unit sheave normal -grad/|grad|


def _rot2(tau):
    """2x2 rotations ``P_phi`` with first column ``tau`` (n, 2) (unit)."""
    return np.stack([np.stack([tau[..., 0], -tau[..., 1]], -1), np.stack([tau[..., 1], tau[..., 0]], -1)], -2)


def _tilted(c0, c1, C2, gamma):
    """Coefficients of a tilted quadratic graph, first order in the tilt ``gamma`` (1.343)/(1.345)."""
    ga = np.sum(gamma * c1, axis=-1)
    Cg = np.einsum("...ij,...j->...i", C2, gamma)
    lin = c1 * (1 - ga)[..., None] - gamma
    quad = C2 * (1 - ga)[..., None, None] - Cg[..., :, None] * c1[..., None, :] - c1[..., :, None] * Cg[..., None, :]
    return c0, lin, quad


def sheave_coefficients(x0, R_c, gamma, profile, side=1.0):
    """Sheave quadratic ``(a, a_vec, A)`` (m, -, 1/m) about in-plane points ``x0`` (n, 2) (m); (1.339)–(1.343).

    ``R_c`` (n, 3) sheave centre (m), ``gamma = theta x k`` (n, 2) its tilt (rad), ``profile(r) ->
    (f, f', f'')`` its meridian ``z - z_c = side f(r)``. One pass ``xi0 = x0 - x_c - f(|x0 - x_c|) gamma``.
    """
    s = np.asarray(side, dtype=float)
    R_c = np.asarray(R_c, dtype=float) * np.stack([np.ones_like(s), np.ones_like(s), s], -1)
    gamma = s[..., None] * np.asarray(gamma, dtype=float)
    xt = np.asarray(x0, dtype=float) - R_c[..., :2]
    xi = xt - profile(np.linalg.norm(xt, axis=-1))[0][..., None] * gamma
    r = np.linalg.norm(xi, axis=-1)
    f, fp, fpp = profile(r)
    eps = xi / r[..., None]
    nu = np.stack([-eps[..., 1], eps[..., 0]], -1)
    alpha = fp[..., None] * eps
    Acal = fpp[..., None, None] * eps[..., :, None] * eps[..., None, :] \
        + (fp / r)[..., None, None] * nu[..., :, None] * nu[..., None, :]
    a = R_c[..., 2] + f - np.sum(gamma * xt, axis=-1)
    return _tilted(a, alpha, Acal, gamma)


def pin_coefficients(z_pin, slope, tau, beta0, beta, Bcal, side=1.0):
    """Pin-face quadratic ``(b, b_vec, B)`` (m, -, 1/m) at the pin-axis end; (1.344)–(1.345).

    ``z_pin`` (n,) axial position of the axis end (m), ``slope = u'_p`` (n, 2) axis slope there
    (-), ``tau`` (n, 2) unit in-plane pin direction ``P_phi e_1``; face ``z = beta0 + beta.xi +
    xi.Bcal xi/2`` in the pin frame (m, -, 1/m; ``Bcal`` (n, 2, 2), crowned: ``diag(1/R_tau,
    1/R_n)``). A face not through the axis end (``beta0 != 0``) is re-centred at
    ``xi0 = -beta0 P_phi^T gamma`` first (digest §5.4, reviewed). ``side`` as for the sheave it touches;
    the face is given in the end's own frame (its outward axis towards that sheave).
    """
    s = np.asarray(side, dtype=float)
    gamma = s[..., None] * np.asarray(slope, dtype=float)
    Pp = _rot2(np.asarray(tau, dtype=float))
    beta0, beta, Bcal = (np.asarray(x, dtype=float) for x in (beta0, beta, Bcal))
    xi0 = -beta0[..., None] * np.einsum("...ji,...j->...i", Pp, gamma)
    beta0 = beta0 + np.sum(beta * xi0, axis=-1) + 0.5 * np.einsum("...i,...ij,...j->...", xi0, Bcal, xi0)
    beta = beta + np.einsum("...ij,...j->...i", Bcal, xi0)
    beta_p = np.einsum("...ij,...j->...i", Pp, beta)
    B_p = Pp @ Bcal @ np.swapaxes(Pp, -1, -2)
    return _tilted(s * np.asarray(z_pin, dtype=float) + beta0, beta_p, B_p, gamma)


def refined_contact(x0, a, a_vec, A, b, b_vec, B, side=1.0) -> RefinedContact:
    """Closed-form contact point and penetration of §5.3 for quadratics about ``x0`` (n, 2) (m).

    ``x_* = (B - A)^-1 (a_vec - b_vec)``, ``Delta = a - b + (a_vec - b_vec) . x_*/2``
    ``= max_x (z_pul - z_pin)``. The coefficients come from :func:`sheave_coefficients` and
    :func:`pin_coefficients` with the same ``side``; the results are in world coordinates.
    Raises :class:`~cvtfem.errors.NumericalError` where ``B - A`` is not positive definite (the
    surfaces are not locally biconvex).
    """
    M = np.asarray(B, dtype=float) - A
    det = M[..., 0, 0] * M[..., 1, 1] - M[..., 0, 1] * M[..., 1, 0]
    if np.any(~(det > 0.0) | ~(M[..., 0, 0] > 0.0)):
        bad = np.flatnonzero(~(det > 0.0) | ~(M[..., 0, 0] > 0.0))
        raise NumericalError(f"H2 contact: B - A not positive definite at contacts {bad[:10].tolist()}",
                             component="contact.refined")
    da = np.asarray(a_vec, dtype=float) - b_vec
    x = np.stack([M[..., 1, 1] * da[..., 0] - M[..., 0, 1] * da[..., 1],
                  M[..., 0, 0] * da[..., 1] - M[..., 1, 0] * da[..., 0]], -1) / det[..., None]
    delta = np.asarray(a, dtype=float) - b + 0.5 * np.sum(da * x, axis=-1)
    Ax = np.einsum("...ij,...j->...i", A, x)
    Bx = np.einsum("...ij,...j->...i", B, x)
    z_pul = a + np.sum(a_vec * x, axis=-1) + 0.5 * np.sum(x * Ax, axis=-1)
    z_pin = b + np.sum(b_vec * x, axis=-1) + 0.5 * np.sum(x * Bx, axis=-1)
    s = np.asarray(side, dtype=float) * np.ones(delta.shape)
    AMB = np.einsum("...ij,...jk->...ik", A, np.stack([np.stack([M[..., 1, 1], -M[..., 0, 1]], -1),
                                                       np.stack([-M[..., 1, 0], M[..., 0, 0]], -1)], -2)
                    / det[..., None, None]) @ B
    hessian = np.zeros(delta.shape + (3, 3))
    hessian[..., :2, :2] = AMB
    point = np.concatenate([np.asarray(x0, dtype=float) + x, (0.5 * s * (z_pul + z_pin))[..., None]], -1)
    grad = np.concatenate([a_vec + Ax, -s[..., None]], -1)          # S (g_*, -1): mirrored back
    return RefinedContact(delta, x, point, grad, hessian, -grad / np.linalg.norm(grad, axis=-1, keepdims=True))


def pin_loads(force, rho, slope, H, n_perp, k=(0.0, 0.0, 1.0)):
    """Pin generalized forces of a contact force ``force`` (n, 3) (N) at ``R_*``; (1.350)–(1.351).

    ``rho = R_* - R_pin`` (n, 3) (m), ``slope = u'_p`` (n, 3) (-), ``H`` (n,) the half offset
    (m; 0 for a whole pin), ``n_perp = k x tau_perp`` (n, 3). Returns ``(Q_p (n, 3) N,
    Q'_p = (rho x F) x k (n, 3) N m, Q_phi = F . [(k + u') x rho + H n_perp] (n,) N m)``; the
    chain maps ``Q_phi`` to the in-plane pin coordinates through its ``delta phi`` (1.349)/(1.352).
    """
    force, rho, slope = (np.asarray(x, dtype=float) for x in (force, rho, slope))
    k = np.broadcast_to(np.asarray(k, dtype=float), force.shape)
    lever = np.cross(k + slope, rho) + np.asarray(H, dtype=float)[..., None] * n_perp
    return force, np.cross(np.cross(rho, force), k), np.sum(force * lever, axis=-1)


def refined_slip(contact: RefinedContact, R_pin, v_pin, omega_pin, R_c, v_c, omega):
    """Slip velocity at ``R_*`` (m/s): ``E_t (v_pin + omega_pin x rho - v_c - omega x (R_* - R_c))``, §5.6.

    Material velocities of both bodies at the contact point, not ``dR_*/dt``; ``omega_pin`` is the
    pin's angular velocity ``k x u'_p_dot + omega_p k`` (rad/s), all (n, 3).
    """
    R_s = contact.point
    v = np.asarray(v_pin, dtype=float) + np.cross(omega_pin, R_s - R_pin) - v_c - np.cross(omega, R_s - R_c)
    n = contact.normal
    return v - np.sum(n * v, axis=-1, keepdims=True) * n
