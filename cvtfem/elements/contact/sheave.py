"""The sheave side of a pin–sheave contact: its tilt rotation and the generalized forces of a
contact force on it (contact-models digest §0, §4.2, §4.4, §5.5).

The sheave pose is ``P = P(theta) P(phi k)`` (1.254) with tilt rotation vector ``theta`` (rad,
``theta . k = 0``) and spin ``phi``; ``delta P = delta o x P``. Vectorised over contacts.
"""
from __future__ import annotations

import numpy as np


def _skew(w):
    z = np.zeros(w.shape[:-1])
    return np.stack([np.stack([z, -w[..., 2], w[..., 1]], -1),
                     np.stack([w[..., 2], z, -w[..., 0]], -1),
                     np.stack([-w[..., 1], w[..., 0], z], -1)], -2)


def _coefficients(t2):
    """``(sin t / t, (1 - cos t)/t^2, (t - sin t)/t^3)`` at ``t^2``, series below ``t^2 = 1e-6``."""
    t = np.sqrt(t2)
    ts = np.where(t2 > 1e-6, t, 1.0)
    small = t2 <= 1e-6
    s1 = np.where(small, 1 - t2 / 6 + t2 * t2 / 120, np.sin(ts) / ts)
    s2 = np.where(small, 0.5 - t2 / 24 + t2 * t2 / 720, (1 - np.cos(ts)) / ts ** 2)
    s3 = np.where(small, 1 / 6 - t2 / 120 + t2 * t2 / 5040, (ts - np.sin(ts)) / ts ** 3)
    return s1, s2, s3


def rotation(theta):
    """Rotation tensors ``P(theta)`` ``(n, 3, 3)`` of rotation vectors ``theta`` ``(n, 3)`` (rad), Rodrigues."""
    theta = np.asarray(theta, dtype=float)
    W = _skew(theta)
    s1, s2, _ = _coefficients(np.sum(theta * theta, axis=-1))
    return np.eye(3) + s1[..., None, None] * W + s2[..., None, None] * (W @ W)


def tangent_operator(theta):
    """``T(theta)`` ``(n, 3, 3)`` with ``delta o = T delta theta`` for ``delta P(theta) = delta o x P``."""
    theta = np.asarray(theta, dtype=float)
    W = _skew(theta)
    _, s2, s3 = _coefficients(np.sum(theta * theta, axis=-1))
    return np.eye(3) + s2[..., None, None] * W + s3[..., None, None] * (W @ W)


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
    Q_theta = np.einsum("...ji,...j->...i", tangent_operator(theta), M)
    axis = np.einsum("...ij,j->...i", rotation(theta), np.asarray(k, dtype=float))
    return -force, Q_theta, np.sum(axis * M, axis=-1)
