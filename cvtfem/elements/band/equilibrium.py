"""One-DOF equilibrium model: span angle for given clamping forces and its stability.

Spec: low-order digest section 4.2, eqs. (1.38)-(1.39).  The potential of the
clamping forces is ``Pi(phi) = F1 z1 + F2 z2`` with ``z_k = z0_k(r_k(phi))``;
equilibria are zeros of ``Pi'`` and are stable where ``Pi'' > 0``.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cvtfem.elements.band.geometry import Sheave, admissible_phi, radii
from cvtfem.errors import InputError


def potential(phi, F, sheaves: tuple[Sheave, Sheave], length: float, L: float):
    """Clamping potential ``Pi = sum F_k z_k`` (per sheave), J. Eq. (1.38)."""
    r, _, _ = radii(phi, length, L)
    return F[0] * sheaves[0].z0(r[0]) + F[1] * sheaves[1].z0(r[1])


def potential_derivatives(phi, F, sheaves: tuple[Sheave, Sheave], length: float, L: float):
    """``Pi'(phi)`` (N m/rad) and ``Pi''(phi)`` (N m/rad^2), eq. (1.39) and section 4.2 [D]."""
    r, dr, ddr = radii(phi, length, L)
    d1 = sum(-F[k] * sheaves[k].tan_gamma(r[k]) * dr[k] for k in range(2))
    d2 = sum(F[k] * (sheaves[k].d2z0(r[k]) * dr[k] ** 2 - sheaves[k].tan_gamma(r[k]) * ddr[k]) for k in range(2))
    return d1, d2


def cone_equilibrium_angle(F1: float, F2: float, gamma: float) -> float:
    """Closed-form equilibrium ``phi = pi/2 (f1 - f2)/(f1 + f2)``, ``f_k = F_k tan(gamma)``, for equal cones."""
    f1, f2 = F1 * np.tan(gamma), F2 * np.tan(gamma)
    return 0.5 * np.pi * (f1 - f2) / (f1 + f2)


def equilibrium_angle(F, sheaves: tuple[Sheave, Sheave], length: float, L: float) -> float:
    """Span angle where ``Pi'(phi) = 0`` for clamping forces ``F = (F1, F2)`` (N), rad.

    Raises InputError when no equilibrium lies in the admissible range.
    """
    lo, hi = admissible_phi(length, L)
    g = lambda p: float(potential_derivatives(p, F, sheaves, length, L)[0])  # noqa: E731
    if g(lo) * g(hi) > 0:
        raise InputError("F", tuple(F), "must admit an equilibrium span angle in the admissible range")
    return brentq(g, lo, hi, xtol=1e-14)


def forces_for_angle(phi: float, sheaves: tuple[Sheave, Sheave], length: float, L: float) -> float:
    """Force ratio ``F1/F2`` that makes ``phi`` an equilibrium (``Pi'(phi) = 0``)."""
    r, dr, _ = radii(phi, length, L)
    t = [sheaves[k].tan_gamma(r[k]) * dr[k] for k in range(2)]
    return float(-t[1] / t[0])


def toroidal_stability_limit(L: float, gamma: float) -> float:
    """Smallest torus radius for which the symmetric equilibrium (phi = 0, equal sheaves) is stable, m.

    ``R > pi L / (2 sin(2 gamma) cos(gamma))`` (section 4.2 [S]).

    Examples
    --------
    >>> round(float(toroidal_stability_limit(0.19, np.radians(10.0))), 2)
    0.89
    """
    return np.pi * L / (2.0 * np.sin(2 * gamma) * np.cos(gamma))
