"""Craig–Bampton reduction of a solid sheave harmonic to the shaft node, the contact ring and a few modes.

The bore is bonded to the shaft, whose section stays rigid: the bore moves as a rigid body of the shaft
node's motion.  In the harmonic ``n`` only some rigid motions exist (:data:`INTERFACE`): axial
translation (``n = 0``, family ``cos``), rotation about the axis (``n = 0``, ``sin``), sideways
translation and tilt (``n = 1``); for ``n >= 2`` the bore is clamped and the sheave has only its own
modes.  The contact ring (a node of the contact face) keeps its three displacement amplitudes as
boundary coordinates, so ring loads are represented exactly.  Coordinates of the reduced model:
``[interface (rigid), ring (3), fixed-interface modes]``; units m and rad, modal coordinates of unit
modal mass.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from cvtfem.blas import arpack_start
from cvtfem.elements.sheave_solid import HarmonicSheave
from cvtfem.errors import InputError, NumericalError


def _rigid(n: int, family: str, z_c: float) -> tuple[tuple[str, callable], ...]:
    """Rigid motions of harmonic ``n``: ``(name, (r, z) -> (U_r, U_theta, U_z))`` per unit coordinate."""
    one, zero = (lambda r, z: np.ones_like(r)), (lambda r, z: np.zeros_like(r))
    table = {
        (0, "cos"): (("axial", lambda r, z: (zero(r, z), zero(r, z), one(r, z))),),
        (0, "sin"): (("spin", lambda r, z: (zero(r, z), r, zero(r, z))),),
        (1, "cos"): (("x", lambda r, z: (one(r, z), -one(r, z), zero(r, z))),
                     ("tilt_y", lambda r, z: (z - z_c, -(z - z_c), -r))),
        (1, "sin"): (("y", lambda r, z: (one(r, z), one(r, z), zero(r, z))),
                     ("tilt_x", lambda r, z: (-(z - z_c), -(z - z_c), r))),
    }
    return table.get((n, family), ())


@dataclass(frozen=True)
class ReducedSheave:
    """A sheave harmonic in Craig–Bampton coordinates.

    Attributes
    ----------
    labels : tuple of str
        Names of the reduced coordinates (rigid interface, ``ring_r``, ``ring_theta``, ``ring_z``, ``mode_k``).
    M, K : (m, m) arrays
        Reduced mass (kg, kg m, kg m^2) and stiffness matrices.
    basis : (ndof, m) array
        Full section DOFs of each reduced coordinate (recovers the displacement field).
    fixed_interface_hz : array
        Frequencies of the kept fixed-interface modes, Hz.
    """

    labels: tuple[str, ...]
    M: np.ndarray
    K: np.ndarray
    basis: np.ndarray
    fixed_interface_hz: np.ndarray

    def index(self, label: str) -> int:
        """Position of the reduced coordinate ``label``."""
        return self.labels.index(label)


def ring_dofs(model: HarmonicSheave, radius: float) -> np.ndarray:
    """The three DOFs (r, theta, z) of the contact-face vertex nearest ``radius`` (m)."""
    sec = model.section
    if not sec.hub_radius <= radius <= sec.outer_radius:
        raise InputError("ring_radius", radius,
                         f"must be a radius on the contact face, {sec.hub_radius:g}..{sec.outer_radius:g} m")
    locs = model.basis.doflocs
    on_face = np.isclose(locs[1], sec.face_height(locs[0]), rtol=0, atol=1e-9 * sec.outer_radius)
    target = np.flatnonzero(on_face)[np.argmin(abs(locs[0, on_face] - radius))]
    same = np.flatnonzero(np.all(np.isclose(locs, locs[:, [target]], rtol=0, atol=1e-12), axis=0))
    comp = np.empty(locs.shape[1], int)
    for c, idx in enumerate(model.basis.split_indices()):
        comp[idx] = c
    return same[np.argsort(comp[same])]


def craig_bampton(model: HarmonicSheave, n_modes: int | None, ring_radius: float | None = None,
                  tilt_centre: float = 0.0) -> ReducedSheave:
    """Reduce ``model`` to its rigid bore motions, the contact ring (if ``ring_radius``, m) and ``n_modes``
    fixed-interface modes (``None``: all of them, a change of coordinates of the unreduced model with a rigid
    bore); tilts turn about the axis point ``z = tilt_centre`` (m, the shaft node)."""
    K, M = model.matrices
    keep = model.free_dofs(clamped=False)
    locs = model.basis.doflocs
    comp = np.empty(K.shape[0], int)
    for c, idx in enumerate(model.basis.split_indices()):
        comp[idx] = c
    bore = np.intersect1d(model.bore_dofs(), keep)
    ring = np.intersect1d(ring_dofs(model, ring_radius), keep) if ring_radius is not None else np.array([], int)
    boundary = np.union1d(bore, ring)
    interior = np.setdiff1d(keep, boundary)
    rigid = _rigid(model.n, model.family, tilt_centre)
    labels = [name for name, _ in rigid] + [("ring_r", "ring_theta", "ring_z")[comp[d]] for d in ring]
    T = np.zeros((K.shape[0], len(labels)))
    for j, (_, shape) in enumerate(rigid):
        values = np.array(shape(locs[0, bore], locs[1, bore]))
        T[bore, j] = values[comp[bore], np.arange(len(bore))]
    for j, d in enumerate(ring):
        T[d, len(rigid) + j] = 1.0
    Kii, Mii = K[interior][:, interior].tocsc(), M[interior][:, interior].tocsc()
    lu = spla.splu(Kii)
    static = -lu.solve(np.asarray((K[interior][:, boundary] @ T[boundary]), float)) if labels else \
        np.zeros((len(interior), 0))
    if n_modes is None:                                   # every interior mode: the unreduced model, exactly
        lam, phi = sla.eigh(Kii.toarray(), Mii.toarray())
        n_modes = len(lam)
    elif n_modes > 0:
        if n_modes >= len(interior):
            raise InputError("n_modes", n_modes, f"must be fewer than the {len(interior)} interior DOFs")
        try:
            lam, phi = spla.eigsh(Kii, k=n_modes, M=Mii, sigma=0.0, which="LM", v0=arpack_start(Kii.shape[0]))
        except (spla.ArpackNoConvergence, RuntimeError) as exc:
            raise NumericalError(f"Craig-Bampton: fixed-interface modes did not converge ({exc})") from None
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
    else:
        lam, phi = np.zeros(0), np.zeros((len(interior), 0))
    basis = np.zeros((K.shape[0], len(labels) + n_modes))
    basis[boundary, :len(labels)] = T[boundary]
    basis[interior, :len(labels)] = static
    basis[interior, len(labels):] = phi
    Kr, Mr = basis.T @ (K @ basis), basis.T @ (M @ basis)
    return ReducedSheave(tuple(labels) + tuple(f"mode_{k}" for k in range(n_modes)), 0.5 * (Mr + Mr.T),
                         0.5 * (Kr + Kr.T), basis, np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi))


@dataclass(frozen=True)
class ReducedSpin:
    """A reduced harmonic ``n`` and its twin spinning: coordinates ``[cos basis Phi; twin basis P Phi]`` (``P`` turns
    ``U_theta`` over), each of :attr:`ReducedSheave.labels`.

    Attributes
    ----------
    M, K : (2m, 2m) arrays
        Mass and stiffness of the pair (kg, N/m; block diagonal, both blocks the reduced model's).
    G_rotating, K2_rotating : (2m, 2m) arrays
        Per unit spin (kg) the Coriolis coupling of the families and per unit ``Omega^2`` (kg) the prestress
        stiffness less the spin softening, ``K_sigma(1) - M_c``: in the frame turning with the disc,
        ``M x'' + Omega G_rotating x' + (K + Omega^2 K2_rotating) x = 0``.
    G_fixed, K2_fixed : (2m, 2m) arrays
        The same motion seen by a fixed observer (amplitudes turned by ``n Omega t``, ``J = [[0, -I], [I, 0]]``):
        ``G_rotating - 2 n M J`` and ``K2_rotating - n (n M + G_rotating J)``.
    """

    n: int
    M: np.ndarray
    K: np.ndarray
    G_rotating: np.ndarray
    K2_rotating: np.ndarray
    G_fixed: np.ndarray
    K2_fixed: np.ndarray

    def waves(self, omega: float, frame: str = "rotating") -> np.ndarray:
        """Frequencies (Hz, ascending, non-negative imaginary parts of the eigenvalues) of the reduced pair spinning
        at ``omega`` (rad/s) in the ``"rotating"`` or ``"fixed"`` frame; a backward wave past the critical speed
        comes out with its frequency's magnitude."""
        G, K2 = (self.G_rotating, self.K2_rotating) if frame == "rotating" else (self.G_fixed, self.K2_fixed)
        m = self.M.shape[0]
        A = np.block([[np.zeros((m, m)), np.eye(m)], [-(self.K + omega ** 2 * K2), -omega * G]])
        B = np.block([[np.eye(m), np.zeros((m, m))], [np.zeros((m, m)), self.M]])
        lam = sla.eigvals(A, B)
        return np.sort(np.abs(lam.imag[lam.imag >= -1e-9 * np.abs(lam).max()])) / (2 * np.pi)

    def critical_speeds(self) -> np.ndarray:
        """Spin speeds (rad/s, ascending) at which the fixed-frame stiffness ``K + Omega^2 K2_fixed`` is singular: a
        wave stands still for the fixed observer (the backward wave of ``n`` diameters meets zero)."""
        mu = sla.eigvals(self.K, -self.K2_fixed)
        real = mu.real[(np.abs(mu.imag) <= 1e-9 * np.abs(mu)) & (mu.real > 0) & np.isfinite(mu.real)]
        return np.sort(np.sqrt(real))


def spin_reduction(model: HarmonicSheave, reduced: ReducedSheave, prestress_unit) -> ReducedSpin:  # noqa: ANN001
    """Project the spinning disc's Coriolis, prestress and spin-softening matrices of harmonic ``model`` (family
    ``cos``, ``n >= 1``) on the Craig–Bampton basis of ``reduced`` and its twin.  ``prestress_unit`` is the
    axisymmetric stress at 1 rad/s (:meth:`HarmonicSheave.stress` of the ``n = 0`` model's
    :meth:`~HarmonicSheave.centrifugal_displacement` at 1 rad/s): the linear prestress scales with ``Omega^2``."""
    from dataclasses import replace

    if model.family != "cos" or model.n < 1:
        raise InputError("model", (model.n, model.family), "must be a 'cos' harmonic with n >= 1 (twins travel)")
    twin = replace(model, family="sin")
    flip = np.ones(model.basis.N)
    flip[model.basis.split_indices()[1]] = -1.0
    Phi = reduced.basis
    Psi = flip[:, None] * Phi                                       # P Phi: the twin's coordinates
    B = model.coriolis
    C = Phi.T @ (B @ Psi)
    m = Phi.shape[1]
    zero = np.zeros((m, m))
    M = np.block([[reduced.M, zero], [zero, reduced.M]])
    K = np.block([[reduced.K, zero], [zero, reduced.K]])
    K2 = [X.T @ ((h.geometric_stiffness(prestress_unit) - h.spin_softening) @ X)
          for h, X in ((model, Phi), (twin, Psi))]
    K2 = np.block([[0.5 * (K2[0] + K2[0].T), zero], [zero, 0.5 * (K2[1] + K2[1].T)]])
    G = np.block([[zero, C], [Psi.T @ (B @ Phi), zero]])
    J = np.block([[zero, -np.eye(m)], [np.eye(m), zero]])
    n = model.n
    return ReducedSpin(n, M, K, G, K2, G - 2 * n * M @ J, K2 - n * (n * M + G @ J))
