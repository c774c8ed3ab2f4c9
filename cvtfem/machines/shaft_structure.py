"""The structure block under the discrete chain: two elastic shafts with rigid sheaves on linear bearings
(shafts-sheaves-supports models 2-5, implementation notes §12).

Per shaft ``k`` (0 driving, 1 driven): a beam FE shaft (:class:`~cvtfem.elements.beam.BeamFamily`, Timoshenko,
6 DOF per node ``(u1, u2, u3, theta1, theta2, phi)``) of length ``L`` between two bearings at its end nodes,
its axis parallel to ``e3`` through the shaft centre ``c_k`` of the chain models and its mid-point in the chain
mid-plane ``x3 = 0``.  Two rigid sheaves (model 3: ``M = diag(m, m, m, B, B, A)``, gyroscopic ``A Omega`` on
the tilts) sit at ``x3 = +-h``: the fixed one rigidly on the node there (rigid connection of model 5, index
merge in the node-based tilt layout, §12.1), the movable one rigidly on its node in translation across the
axis, tilt and spin, and free along the axis with its own coordinate ``zeta`` (absolute axial displacement, m)
under the clamping force, which acts between it and its node (the cylinder is part of the shaft).  The movable
sheave of the driving shaft is on the ``x3 > 0`` side, the driven one's on ``x3 < 0``
(:mod:`~cvtfem.machines.chain_a_cvt`'s convention).  Bearings (model 4, linear): radial stiffness and damping
at both end nodes, axial at node 0 (the locating bearing), no tilt or torsion stiffness.

Structure coordinates: shaft 0's nodes, ``zeta_0``, shaft 1's nodes, ``zeta_1``.  Equation of the block:
``M q'' + (C + Omega_0 G_0 + Omega_1 G_1) q' + K q = f`` with ``Omega_k`` the spin rate of shaft ``k``.
The sheaves' polar inertia ``A = (J - J_shaft) / 2`` keeps the scene's spin inertia ``J`` of shaft plus sheaves
(the rigid model's), and ``B = Theta / 2``, ``m`` half the pair's mass.  Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly import assemble
from cvtfem.elements.beam import BeamFamily, BeamOptions
from cvtfem.elements.bearing import BearingFamily
from cvtfem.errors import InputError

#: Density of the steel shafts (kg/m^3): assumed, the spec gives no values (§9.1).
STEEL_DENSITY = 7850.0
#: Poisson's ratio of the steel shafts: assumed.
STEEL_POISSON = 0.3


@dataclass(frozen=True)
class ShaftParameters:
    """One shaft with its sheave pair and bearings (SI units).

    Attributes
    ----------
    length, diameter : m
        Shaft between the bearings, solid section.
    elements : int
        Beam elements (at least 3: nodes at both sheaves).
    sheave_offset : m
        Axial distance ``h`` of each sheave's centre of mass from the chain mid-plane.
    inertia : kg m^2
        Spin inertia ``J`` of shaft plus sheaves.
    sheave_mass, sheave_transverse_inertia : kg, kg m^2
        Of the pair (each sheave has half).
    bearing_stiffness, bearing_damping : N/m, N s/m
        Of each of the two bearings (radial; axial for the locating one at node 0).
    movable_side : +1 or -1
        Side (sign of ``x3``) of the movable sheave.
    """

    length: float
    diameter: float
    elements: int
    sheave_offset: float
    inertia: float
    sheave_mass: float
    sheave_transverse_inertia: float
    bearing_stiffness: float
    bearing_damping: float
    movable_side: int


def shaft_mesh(p: ShaftParameters) -> np.ndarray:
    """Node positions (n_elem + 1,) m along the shaft from its left bearing (``x3 = x - L/2``), with nodes at
    ``L/2 -+ h``: the elements split over the three segments in proportion to their lengths."""
    L, h, ne = p.length, p.sheave_offset, int(p.elements)
    if ne < 3:
        raise InputError("shaft_elements", ne, "must be at least 3 for an elastic shaft (nodes at both sheaves)")
    if not 0 < h < L / 2:
        raise InputError("sheave_offset", h, f"must lie strictly between 0 and half the shaft length {L / 2:g} m")
    n_mid = min(max(1, round(ne * 2 * h / L)), ne - 2)
    n_left = (ne - n_mid) // 2
    n_right = ne - n_mid - n_left
    return np.concatenate([np.linspace(0, L / 2 - h, n_left + 1), np.linspace(L / 2 - h, L / 2 + h, n_mid + 1)[1:],
                           np.linspace(L / 2 + h, L, n_right + 1)[1:]])


@dataclass(frozen=True)
class ShaftStructure:
    """Matrices and DOF maps of the two shafts with their sheaves and bearings.

    Attributes
    ----------
    M, K, C : csr (n, n)
        Mass, stiffness (shaft + bearings), damping (bearings).
    G : tuple of two csr (n, n)
        Gyroscopic matrix per unit spin rate of each shaft (sheaves; shaft elements when switched on).
    x : tuple of two arrays
        Node positions along each shaft (m, from its left bearing).
    offset : (2,) int
        First structure index of each shaft.
    sheave_dofs : (2, 2, 6) int
        Structure indices of ``(u1, u2, u3, theta1, theta2, phi)`` of each shaft's (fixed, movable) sheave;
        the movable sheave's ``u3`` is its ``zeta``.
    sheave_x3 : (2, 2) m
        Mid-plane coordinate of each sheave's pivot (its node), (fixed, movable).
    node_of_sheave : (2, 2) int
        Structure index of the first DOF of each sheave's node.
    spin_dof : (2,) int
        The fixed sheave's ``phi`` (the shaft's speed and torques act there).
    bearing_dofs : (2, 2, 3) int
        ``(u1, u2, u3)`` of each shaft's two bearing nodes.
    bearing_K, bearing_C : (2, 2, 3) N/m, N s/m
        Diagonal bearing stiffness and damping on those DOFs.
    params : tuple of ShaftParameters
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    C: sp.csr_matrix
    G: tuple
    x: tuple
    offset: np.ndarray
    sheave_dofs: np.ndarray
    sheave_x3: np.ndarray
    node_of_sheave: np.ndarray
    spin_dof: np.ndarray
    bearing_dofs: np.ndarray
    bearing_K: np.ndarray
    bearing_C: np.ndarray
    params: tuple

    @property
    def n(self) -> int:
        """Structure coordinates."""
        return self.M.shape[0]

    @property
    def dof_kind(self) -> np.ndarray:
        """Kind 0..5 (``u1 u2 u3 theta1 theta2 phi``) of every structure coordinate (``zeta``: 2, axial)."""
        kinds = [np.concatenate([np.tile(np.arange(6), len(x)), [2]]) for x in self.x]
        return np.concatenate(kinds)

    def damping_matrix(self, rates) -> sp.csr_matrix:
        """``C + sum_k Omega_k G_k`` at the spin rates ``rates`` (2,) rad/s."""
        return self.C + rates[0] * self.G[0] + rates[1] * self.G[1]

    def bearing_forces(self, q, v) -> np.ndarray:
        """Forces (2, 2, 3) N the bearings carry, ``K_b u + C_b v`` per shaft and bearing (x1, x2, x3)."""
        return self.bearing_K * q[self.bearing_dofs] + self.bearing_C * v[self.bearing_dofs]


