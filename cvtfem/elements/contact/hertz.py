"""Hertz contact law, stiffness and contact ellipse (contact-models digest §4.1, §4.3).

Normal force ``N = c max(Delta, 0)^{3/2}`` (1.306), potential ``2/5 c Delta^{5/2}`` (1.313);
stiffness (1.325) and ellipse (1.326)–(1.327, corrected) with the coefficients ``n_a, n_b,
n_Delta`` from complete elliptic integrals (digest §4.3 [D], Johnson, *Contact Mechanics*, ch. 4).
Vectorised over contacts.
"""
from __future__ import annotations

import numpy as np
from scipy.special import ellipe, ellipkm1

from cvtfem.errors import InputError

_LOG_P_MIN = -80.0  # bracket of log(1 - m) for the eccentricity: Omega(1 - e^-80) = 1 - 3e-36
_BISECTIONS = 200   # halvings of the bracket: below the spacing of float64


def hertz_force(delta, c):
    """``(N, dN/dDelta)`` (N, N/m) for penetrations ``delta`` (m) and stiffness ``c`` (N/m^1.5), (1.306).

    Clamped before the power: no NaN at grazing (digest §10.4 item 2); both vanish for ``delta <= 0``.
    """
    d = np.maximum(np.asarray(delta, dtype=float), 0.0)
    root = np.sqrt(d)
    return c * d * root, 1.5 * c * root


def hertz_potential(delta, c):
    """Contact potential ``2/5 c max(Delta, 0)^{5/2}`` (J), (1.313)."""
    d = np.maximum(np.asarray(delta, dtype=float), 0.0)
    return 0.4 * c * d * d * np.sqrt(d)


def normal_force(grad, N):
    """Normal force on the pin ``-N dDelta/dR_pin`` (n, 3) (N): minus the gradient of the potential
    (1.311)–(1.312) for the contact's ``grad = dDelta/dR_pin`` (H1 or H2); the sheave gets its negative."""
    return -np.asarray(N, dtype=float)[..., None] * grad


def normal_stiffness(grad, hessian, N, dN):
    """``d(normal_force)/dR_pin = -(dN/dDelta grad grad + N d2Delta/dR_pin^2)`` (n, 3, 3) (N/m);
    minus it for the sheave's translation. ``N, dN`` from :func:`hertz_force`."""
    return -(np.asarray(dN, dtype=float)[..., None, None] * grad[..., :, None] * grad[..., None, :]
             + np.asarray(N, dtype=float)[..., None, None] * hessian)


def _omega_of(p):
    """``Omega`` (1.325) at ``m = 1 - p`` through ``kappa = B/A`` of Johnson's gap coefficients."""
    K, E = ellipkm1(p), ellipe(1.0 - p)
    kappa = (E / p - K) / (K - E)
    return (kappa - 1.0) / (kappa + 1.0)


def hertz_shape(Omega):
    """Coefficients ``(n_a, n_b, n_Delta)`` (-) of (1.325)–(1.326) for shape parameters ``0 <= Omega < 1``.

    Solves ``Omega(e) = Omega`` for the eccentricity by bisection on ``log(1 - e^2)``; ``n = 1``
    at ``Omega = 0`` (circle). ``Omega -> 1`` is line contact (``n_Delta -> 0``, ``c -> inf``).
    """
    Om = np.asarray(Omega, dtype=float)
    if np.any(~(Om >= 0.0) | ~(Om < 1.0)):
        raise InputError("Omega", Omega, "must lie in [0, 1) (Omega = 1 is line contact)")
    lo = np.full(Om.shape, _LOG_P_MIN)   # Omega(lo) > Omega
    hi = np.zeros(Om.shape)              # Omega(hi) = 0 <= Omega
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        above = _omega_of(np.exp(mid)) > Om
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    p = np.where(Om > 0.0, np.exp(0.5 * (lo + hi)), 1.0)
    K, E = ellipkm1(p), ellipe(1.0 - p)
    n_a = np.cbrt(2 * E / (np.pi * p))
    n_b = np.cbrt(2 * E * np.sqrt(p) / np.pi)
    return n_a, n_b, n_b ** 2 * K / E


def relative_curvature(K1, K2):
    """``(Sigma k, Omega)`` (1/m, -) of two bodies from their 2x2 curvature tensors ``(n, 2, 2)``
    in the common tangent plane (1/m, convex positive), digest §4.3 "angle-free"."""
    Kr = np.asarray(K1, dtype=float) + np.asarray(K2, dtype=float)
    tr = Kr[..., 0, 0] + Kr[..., 1, 1]
    diff = np.hypot(Kr[..., 0, 0] - Kr[..., 1, 1], 2 * Kr[..., 0, 1])  # lambda1 - lambda2
    return tr, diff / tr


def sheave_curvatures(r, fp, fpp):
    """Principal curvatures (1/m) of the sheave surface ``z = f(r)`` at radius ``r`` (m):
    ``(meridional |f''|/(1+f'^2)^{3/2}, circumferential |f'|/(r sqrt(1+f'^2)))``, digest §4.3."""
    s2 = 1.0 + np.asarray(fp, dtype=float) ** 2
    return np.abs(fpp) / s2 ** 1.5, np.abs(fp) / (r * np.sqrt(s2))


def compliance(E1, nu1, E2, nu2):
    """``eta = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`` (1/Pa) of (1.325)."""
    return (1 - nu1 ** 2) / E1 + (1 - nu2 ** 2) / E2


def hertz_stiffness(sum_k, Omega, eta):
    """Hertz stiffness ``c`` (N/m^1.5) of (1.325) from ``Sigma k`` (1/m), ``Omega``, ``eta`` (1/Pa)."""
    n_delta = hertz_shape(Omega)[2]
    return 1.0 / ((0.5 * n_delta) ** 1.5 * 1.5 * eta * np.sqrt(sum_k))


def contact_ellipse(N, sum_k, Omega, eta):
    """Semi-axes ``a >= b`` (m) and peak pressure ``p_max = 3N/(2 pi a b)`` (Pa), (1.326)–(1.327).

    ``a`` lies along the smaller relative curvature. Zero normal force gives zeros.
    """
    n_a, n_b, _ = hertz_shape(Omega)
    X = np.cbrt(1.5 * eta * np.maximum(np.asarray(N, dtype=float), 0.0) / sum_k)
    a, b = n_a * X, n_b * X
    p_max = np.where(X > 0.0, 1.5 * np.maximum(N, 0.0) / (np.pi * a * np.where(X > 0.0, b, 1.0)), 0.0)
    return a, b, p_max
