"""The flexible sheave faces of the 6+2n band models condensed onto the band's arc functions, tabulated in phi.

On flexible faces (issue 20) the strain is ``eps = A^-1 eps_r`` with ``A = I + c' K_f D`` per arc
(:mod:`cvtfem.elements.band.compressible`).  The rigid-face strain lies in the span of the rows of ``E``
(``E[0] = 1``): ``eps_r = E^T x~`` with ``x~ = x - z0 e_0``.  So everything the faces change is two matrices that
depend on the span angle phi only (geometry), not on the state:

* ``dG = A^-1 E^T - E^T`` (g, nx): ``eps = eps_r + dG x~`` at the Gauss nodes (normal force, band damping);
* ``dK = E D dG`` (nx, nx), symmetrised: the sheaves' share of the strain energy
  ``V = c' int eps_r^2 ds + c' x~^T dK x~``, whose gradient gives the generalized forces.  Symmetric by
  construction, so the forces stay exactly the gradient of the energy the table defines.

Both are tabulated with their phi-derivatives (complex step through the exact ``A``) on a uniform grid over the
span angles whose contact radii both lie in the faces' fitted range, and read by cubic Hermite interpolation: a
right-hand side costs a few thousand multiply-adds instead of the face kernel's ``(H + 1) g^2`` complex products
and a complex LU per arc.  Outside the grid the model falls back on the exact ``A``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from cvtfem.elements.band.geometry import admissible_phi, radii
from cvtfem.errors import InputError

#: Grid intervals over the span-angle range.  Hermite error falls as h^4 (values) and h^3 (derivatives): at 256 on
#: the reference CVT (phi in +-0.30 rad) dG is within 4e-10 of its size, d dG / d phi within 3e-7 (accelerations
#: within 1e-9 relative of the exact faces, tests/band/test_face_table.py).
INTERVALS = 256


@dataclass(frozen=True)
class FaceTable:
    """``dG``, ``dK`` and their phi-derivatives on ``phi = lo + i h``, ``i = 0..N``.

    Attributes
    ----------
    lo, h : float, rad
        First grid angle and spacing.
    values : (N + 1, 2, 2, g + nx, nx) array
        Per grid angle and arc ``k``: ``[value, d/dphi]`` of ``dG`` (rows ``0..g-1``, dimensionless) stacked on
        ``dK`` (rows ``g..``, m).
    """

    lo: float
    h: float
    values: np.ndarray

    @property
    def hi(self) -> float:
        return self.lo + self.h * (self.values.shape[0] - 1)

    def covers(self, phi: float) -> bool:
        """Whether ``phi`` (rad) lies on the grid."""
        return self.lo <= phi <= self.hi

    def at(self, phi: float) -> tuple[np.ndarray, np.ndarray]:
        """Hermite interpolation at ``phi`` (rad, on the grid): ``(value, d/dphi)``, each ``(2, g + nx, nx)``."""
        N = self.values.shape[0] - 1
        u = (phi - self.lo) / self.h
        i = min(max(int(u), 0), N - 1)
        t = u - i
        w = hermite_weights(t, self.h)
        a, b = self.values[i], self.values[i + 1]
        return (w[0] * a[:, 0] + w[1] * a[:, 1] + w[2] * b[:, 0] + w[3] * b[:, 1],
                w[4] * a[:, 0] + w[5] * a[:, 1] + w[6] * b[:, 0] + w[7] * b[:, 1])


def hermite_weights(t: float, h: float) -> tuple[float, ...]:
    """Cubic Hermite weights at ``t`` in [0, 1] of an interval of width ``h``: value from ``(f_i, f'_i, f_i+1,
    f'_i+1)`` (first four), derivative (last four)."""
    t2, t3 = t * t, t * t * t
    return (2 * t3 - 3 * t2 + 1, (t3 - 2 * t2 + t) * h, 3 * t2 - 2 * t3, (t3 - t2) * h,
            (6 * t2 - 6 * t) / h, 3 * t2 - 4 * t + 1, (6 * t - 6 * t2) / h, 3 * t2 - 2 * t)


def phi_range(length: float, L: float, faces: tuple) -> tuple[float, float]:
    """Span angles (rad) with the driving radius in ``faces[0]``'s fitted range and the driven in ``faces[1]``'s:
    ``r1`` grows and ``r2`` falls with phi."""
    lo, hi = admissible_phi(length, L)

    def crossing(k: int, value: float, default: float) -> float:
        f = lambda p: float(radii(p, length, L)[0][k]) - value  # noqa: E731
        return brentq(f, lo, hi, xtol=1e-14) if f(lo) * f(hi) < 0 else default

    a = max(crossing(0, faces[0].r_lo, lo), crossing(1, faces[1].r_hi, lo))
    b = min(crossing(0, faces[0].r_hi, hi), crossing(1, faces[1].r_lo, hi))
    if not a < b:
        raise InputError("sheave contact radii", (faces[0].r_lo, faces[0].r_hi),
                         f"must leave span angles with both radii on the faces (found {a:g} >= {b:g} rad)")
    return a, b


def face_table(model, intervals: int = INTERVALS) -> FaceTable:  # noqa: ANN001 - CompressibleBand with faces
    """Tabulate ``dG``, ``dK`` of ``model`` (a :class:`~cvtfem.elements.band.compressible.CompressibleBand` with
    faces) from its exact face systems, over :func:`phi_range` in ``intervals`` steps."""
    if not 4 <= intervals <= 100_000:
        raise InputError("face_intervals", intervals, "must be 4..100000 grid intervals (or 0: no table)")
    p = model.p
    lo, hi = phi_range(p.length, p.L, model.faces)
    grid = np.linspace(lo, hi, intervals + 1)
    out = np.stack([np.stack(model.exact_face_terms(phi), axis=1) for phi in grid])
    return FaceTable(float(lo), float(grid[1] - grid[0]), out)