def build_structure(shafts, young_modulus: float, gyroscopic: bool = True, damping: bool = True,
                    shaft_gyroscopic: bool = False) -> ShaftStructure:
    """The structure block of two :class:`ShaftParameters` (driving, driven).

    ``gyroscopic`` switches the sheaves' gyroscopic terms, ``shaft_gyroscopic`` the shaft elements' (the source
    neglects them, spec §2.3); ``damping`` the bearing damping.  Steel shafts (:data:`STEEL_DENSITY`,
    :data:`STEEL_POISSON`) with Young's modulus ``young_modulus`` (Pa).
    """
    E = float(young_modulus)
    Gmod = E / (2 * (1 + STEEL_POISSON))
    blocks_M, blocks_K, blocks_C, blocks_G = [], [], [], []
    xs, offsets, sheave_dofs, sheave_x3, node_of, spin, b_dofs, b_K, b_C = [], [], [], [], [], [], [], [], []
    start = 0
    n_total = sum(6 * (int(p.elements) + 1) + 1 for p in shafts)
    for k, p in enumerate(shafts):
        if p.movable_side not in (1, -1):
            raise InputError("movable_side", p.movable_side, "must be +1 or -1")
        x = shaft_mesh(p)
        ne = len(x) - 1
        beam = BeamFamily(nodes=np.stack([np.arange(ne), np.arange(1, ne + 1)], axis=1),
                          L=np.diff(x), Do=np.full(ne, p.diameter), Di=np.zeros(ne), E=np.full(ne, E),
                          G=np.full(ne, Gmod), rho=np.full(ne, STEEL_DENSITY),
                          options=BeamOptions(gyroscopic=shaft_gyroscopic))
        dofs = beam.dofs + start
        j_shaft = float(np.sum(STEEL_DENSITY * 2 * beam.inertia * beam.L))
        A = (p.inertia - j_shaft) / 2
        if not A > 0:
            raise InputError("inertia", p.inertia, f"must exceed the shaft's own spin inertia {j_shaft:.4g} kg m^2")
        m, B = p.sheave_mass / 2, p.sheave_transverse_inertia / 2
        i_plus = int(np.argmin(abs(x - (p.length / 2 + p.sheave_offset))))
        i_minus = int(np.argmin(abs(x - (p.length / 2 - p.sheave_offset))))
        i_fixed, i_mov = (i_minus, i_plus) if p.movable_side > 0 else (i_plus, i_minus)
        zeta = start + 6 * (ne + 1)
        nf, nm = start + 6 * i_fixed, start + 6 * i_mov
        disk_fixed = np.diag([m, m, m, B, B, A])
        disk_mov = np.diag([m, m, 0.0, B, B, A])
        gyro = np.zeros((6, 6))
        gyro[3, 4], gyro[4, 3] = A, -A
        bearings = BearingFamily.from_dicts(np.array([0, ne]), [
            {"kxx": p.bearing_stiffness, "kyy": p.bearing_stiffness, "kzz": p.bearing_stiffness,
             "cxx": p.bearing_damping, "cyy": p.bearing_damping, "czz": p.bearing_damping},
            {"kxx": p.bearing_stiffness, "kyy": p.bearing_stiffness,
             "cxx": p.bearing_damping, "cyy": p.bearing_damping}])
        bdofs = bearings.dofs + start
        six = np.arange(6)
        blocks_M += [(beam.mass(), dofs), (disk_fixed[None], (nf + six)[None]), (disk_mov[None], (nm + six)[None]),
                     (np.full((1, 1, 1), m), np.array([[zeta]]))]
        blocks_K += [(beam.stiffness(), dofs), (bearings.stiffness(), bdofs)]
        if damping:
            blocks_C += [(bearings.damping(), bdofs)]
        g = [(gyro[None], (nf + six)[None]), (gyro[None], (nm + six)[None])] if gyroscopic else []
        if shaft_gyroscopic:
            g.append((beam.gyroscopic(), dofs))
        blocks_G.append(assemble(n_total, g) if g else sp.csr_matrix((n_total, n_total)))
        xs.append(x)
        offsets.append(start)
        sheave_dofs.append([nf + six, np.array([nm, nm + 1, zeta, nm + 3, nm + 4, nm + 5])])
        sheave_x3.append([x[i_fixed] - p.length / 2, x[i_mov] - p.length / 2])
        node_of.append([nf, nm])
        spin.append(nf + 5)
        b_dofs.append(bdofs[:, :3])
        kb, cb = (p.bearing_stiffness, p.bearing_damping if damping else 0.0)
        b_K.append([[kb, kb, kb], [kb, kb, 0.0]])
        b_C.append([[cb, cb, cb], [cb, cb, 0.0]])
        start = zeta + 1
    M = assemble(n_total, blocks_M)
    K = assemble(n_total, blocks_K)
    C = assemble(n_total, blocks_C) if blocks_C else sp.csr_matrix((n_total, n_total))
    return ShaftStructure(M, K, C, tuple(blocks_G), tuple(xs), np.array(offsets), np.array(sheave_dofs),
                          np.array(sheave_x3), np.array(node_of), np.array(spin), np.array(b_dofs),
                          np.array(b_K, float), np.array(b_C, float), tuple(shafts))


