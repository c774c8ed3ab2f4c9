"""Axial compliance of a sheave's contact face under loads along a contact arc (issue 20).

A force ``f`` pushing the face back at radius ``r`` and angle ``theta_j`` opens it at ``(r, theta)`` by
``w = K_r(theta - theta_j) f``: the static Green's function of the solid sheave with its bore clamped, summed over
nodal-diameter harmonics, ``K_r(d) = sum_n c_n(r) cos(n d)``.  Each harmonic's compliance is
``c_n = L^T K_n^-1 L`` of the axisymmetric-harmonic model (:class:`~cvtfem.elements.sheave_solid.HarmonicSheave`,
family ``cos``): ``L`` spreads a unit axial force over a patch of the face ``PATCH_WIDTH`` wide (a cosine bump in
the radius, a point in ``theta``), and the same weights read the face's displacement.  Its virtual work on
``U_z cos n theta`` at ``theta = 0`` is ``L^T U`` whatever ``n``, and the model's matrices hold the whole disc
(``pi``, ``2 pi`` per squared cosine), so each harmonic answers the point force with ``K_n^-1 L``.  The ``c_n`` are
fitted in the radius by Chebyshev polynomials, which also take a complex radius (complex-step derivatives).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection
from cvtfem.errors import InputError

#: Radial width of the face patch a contact force is spread over, m (the height of a pin end's contact).
PATCH_WIDTH = 4e-3
#: Radii sampled between the ends of the fitted range and degree of the Chebyshev fit of each ``c_n(r)``.
SAMPLES, DEGREE = 17, 6


@dataclass(frozen=True)
class FaceCompliance:
    """Axial face compliance of one sheave, bore clamped, as a harmonic series fitted over a range of radii.

    Attributes
    ----------
    r_lo, r_hi : float, m
        Range of contact radii the fit covers.
    coef : (H + 1, DEGREE + 1) array
        Chebyshev coefficients (on ``[r_lo, r_hi]`` mapped to ``[-1, 1]``) of ``c_n(r)``, m/N, n = 0..H.
    """

    r_lo: float
    r_hi: float
    coef: np.ndarray

    def harmonics(self, r):  # noqa: ANN001, ANN201 - float or complex
        """``c_n(r)`` for n = 0..H (m/N); ``r`` may be complex."""
        x = (2 * r - (self.r_lo + self.r_hi)) / (self.r_hi - self.r_lo)
        return np.polynomial.chebyshev.chebval(x, self.coef.T)

    def kernel(self, r, dtheta):  # noqa: ANN001, ANN201
        """``K_r(dtheta)``, m/N: axial opening at angular distance ``dtheta`` (rad, any shape) from a unit force."""
        c = self.harmonics(r)
        n = np.arange(len(c)).reshape((-1,) + (1,) * np.ndim(dtheta))
        return np.sum(c.reshape(n.shape) * np.cos(n * dtheta), axis=0)

    def matrix(self, r, theta):  # noqa: ANN001, ANN201
        """Influence matrix ``K_r(theta_i - theta_j)`` (m/N) of points at angles ``theta`` (rad, (g,)) on radius r,
        as ``C^T diag(c) C + S^T diag(c) S`` with ``C = cos n theta``, ``S = sin n theta`` (2 (H + 1) g sines and
        cosines instead of (H + 1) g^2)."""
        c = self.harmonics(r)
        nt = np.arange(len(c))[:, None] * theta[None, :]
        C, S = np.cos(nt), np.sin(nt)
        K = C.T @ (c[:, None] * C) + S.T @ (c[:, None] * S)
        return 0.5 * (K + K.T)                                         # symmetric to the last bit (Maxwell)


def _patch_load(model: HarmonicSheave, radius: float, width: float) -> np.ndarray:
    """``L``: a unit axial force spread over the face patch around ``radius`` (cosine bump of ``width``, m)."""
    from skfem import FacetBasis, Functional, LinearForm, asm

    sec = model.section
    mesh = model.basis.mesh
    tol = 1e-3 * sec.rim_thickness
    facets = mesh.facets_satisfying(lambda x: np.abs(x[1] - sec.face_height(x[0])) < tol)
    fb = FacetBasis(mesh, model.basis.elem, facets=facets)

    def bump(r):  # noqa: ANN001, ANN202
        s = (r - radius) / width
        return np.where(np.abs(s) < 0.5, np.cos(np.pi * s) ** 2, 0.0)

    area = asm(Functional(lambda w: bump(w.x[0])), fb)
    return asm(LinearForm(lambda v, w: bump(w.x[0]) * v[2]), fb) / area


def face_compliance(section: SheaveSection, r_lo: float, r_hi: float, harmonics: int = 24,
                    mesh: tuple[int, int] = (24, 2), width: float = PATCH_WIDTH) -> FaceCompliance:
    """The face compliance of ``section`` for contact radii ``r_lo..r_hi`` (m) and harmonics ``0..harmonics``:
    one sparse LU per harmonic (bore clamped), :data:`SAMPLES` patch loads per LU."""
    lo, hi = section.hub_radius + width / 2, section.outer_radius - width / 2
    if not lo <= r_lo < r_hi <= hi:
        raise InputError("sheave contact radii", (r_lo, r_hi),
                         f"must lie on the face clear of hub and rim, {lo:g} <= r_min < r_max <= {hi:g} m")
    if not 0 <= harmonics <= 200:
        raise InputError("sheave.harmonics", harmonics, "must be 0..200 nodal-diameter harmonics")
    x = np.cos(np.pi * (np.arange(SAMPLES) + 0.5) / SAMPLES)[::-1]       # Chebyshev points: a well-posed fit
    radii = 0.5 * (r_lo + r_hi) + 0.5 * (r_hi - r_lo) * x
    coef = np.empty((harmonics + 1, DEGREE + 1))
    loads = None
    for n in range(harmonics + 1):
        model = HarmonicSheave(section, n, "cos", *mesh)
        if loads is None:
            loads = np.column_stack([_patch_load(model, r, width) for r in radii])
        K, _ = model.matrices
        free = model.free_dofs()
        lu = spla.splu(K[free][:, free].tocsc())
        c = np.einsum("ij,ij->j", loads[free], lu.solve(loads[free]))
        coef[n] = np.polynomial.chebyshev.chebfit(x, c, DEGREE)
    return FaceCompliance(r_lo, r_hi, coef)
