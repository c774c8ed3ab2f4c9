"""The contact face of a flexible sheave in the rotor model, as its modal coordinates move it (issue 20).

For the radiated power of the forced response (:mod:`cvtfem.modal.radiation`): the axial displacement of the face
at a panel point ``(r, a)`` is the rigid disc's (``u3`` and tilts, :func:`~cvtfem.modal.radiation.rigid_annulus`)
plus, per fixed-interface modal coordinate of harmonic ``n``, ``facing * U_z(r) * cos n a`` (``cos`` family) or
``sin n a`` (the twins, bore-clamped waves' and ``n = 1``'s), ``U_z(r)`` the mode's axial displacement along the
contact face of the section (its quadratic elements' face nodes, linear between them).  The torsion family
(``n = 0``, ``sin``) has no axial displacement.  Both faces of a sheave are taken to move alike (bending of a disc
whose thickness is small against its radius).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class FaceModes:
    """Axial face displacement per modal coordinate of one sheave.

    Attributes
    ----------
    disk : int
        The ``[[disk]]`` index.
    dofs : int array (k,)
        Model DOFs of the modal coordinates.
    n : int array (k,)
        Nodal diameters of each.
    sine : bool array (k,)
        ``sin n a`` (twins) rather than ``cos n a``.
    radii : array (R,), m
        Radii of the contact face's nodes, ascending.
    uz : array (R, k), m per unit coordinate
        Axial displacement there, in the rotor's axial sense (``facing`` applied).
    """

    disk: int
    dofs: np.ndarray
    n: np.ndarray
    sine: np.ndarray
    radii: np.ndarray
    uz: np.ndarray

    def rows(self, n_dof: int, r: np.ndarray, a: np.ndarray) -> sp.csr_matrix:
        """``(p, n_dof)`` map from the model's DOFs to the axial displacement at the points ``(r, a)`` (m, rad)."""
        prof = np.column_stack([np.interp(r, self.radii, self.uz[:, j]) for j in range(len(self.dofs))])
        ang = np.where(self.sine[None, :], np.sin(np.outer(a, self.n)), np.cos(np.outer(a, self.n)))
        vals = prof * ang
        rows = np.repeat(np.arange(len(r)), len(self.dofs))
        cols = np.tile(self.dofs, len(r))
        return sp.csr_matrix((vals.ravel(), (rows, cols)), shape=(len(r), n_dof))


def face_nodes(model) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001 - HarmonicSheave
    """Radii (m, ascending) and section DOF indices of ``U_z`` at the nodes of the contact face of ``model``'s mesh
    (the same for every harmonic of one section and mesh)."""
    sec = model.section
    locs = model.basis.doflocs
    z_dofs = model.basis.split_indices()[2]
    r, z = locs[0, z_dofs], locs[1, z_dofs]
    on = np.isclose(z, sec.face_height(r), rtol=0, atol=1e-9 * sec.outer_radius)
    order = np.argsort(r[on])
    return r[on][order], z_dofs[on][order]


def face_modes(disk: int, nodes: tuple[np.ndarray, np.ndarray], blocks: list, facing: float) -> FaceModes:
    """:class:`FaceModes` of sheave ``disk`` from ``blocks`` of ``(model DOFs, section basis columns, n, sine)``
    and the contact face's ``nodes`` (:func:`face_nodes`); ``facing`` -1 for a ``-z``-facing sheave."""
    radii, z_dofs = nodes
    dofs = np.concatenate([np.asarray(b[0], int) for b in blocks])
    uz = facing * np.hstack([b[1][z_dofs] for b in blocks])
    n = np.concatenate([np.full(len(b[0]), b[2]) for b in blocks])
    sine = np.concatenate([np.full(len(b[0]), b[3]) for b in blocks])
    return FaceModes(disk, dofs, n, sine, radii, uz)