def force_operator(s: ShaftStructure) -> sp.csr_matrix:
    """``[K, C, G_0, G_1]`` (n, 4 n): ``K q + (C + Omega_0 G_0 + Omega_1 G_1) v`` of the structure ``s`` in one product
    with ``[q, v, Omega_0 v, Omega_1 v]`` (N, N m)."""
    return sp.hstack([s.K, s.C, s.G[0], s.G[1]], format="csr")


def acceleration_parts(s: ShaftStructure, M_inv, row: int, cols: tuple, shape: tuple) -> tuple:
    """``(indices, indptr, data)``: ``M^-1 [-K, -C, -G_0, -G_1]`` of the structure ``s`` (``M_inv`` its dense inverse
    mass) placed at rows ``row + i`` and columns ``cols[0] + j`` (``K``: positions) or ``cols[1] + j`` (rates) of a
    ``shape`` matrix, as four data arrays (4, nnz) on one sorted CSR pattern: the structure's acceleration rows of a
    Jacobian at spin rates ``Omega`` are ``data[0] + data[1] + Omega_0 data[2] + Omega_1 data[3]`` there."""
    n_rows, n_cols = shape
    blocks = [(sp.csr_matrix(M_inv) @ A).tocoo() for A in (s.K, s.C, s.G[0], s.G[1])]
    keys = [(row + B.row).astype(np.int64) * n_cols + cols[min(i, 1)] + B.col for i, B in enumerate(blocks)]
    uniq, where = np.unique(np.concatenate(keys), return_inverse=True)
    data = np.zeros((4, len(uniq)))
    start = np.cumsum([0] + [len(k) for k in keys])
    for i, B in enumerate(blocks):
        np.add.at(data[i], where[start[i]:start[i + 1]], -B.data)
    indptr = np.searchsorted(uniq // n_cols, np.arange(n_rows + 1))
    return (uniq % n_cols).astype(np.int32), indptr.astype(np.int32), data
