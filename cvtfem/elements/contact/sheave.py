"""The sheave side of a pin–sheave contact: its tilt rotation and the generalized forces of a
contact force on it (contact-models digest §0, §4.2, §4.4, §5.5).

The sheave pose is ``P = P(theta) P(phi k)`` (1.254) with tilt rotation vector ``theta`` (rad,
``theta . k = 0``) and spin ``phi``; ``delta P = delta o x P``. Vectorised over contacts.
"""
from __future__ import annotations

import numpy as np


def _coefficients(t2):
    """``(sin t / t, (1 - cos t)/t^2, (t - sin t)/t^3)`` at ``t^2``, series below ``t^2 = 1e-6``."""
    t = np.sqrt(t2)
    ts = np.where(t2 > 1e-6, t, 1.0)
    small = t2 <= 1e-6
    s1 = np.where(small, 1 - t2 / 6 + t2 * t2 / 120, np.sin(ts) / ts)
    s2 = np.where(small, 0.5 - t2 / 24 + t2 * t2 / 720, (1 - np.cos(ts)) / ts ** 2)
    s3 = np.where(small, 1 / 6 - t2 / 120 + t2 * t2 / 5040, (ts - np.sin(ts)) / ts ** 3)
    return s1, s2, s3


def rotate(theta, v, inverse=False):
    """``P(theta) v`` (or ``P(theta)^T v``) for rotation vectors ``theta`` and vectors ``v`` (n, 3), Rodrigues."""
    theta, v = np.asarray(theta, dtype=float), np.asarray(v, dtype=float)
    s1, s2, _ = _coefficients(np.sum(theta * theta, axis=-1))
    tv = np.cross(theta, v)
    sign = -1.0 if inverse else 1.0
    return v + sign * s1[..., None] * tv + s2[..., None] * np.cross(theta, tv)


def tilt_forces(theta, moment):
    """``T(theta)^T M`` (n, 3): generalized forces on the rotation vector ``theta`` of moments ``M``
    (n, 3) (N m), with ``delta o = T delta theta`` for ``delta P(theta) = delta o x P`` (tangent operator
    ``T = E + (1 - cos t)/t^2 Theta + (t - sin t)/t^3 Theta^2``, ``Theta = theta x``)."""
    theta, moment = np.asarray(theta, dtype=float), np.asarray(moment, dtype=float)
    _, s2, s3 = _coefficients(np.sum(theta * theta, axis=-1))
    tm = np.cross(theta, moment)
    return moment - s2[..., None] * tm + s3[..., None] * np.cross(theta, tm)


def sheave_generalized(force, arm, theta, k=(0.0, 0.0, 1.0)):
    """Generalized forces on the sheave of contact forces ``force`` ``(n, 3)`` (N) on the pin.

    The sheave feels ``-force`` at ``R_c + arm`` (``arm`` ``(n, 3)``, m): translation ``-force``
    (N), moment ``M = -(arm x force)`` (N m), and with ``delta o = T(theta) delta theta +
    P(theta) k delta phi`` the tilt forces ``Q_theta = T^T M`` ``(n, 3)`` (N m; the lead keeps the
    two components normal to ``k``) and the spin force ``Q_phi = (P(theta) k) . M`` ``(n,)``;
    (1.323), (1.324), (1.329) with the exact tangent operator in place of ``delta o ~ delta theta``.
    """
    force, arm, theta = (np.asarray(x, dtype=float) for x in (force, arm, theta))
    M = -np.cross(arm, force)
    axis = rotate(theta, np.broadcast_to(np.asarray(k, dtype=float), M.shape))
    return -force, tilt_forces(theta, M), np.sum(axis * M, axis=-1)
