"""Band geometry: contact radii from the span angle, sheave faces, flank angle.

Spec: low-order digest section 4.1, eqs. (1.36), (1.37), (1.39).  All functions
are pure and accept complex ``phi`` (used for complex-step derivatives), so no
``abs``/``max`` appears on the span-angle path.

Frame: driving axis at the origin, driven axis at ``-L i``; ``phi > 0`` means
``r1 > r2``; the band runs counter-clockwise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from cvtfem.errors import InputError


_SIGN = np.array([1.0, -1.0])


def radii(phi, length: float, L: float):
    """Contact radii of the two pulleys and their first two phi-derivatives.

    Parameters
    ----------
    phi : float or array (may be complex), rad
        Span angle.
    length : float, m
        Band (chain) length ``l``.
    L : float, m
        Centre distance.

    Returns
    -------
    r, dr, ddr : arrays of shape ``(2, *phi.shape)``, m, m/rad, m/rad^2
        ``r[0] = r1`` (driving), ``r[1] = r2`` (driven); eq. (1.36) solved and (1.39).

    Examples
    --------
    >>> r, _, _ = radii(0.0, 0.756, 0.1746)
    >>> round(float(r[0]), 5) == round(float(r[1]), 5) == round((0.756 - 2 * 0.1746) / (2 * np.pi), 5)
    True
    """
    phi = np.asarray(phi)
    s, c = np.sin(phi), np.cos(phi)
    S = (length - 2 * L * (c + phi * s)) / np.pi
    sign = _SIGN if phi.ndim == 0 else _SIGN.reshape((2,) + (1,) * phi.ndim)
    r = 0.5 * (S + sign * L * s)
    dr = L * c * (0.5 * sign - phi / np.pi)
    ddr = -L * s * (0.5 * sign - phi / np.pi) - L * c / np.pi
    return r, dr, ddr


def wrap_half_angles(phi):
    """Wrap half-angles ``theta*_1 = pi/2 + phi``, ``theta*_2 = pi/2 - phi`` (rad), shape ``(2, ...)``."""
    phi = np.asarray(phi)
    return np.array([np.pi / 2 + phi, np.pi / 2 - phi])


@dataclass(frozen=True)
class Sheave:
    """Sheave face of one pulley (both sheaves of a pair are mirror images).

    Attributes
    ----------
    profile : str
        "conical" or "toroidal".
    gamma : float, rad
        Flank angle of a conical face (unused for toroidal faces).
    R : float, m
        Radius of the generating arc of a toroidal face, eq. (1.37).
    y : float, m
        Offset of the arc centre from the axis (signed radial coordinate ``-y``).
    w : float, m
        Band half-width.
    """

    profile: str
    gamma: float
    R: float = 0.0
    y: float = 0.0
    w: float = 0.0

    def z0(self, r):
        """Axial position of the sheave reference for contact at radius r, m (eq. (1.37) solved).

        Conical faces use ``z0 = w - r tan(gamma)`` (reference where the face meets the axis).
        """
        if self.profile == "conical":
            return self.w - r * np.tan(self.gamma)
        return self.w + np.sqrt(self.R ** 2 - (r + self.y) ** 2)

    def tan_gamma(self, r):
        """Local ``tan(gamma) = -dz0/dr`` at contact radius r."""
        if self.profile == "conical":
            return np.tan(self.gamma) + 0.0 * r
        s = (r + self.y) / self.R
        return s / np.sqrt(1.0 - s * s)

    def d2z0(self, r):
        """``d^2 z0 / dr^2 = -1 / (R cos^3 gamma)`` (toroidal) or 0 (conical), 1/m."""
        if self.profile == "conical":
            return 0.0 * r
        s = (r + self.y) / self.R
        return -1.0 / (self.R * (1.0 - s * s) ** 1.5)

    def gamma_at(self, r):
        """Local flank angle at contact radius r, rad."""
        return np.arctan(self.tan_gamma(r))

    def lever(self, r):
        """Axial position of the contact point relative to the tilt pivot, ``w - z0(r)``, m (eq. (1.63))."""
        return self.w - self.z0(r)


def phi_for_ratio(ratio: float, length: float, L: float) -> float:
    """Span angle at which ``r2 / r1 = ratio`` (the geometric ratio without slip), rad.

    ``r2/r1`` decreases monotonically in phi over the admissible range, so the root is bracketed
    by the angles at which a radius vanishes.
    """
    if not ratio > 0:
        raise InputError("ratio", ratio, "must be positive")
    lo, hi = admissible_phi(length, L)
    g = lambda p: float(np.log(radii(p, length, L)[0][1] / radii(p, length, L)[0][0]) - np.log(ratio))  # noqa: E731
    if g(lo) * g(hi) > 0:
        raise InputError("ratio", ratio, "must be reachable with this band length and centre distance",
                         f"range {np.exp(g(hi)) * ratio:.3g}..{np.exp(g(lo)) * ratio:.3g}")
    return brentq(g, lo, hi, xtol=1e-14)


def phi_for_ratios(ratios, length: float, L: float) -> np.ndarray:
    """Vectorised :func:`phi_for_ratio` for an array of ratios ``r2 / r1`` (rad), by bisection to rounding.

    ``log(r2/r1)`` falls monotonically in phi on the admissible interval, so 64 halvings of that
    interval give each root to the last bit, as brentq at ``xtol = 1e-14`` does.
    """
    ratios = np.asarray(ratios, dtype=float)
    lo, hi = admissible_phi(length, L)
    target = np.log(ratios)

    def g(p):
        r = radii(p, length, L)[0]
        return np.log(r[1] / r[0]) - target

    bad = (g(np.full_like(target, lo)) < 0) | (g(np.full_like(target, hi)) > 0) | ~(ratios > 0)
    if bad.any():
        phi_for_ratio(float(ratios[bad][0]), length, L)  # raises the InputError that names the ratio
    a, b = np.full_like(target, lo), np.full_like(target, hi)
    for _ in range(64):
        m = 0.5 * (a + b)
        right = g(m) > 0  # root right of m
        a, b = np.where(right, m, a), np.where(right, b, m)
    return 0.5 * (a + b)


def admissible_phi(length: float, L: float, r_min: float = 1e-4) -> tuple[float, float]:
    """Span-angle interval on which both radii exceed ``r_min`` (m), rad."""
    f1 = lambda p: float(radii(p, length, L)[0][0]) - r_min  # noqa: E731
    f2 = lambda p: float(radii(p, length, L)[0][1]) - r_min  # noqa: E731
    lim = np.pi / 2 - 1e-9
    return brentq(f1, -lim, 0.0), brentq(f2, 0.0, lim)


def admissible_ratio_range(length: float, L: float, r_min: float, r_max: float) -> tuple[float, float]:
    """Smallest and largest ratio ``r2 / r1`` with both contact radii in ``[r_min, r_max]`` (m).

    ``r1`` grows and ``r2`` falls with the span angle phi (eq. (1.36)), so the largest ratio is at
    the smallest phi with ``r1 >= r_min`` and ``r2 <= r_max``, the smallest at the largest phi with
    ``r2 >= r_min`` and ``r1 <= r_max``.
    """
    lo, hi = admissible_phi(length, L)
    r = lambda p, k: float(radii(p, length, L)[0][k])  # noqa: E731

    def root(k: int, value: float, default: float) -> float:
        f = lambda p: r(p, k) - value  # noqa: E731
        return brentq(f, lo, hi, xtol=1e-14) if f(lo) * f(hi) < 0 else default

    phi_lo = max(root(0, r_min, lo), root(1, r_max, lo))
    phi_hi = min(root(1, r_min, hi), root(0, r_max, hi))
    if phi_lo >= phi_hi:
        raise InputError("cvt.geometry", (r_min, r_max), "admits no span angle for this band length and centre distance")
    return r(phi_hi, 1) / r(phi_hi, 0), r(phi_lo, 1) / r(phi_lo, 0)


def path_point(s_tilde, phi, length: float, L: float):
    """Position on the band path of the path coordinate ``s_tilde`` (m), spec section 4.3 path map.

    Parameters
    ----------
    s_tilde : array, m
        Counter-clockwise arc length from section X (driving pulley, ``theta = 0``), taken mod ``length``.
    phi : float (may be complex), rad
        Span angle; the piece each point belongs to is chosen with ``phi.real``.

    Returns
    -------
    u : array ``(2, n)``, m
        In-plane position (x, y).
    """
    s = np.mod(np.asarray(s_tilde, dtype=float), length)
    r, _, _ = radii(phi, length, L)
    r1, r2 = r[0], r[1]
    a1, a2 = r1 * (np.pi / 2 + phi), r2 * (np.pi / 2 - phi)
    Lc = L * np.cos(phi)
    a1r, a2r, Lcr = np.real(a1), np.real(a2), np.real(Lc)
    s = np.where(s >= length - a1r, s - length, s)  # arc 1 straddles s = 0
    out = np.zeros((2,) + s.shape, dtype=np.result_type(phi, float))
    e_r = lambda t: np.stack([np.cos(t), np.sin(t)])  # noqa: E731
    e_t = lambda t: np.stack([-np.sin(t), np.cos(t)])  # noqa: E731
    arc1 = s < a1r
    span1 = (s >= a1r) & (s < a1r + Lcr)
    arc2 = (s >= length / 2 - a2r) & (s < length / 2 + a2r)
    span2 = s >= length / 2 + a2r
    th = s[arc1] / r1
    out[:, arc1] = r1 * e_r(th)
    tau = (s[span1] - a1) / Lc
    b = np.pi / 2 + phi
    out[:, span1] = (r1 * e_r(b))[:, None] + tau * Lc * e_t(b)[:, None]
    th = (s[arc2] - length / 2) / r2
    out[:, arc2] = np.array([-L, 0.0])[:, None] + r2 * e_r(np.pi + th)
    tau = (s[span2] - length / 2 - a2) / Lc
    b = -np.pi / 2 - phi
    out[:, span2] = (r1 * e_r(b))[:, None] + (tau - 1) * Lc * e_t(b)[:, None]
    return out
