"""Estimate formulas of section 1.3 (low-order digest section 3).

Clamping force for a torque (1.13), Euler force of a pin (1.14), the Green's
functions of a pinned-pinned pin with and without axial compression
((1.31), (1.33) with the missing 1/l restored, erratum 9), and the frequencies
of the discrete chain (1.34)-(1.35).
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError


def _positive(name: str, value: float) -> None:
    if not np.all(np.asarray(value) > 0):
        raise InputError(name, value, "must be positive")


def min_clamping_force(torque, radius, friction: float, gamma):
    """Smallest clamping force (per sheave) that transmits ``torque`` without gross slip, N. Eq. (1.13).

    ``F >= M cos(gamma) / (2 f r)``; apply a safety factor >= 1.1 on top (section 1.7).

    Parameters
    ----------
    torque : float, N m (magnitude is used)
    radius : float, m
        Contact radius.
    friction : float
        Friction coefficient f.
    gamma : float, rad
        Flank angle.

    Examples
    --------
    >>> round(float(min_clamping_force(200.0, 0.037, 0.1, np.radians(10.0))) / 1e3, 1)
    26.6
    """
    _positive("radius", radius)
    _positive("friction", friction)
    return np.abs(torque) * np.cos(gamma) / (2.0 * friction * radius)


def euler_force(E: float, I: float, length: float) -> float:
    """Euler critical force of a pinned-pinned pin ``P* = (pi / l)^2 E I``, N. Eq. (1.14).

    Examples
    --------
    >>> round(float(euler_force(2.1e11, 6.8e-12, 0.033)))
    12942
    """
    for name, v in (("E", E), ("I", I), ("length", length)):
        _positive(name, v)
    return (np.pi / length) ** 2 * E * I


def green_compressed(s, s_star, length: float, EI: float, P: float):
    """Deflection at ``s`` of a pinned-pinned pin compressed by ``P`` under a unit force at ``s_star``, m/N.

    Eq. (1.31) with ``omega^2 = P / EI`` (1.29); singular at the Euler force.
    """
    if not 0 < P < euler_force(1.0, EI, length):
        raise InputError("P", P, "must lie strictly between 0 and the Euler force (pi/l)^2 EI")
    w = np.sqrt(P / EI)
    s, s_star = np.broadcast_arrays(np.asarray(s, float), np.asarray(s_star, float))
    left = -np.sin(w * (s_star - length)) * np.sin(w * s) / (w * np.sin(w * length)) + (s_star - length) * s / length
    right = -np.sin(w * s_star) * np.sin(w * (s - length)) / (w * np.sin(w * length)) + s_star * (s - length) / length
    return np.where(s < s_star, left, right) / (EI * w * w)


def green_plain(s, s_star, length: float, EI: float):
    """Deflection Green's function of a pinned-pinned beam without compression, m/N. Eq. (1.33), corrected.

    The source omits the factor ``1 / l`` (erratum 9); ``g(l/2, l/2) = l^3 / (48 EI)``.
    """
    s, s_star = np.broadcast_arrays(np.asarray(s, float), np.asarray(s_star, float))
    left = (length - s_star) * s * (2 * s_star * length - s_star ** 2 - s ** 2)
    right = (length - s) * s_star * (2 * s * length - s ** 2 - s_star ** 2)
    return np.where(s < s_star, left, right) / (6.0 * EI * length)


def compressed_stiffness_factor(P: float, P_euler: float) -> float:
    """Mid-span amplification ``G/g ~ 1 / (1 - P/P*)`` of pin bending compliance under compression (section 3.3)."""
    if not 0 <= P < P_euler:
        raise InputError("P", P, f"must lie in [0, P*) with P* = {P_euler:g} N")
    return 1.0 / (1.0 - P / P_euler)


def chain_speed(omega1, r1):
    """Chain speed without slip ``v = omega1 r1``, m/s. Eq. (1.34)."""
    return np.asarray(omega1) * np.asarray(r1)


def link_frequency(omega1, r1, link_length: float):
    """Link-passing frequency ``f_link = v / l_link``, Hz. Eq. (1.34)."""
    _positive("link_length", link_length)
    return chain_speed(omega1, r1) / link_length


def chain_frequency(omega1, r1, chain_length: float):
    """Chain-revolution frequency ``f_chain = v / l_chain``, Hz. Eq. (1.35)."""
    _positive("chain_length", chain_length)
    return chain_speed(omega1, r1) / chain_length
