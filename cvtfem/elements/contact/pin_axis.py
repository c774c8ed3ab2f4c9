"""Hertz contact at the pin-axis end point, H1 (contact-models digest §4.1, §4.2, §4.4).

Penetration (1.321) ``Delta = f(r) - s (z_pin - z_c)`` in the tilted sheave frame (1.317)–(1.318),
``s = +-1`` the side of the sheave (its material on the ``-s k`` side). Normal forces are the
exact gradient of the potential ``2/5 c Delta^{5/2}`` (1.311)–(1.313): on the pin ``-N dDelta/dR``
``= N sqrt(1 + f'^2) n`` (digest §4.2 [D]; :func:`cvtfem.elements.contact.hertz.normal_force` with
``grad``), so energy balances hold to round-off; the source's ``N n`` (1.322) is
``1/sqrt(1 + f'^2)`` of it (docs/chain.md). Vectorised over contacts.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.contact.sheave import rotate

K = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class PinAxisContact:
    """Geometry of H1 contacts (arrays over contacts)."""

    delta: np.ndarray    # (n,) penetration along the sheave axis (m), > 0 in contact
    normal: np.ndarray   # (n, 3) outward unit sheave normal n at the pin-axis point
    grad: np.ndarray     # (n, 3) dDelta/dR_pin (-); dDelta/dR_c = -grad
    hessian: np.ndarray  # (n, 3, 3) d2 Delta/dR_pin^2 (1/m)
    arm: np.ndarray      # (n, 3) R_pin - R_c (m)
    radius: np.ndarray   # (n,) contact radius r (m), (1.317)


def pin_axis_contact(R_pin, R_c, theta, profile, side=1.0) -> PinAxisContact:
    """H1 penetration and normal at pin-axis points ``R_pin`` ``(n, 3)`` (m), (1.317)–(1.321).

    ``R_c`` ``(n, 3)`` sheave centres (m), ``theta`` ``(n, 3)`` sheave tilts (rad), ``profile(r)
    -> (f, f', f'')`` the sheave surface ``z - z_c = s f(r)`` (m, -, 1/m), vectorised; ``side``
    ``s`` (n,) or scalar. The exact derivative with respect to tilt is ``(grad x arm)`` through
    :func:`cvtfem.elements.contact.sheave.tilt_forces`, which
    :func:`cvtfem.elements.contact.sheave.sheave_generalized` uses.
    """
    R_pin, R_c = np.asarray(R_pin, dtype=float), np.asarray(R_c, dtype=float)
    s = np.asarray(side, dtype=float)
    arm = R_pin - R_c
    d = rotate(theta, arm, inverse=True)                    # P^T (R - R_c), sheave frame
    r = np.hypot(d[..., 0], d[..., 1])
    f, fp, fpp = profile(r)
    e_xi = np.stack([d[..., 0], d[..., 1], np.zeros_like(r)], -1) / np.where(r > 0, r, 1.0)[..., None]
    g = fp[..., None] * e_xi - s[..., None] * K            # dDelta/dd in the sheave frame
    grad = rotate(theta, g)
    normal = -grad / np.linalg.norm(grad, axis=-1, keepdims=True)
    e, k = rotate(theta, e_xi), rotate(theta, np.broadcast_to(K, e_xi.shape))
    ee, kk = e[..., :, None] * e[..., None, :], k[..., :, None] * k[..., None, :]
    hessian = fpp[..., None, None] * ee + (fp / np.where(r > 0, r, 1.0))[..., None, None] * (np.eye(3) - kk - ee)
    return PinAxisContact(f - s * d[..., 2], normal, grad, hessian, arm, r)


def pin_axis_slip(contact: PinAxisContact, v_pin, v_c, omega):
    """Slip velocity ``E_t (v_pin - v_c - omega x (R_pin - R_c))`` (m/s), ``E_t = E - n n``; (1.328)-(1.329).

    ``v_pin``, ``v_c`` ``(n, 3)`` (m/s), ``omega`` ``(n, 3)`` sheave angular velocity (rad/s).
    """
    v = np.asarray(v_pin, dtype=float) - v_c - np.cross(omega, contact.arm)
    n = contact.normal
    return v - np.sum(n * v, axis=-1, keepdims=True) * n
