"""Pins of a closed chain placed on the band path of a ratio, every link at its unstretched length.

The band path (low-order digest §4.1, :func:`~cvtfem.elements.band.geometry.path_point`) is two arcs
and two straight spans.  Pins are marched along it so that consecutive pins are exactly one link
length apart (a chord on the arcs, not an arc length); the path length ``l_eff`` is solved so that the
chain closes, and the span angle so that ``r2 / r1`` is the ratio.  Frame of the chain models
(chain-models-1 §1.1): driven shaft at the origin, driving shaft at ``(L, 0)``; the chain runs
counter-clockwise.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from cvtfem.elements.band.geometry import path_point, phi_for_ratio, radii
from cvtfem.errors import InputError, NumericalError


@dataclass(frozen=True)
class Placement:
    """Pins on the path (arrays over pins).

    Attributes
    ----------
    u : (n, 2) m
        Pin positions.
    tangent : (n, 2)
        Unit path direction at each pin (direction of travel).
    piece : (n,) int
        0 on the driving arc, 1 on the driven arc, -1 on a span.
    r : (2,) m
        Arc radii ``(r1, r2)``; ``phi`` (rad) span angle; ``length`` (m) path length ``l_eff``.
    """

    u: np.ndarray
    tangent: np.ndarray
    piece: np.ndarray
    r: np.ndarray
    phi: float
    length: float


def _march(L, length: float, phi: float, L_c: float) -> np.ndarray:
    """Path coordinates of pins ``0..n`` (pin ``n`` is pin 0 again if the chain closes), m."""
    s = np.empty(len(L) + 1)
    s[0] = 0.0
    for p, Lp in enumerate(L):
        x0 = path_point(np.array([s[p]]), phi, length, L_c)[:, 0]
        gap = lambda t: float(np.hypot(*(path_point(np.array([t]), phi, length, L_c)[:, 0] - x0))) - Lp  # noqa: E731
        s[p + 1] = brentq(gap, s[p] + 0.99 * Lp, s[p] + 1.2 * Lp, xtol=1e-15)
    return s


def place_on_path(L, ratio: float, L_c: float) -> Placement:
    """Pins with link lengths ``L`` (n,) m on the path of ``ratio = r2 / r1`` for the centre distance ``L_c`` (m).
    Cached (about 0.3 s of scalar root finding; a model's construction and its start ask for the same one)."""
    return copy.deepcopy(_place(tuple(np.asarray(L, float).tolist()), float(ratio), float(L_c)))


@lru_cache(maxsize=16)
def _place(L: tuple, ratio: float, L_c: float) -> Placement:
    """:func:`place_on_path` for hashable arguments."""
    L = np.asarray(L, float)
    total = L.sum()
    phi_of = lambda length: phi_for_ratio(ratio, length, L_c)  # noqa: E731

    def closure(length):
        return _march(L, length, phi_of(length), L_c)[-1] - length
    try:
        length = brentq(closure, total, 1.02 * total, xtol=1e-13)
    except ValueError:
        raise NumericalError(f"the chain does not close on the path of ratio {ratio} (centre distance {L_c} m, "
                             f"chain length {total:.4f} m)", component="chain placement") from None
    phi = phi_of(length)
    s = _march(L, length, phi, L_c)[:-1]
    u = path_point(s, phi, length, L_c).T
    h = 1e-7
    t = (path_point(s + h, phi, length, L_c) - path_point(s - h, phi, length, L_c)).T
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    r = radii(phi, length, L_c)[0]
    piece = np.full(len(L), -1)
    piece[np.abs(np.hypot(u[:, 0], u[:, 1]) - r[0]) < 1e-9] = 0
    piece[np.abs(np.hypot(u[:, 0] + L_c, u[:, 1]) - r[1]) < 1e-9] = 1
    if not (piece == 0).any() or not (piece == 1).any():
        raise InputError("ratio", ratio, "must put pins on both arcs")
    return Placement(u + np.array([L_c, 0.0]), t, piece, np.asarray(r, float), float(phi), float(length))
