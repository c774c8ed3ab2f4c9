"""Chains on elastic shafts: the symmetric chain (S2, S3) as :class:`ElasticChainCVT`, the transmission of
:class:`~cvtfem.machines.chain_cvt.ChainCVT` with the rigid shafts of model 1 replaced by the structure block
of :mod:`~cvtfem.machines.shaft_structure` (beam FE shafts, rigid sheaves, linear bearings; Table 1.1 (b)'s
structure); the whole-pin chains as :class:`ElasticChainACVT` (A1 with H1, or with the refined contact H2:
variant (b)) and :class:`ElasticChainA2CVT` (A2's coupled halves with H2: variant (v)).

State ``x = [q_chain, q_structure, velocities, control states, W]``.  Each pin end touches each of the two
sheaves of a shaft: the end at ``x = (u1, u2, s u3)`` on the sheave on side ``s`` (the mirror end of the
symmetric chain is implied).  A contact is evaluated in the frame of its sheave: with the sheave's pivot ``o``
(its node on the undeformed axis), translation ``a`` and small tilt ``theta`` (no spin part), the pin end's
reference position is ``X = o + (I - theta x)(x - o - a)`` (first order in the tilt) and its velocity the time
derivative of that map.  The axial part of ``a`` is measured from the pair's mid-plane (half the difference of
the two sheaves' axial displacements): the symmetric chain has no axial rigid motion, so its mid-plane follows
each pulley's, as a real chain centres itself between the sheaves (the bearings then carry no axial force from
the chain).  Mirrored to the ``x3 > 0`` side (``x3 -> s x3``) the position is the input of the rigid model's
H1 kernel (:class:`~cvtfem.elements.chain.sheave_contact.SheaveContact`) with the sheave face at the constant
reference position ``z_ref`` of the quasi-static start.  The kernel's force (per end: half its mirrored
pair's) acts on every coordinate through the same map (virtual work: ``Q = (dX/dq)^T F``), so the pin end gets
the contact force, the sheave's node its reaction and the moment of it about the pivot, the spin ``phi`` the
friction moment.  The normal force stays the gradient of the Hertz potential of ``X(q)``, and the friction
power is that of the kernel: the energy balance of ChainCVT holds with the structure's kinetic and elastic
energy added and its bearing damping dissipating.  The clamping force ``F_k`` acts between the movable
sheave (``zeta_k``) and its node; the torques act on the fixed sheave's node, whose spin rate the loops read.

Jacobian: the chain family's blocks, the structure's ``-K``, ``-(C + Omega G)`` and ``-G v`` on the spin
rates, per-contact central differences of the mapped kernel (H1: 19 inputs, 11 outputs; H2: 31, 17; all contacts
at once) scattered on both sides, and the loops' forward differences, as in ChainCVT.  The mapped contacts run
compiled where :mod:`~cvtfem.machines.elastic_contact_compiled` offers it (H1, H2 at whole-pin and half ends); the
numpy path here is its tested twin.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.optimize import least_squares

from cvtfem.assembly.model import StateLayout
from cvtfem.blas import single_thread_blas
from cvtfem.elements.base import Block
from cvtfem.elements.chain import mapped_contact_kernel as MCK
from cvtfem.elements.chain.sheave_contact import central_local_jacobian
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.jit import HAVE_NUMBA
from cvtfem.errors import NumericalError
from cvtfem.machines.chain_a2_cvt import ChainA2CVT
from cvtfem.machines.chain_a_cvt import ChainACVT
from cvtfem.machines.chain_cvt import ChainCVT
from cvtfem.machines.elastic_contact_compiled import CompiledMappedContacts, difference_steps
from cvtfem.machines.shaft_structure import (ShaftParameters, ShaftStructure, acceleration_parts, build_structure,
                                             force_operator)
from cvtfem.outputs import OutputSpec


#: Chain positions of an H2 contact (ChainACVT's map without ``z``): pins ``p-1, p, p+1`` (2 each), ``x3``, slope (2).
N_REFINED_CHAIN = 9


def _tilt(th):
    """Tilt vectors (m, 3) from their two components."""
    return np.column_stack([th, np.zeros(len(th))])


@dataclass(frozen=True, eq=False)
class ElasticChainCVT(CompiledMappedContacts, ChainCVT):
    """ChainCVT on the elastic shafts of ``structure`` (:class:`~cvtfem.machines.shaft_structure.ShaftStructure`).

    Attributes (besides ChainCVT's; ``J`` and ``m_sheave`` are the structure's, kept for the loops)
    structure : ShaftStructure
    z_ref : (2, 2) m or None
        Reference position of each shaft's (fixed, movable) sheave face (the rigid model's at the quasi-static
        start), counted outwards from the chain mid-plane; None: that of the rigid start at the regime's ratio and
        driving speed at ``t = 0``, solved when first needed (:attr:`face_ref`), so that building the model for
        its layout (``cvtfem describe``) solves no start.
    """

    structure: Any = None
    z_ref: np.ndarray = None
    #: ``(ratio, w1, x0, report)`` of the rigid model's quasi-static start that set ``z_ref`` (reused).
    rigid_start: tuple = None

    @cached_property
    def _reference(self) -> tuple:
        """``(z_ref, rigid_start)``: the given ones, or those of the rigid start at the regime's start targets."""
        if self.z_ref is not None:
            return np.asarray(self.z_ref, float), self.rigid_start
        rs = self.rigid_start
        if rs is None:
            w1, _, i = self.regime.targets(0.0)
            rs = (i, w1) + tuple(self._rigid_static_state(i, w1))
        return self._face_reference(rs[2]), rs

    @property
    def face_ref(self) -> np.ndarray:
        """The faces' reference positions (2, 2) m the contacts use (``z_ref``, or the rigid start's)."""
        return self._reference[0]

    # ----- layout ------------------------------------------------------------------------------
    @cached_property
    def layout(self) -> StateLayout:
        return StateLayout(tuple(self.family.blocks) + (Block("structure", self.structure.n, "m, rad"),)
                           + tuple(self.control.blocks) + (Block("work", 4, "J", order=1),))

    @cached_property
    def _idx(self):
        nc, s = self.family.size, self.structure
        return nc, nc + s.spin_dof, nc + s.sheave_dofs[:, 1, 2], self.family.dof_index[:, :3]

    @cached_property
    def _sides(self) -> np.ndarray:
        """Side (sign of ``x3``) of each shaft's (fixed, movable) sheave, (2, 2)."""
        m = np.array([p.movable_side for p in self.structure.params])
        return np.column_stack([-m, m])

    @cached_property
    def _movable_node_u3(self) -> np.ndarray:
        """State index of ``u3`` of each movable sheave's node (the clamping reaction acts there)."""
        return self._idx[0] + self.structure.node_of_sheave[:, 1] + 2

    def state_label(self, i: int) -> str:
        i, n2, nc = int(i), self.n2, self._idx[0]
        if i >= 2 * n2 or i % n2 < nc:
            return super().state_label(i)
        j, s = i % n2, self.structure
        k = int(j - nc >= s.offset[1])
        local = j - nc - s.offset[k]
        name = f"{('driving', 'driven')[k]} shaft, "
        n_nodes = len(s.x[k])
        what = "movable sheave zeta" if local == 6 * n_nodes else \
            f"node {local // 6} {('u1', 'u2', 'u3', 'theta1', 'theta2', 'phi')[local % 6]}"
        return name + (f"d({what})/dt" if i >= n2 else what)

    @cached_property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        new = []
        for name in ("driving", "driven"):
            new += [OutputSpec(f"{name}.bearing_force", "N", f"Forces the two bearings of the {name} shaft carry "
                               "(K_b u + C_b v), x1 x2 x3 per bearing (the left one locates axially).", 6),
                    OutputSpec(f"{name}.sheave_tilt", "rad", f"Tilts theta1, theta2 of the fixed, then the movable "
                               f"sheave of the {name} shaft.", 4),
                    OutputSpec(f"{name}.sheave_shift", "m", f"Translation u1, u2 of the fixed, then the movable "
                               f"sheave of the {name} shaft.", 4)]
        for name, x in zip(("driving", "driven"), self.structure.x):
            new.append(OutputSpec(f"{name}.shaft_coordinates", "m, rad", f"Structure coordinates of the {name} shaft "
                                  "(per beam node u1 u2 u3 theta1 theta2 phi, then the movable sheave's zeta): "
                                  "renderings of a results file.", 6 * len(x) + 1))
            new.append(OutputSpec(f"{name}.face_reference", "m", f"Reference positions z_ref of the fixed, then the "
                                  f"movable sheave face of the {name} shaft in their sheaves' frames (the run's "
                                  "constant: renderings and resumes read it instead of solving the start again).", 2))
        rigid_only = ("driving.sheave_position", "driven.sheave_position")   # the rigid model's z: here sheave_shift
        return tuple(o for o in super().output_specs if o.name not in rigid_only) + tuple(new)

    @property
    def backend(self) -> str:
        """ChainCVT's label (the run summary's) with this model's mapped contacts (:meth:`_mapped_kernel`)."""
        family = super().backend in ("numba", "numba family")
        contacts = HAVE_NUMBA and self._mapped_kernel() is not None
        return "numba" if family and contacts else "numba contacts" if contacts else "numba family" if family else "numpy"

    # ----- contacts ----------------------------------------------------------------------------
    #: Share of the kernel's output that one evaluation carries (the S2/S3 kernel loads a mirrored pair: 1/2).
    kernel_share: ClassVar[float] = 0.5
    #: Sheaves of a shaft each pin end meets (2: the symmetric chain's end stands for both of its mirror pair).
    sheaves_per_end: ClassVar[int] = 2
    #: The sheaves' axial motion counts from the pulley's mid-plane (the symmetric chain has no axial motion).
    axial_relative: ClassVar[bool] = True
    #: Where the elastic start's solve ends above ``static_residual_limit``: raise (False), or keep the state it
    #: reached with the failure in ``report["unbalanced"]`` (True: a chain whose balance the solve may not reach).
    keeps_unbalanced_start: ClassVar[bool] = False

    def _pairs_map(self, ends, shafts):
        """``(ends, shafts, sheaves, cols, coef)``: each ``(end, shaft)`` pair with both sheaves (0 fixed, 1 movable) of
        its shaft, the state columns and weights (m, 19, k) of its mapped inputs in ``y = [q, v]`` (the contact map
        of :meth:`ChainCVT._contact_map`)."""
        e, k = np.repeat(ends, 2), np.repeat(shafts, 2)
        j = np.tile(np.arange(2), len(ends))
        dof3 = self._idx[3][e]
        return (e, k, j) + self._mapped_map(dof3[:, :, None], np.ones(dof3.shape + (1,)), k, j)

    def _mapped_pairs(self, q):
        """:meth:`_pairs_map` of the broad phase's candidates."""
        return self._pairs_map(*self._candidates(q))

    def _mapped_map(self, end_cols, end_coef, k, j):
        """The mapped inputs' ``(cols, coef)`` (m, 2 (P + 6) + 1, K) from the chain positions' (m, P, K) in the
        mirrored frame of the sheave (``x3 -> s x3``; H1: the pin end, P = 3; H2: the kernel's nine) and the
        sheave's structure columns: positions, their rates, the spin rate."""
        nc, n2 = self._idx[0], self.n2
        sd = nc + self.structure.sheave_dofs[k, j]                 # (m, 6)
        other = nc + self.structure.sheave_dofs[k, 1 - j, 2]
        own = np.column_stack([sd[:, :5], other])                  # (m, 6)
        (m, P, K), n_pos = end_cols.shape, end_cols.shape[1] + 6
        cols = np.zeros((m, 2 * n_pos + 1, K), np.int64)
        coef = np.zeros((m, 2 * n_pos + 1, K))
        for off in (0, n_pos):
            cols[:, off:off + P] = end_cols + (n2 if off else 0)
            coef[:, off:off + P] = end_coef
            cols[:, off + P:off + n_pos, 0] = own + (n2 if off else 0)
            coef[:, off + P:off + n_pos, 0] = 1.0
        cols[:, -1, 0] = n2 + sd[:, 5]
        coef[:, -1, 0] = 1.0
        return cols, coef

    def mapped_local(self, Z, k, j, details: bool = False):
        """Outputs (m, 11) of mapped H1 contacts with inputs ``Z`` (m, 19) on shafts ``k``, sheaves
        ``j``: generalized forces on the pin-end coordinates (3), the sheave's translation (3) and tilt (2), the other
        sheave's axial position (1) and the spin (1), and the friction power (W); with ``details`` also the kernel's
        per-contact dict (for one end and one sheave) with the mapped position ``X`` (kernel frame), tilt, side."""
        s = self._sides[k, j].astype(float)
        o = np.column_stack([self.contact.centres[k], self.structure.sheave_x3[k, j]])
        x = Z[:, :3].copy()
        x[:, 2] *= s
        a, th = Z[:, 3:6].copy(), _tilt(Z[:, 6:8])
        vx = Z[:, 9:12].copy()
        vx[:, 2] *= s
        va, vth = Z[:, 12:15].copy(), _tilt(Z[:, 15:17])
        if self.axial_relative:                                  # axial: from the pair's mid-plane
            a[:, 2] = 0.5 * (Z[:, 5] - Z[:, 8])
            va[:, 2] = 0.5 * (Z[:, 14] - Z[:, 17])
        d, dd = x - o - a, vx - va
        X = o + d - np.cross(th, d)
        Xd = dd - np.cross(th, dd) - np.cross(vth, d)
        X[:, 2] *= s
        Xd[:, 2] *= s
        kin = np.column_stack([X, self.face_ref[k, j], Xd, np.zeros(len(Z)), Z[:, 18]])
        out = self.contact.local(kin, k, details)
        Y, det = out if details else (out, None)
        if details:
            det = dict(det, X=X, tilt=th, side=s)
        F = self.kernel_share * Y[:, :3]
        F[:, 2] *= s                                               # conjugate to X in the true frame
        Qx = F + np.cross(th, F)                                     # (I - theta x)^T F
        Qpin = Qx.copy()
        Qpin[:, 2] *= s
        Qa = -Qx
        Qo = np.zeros(len(Z))
        if self.axial_relative:
            Qa[:, 2] *= 0.5
            Qo = -Qa[:, 2]
        share = self.kernel_share
        res = np.column_stack([Qpin, Qa, -np.cross(d, F)[:, :2], Qo, share * Y[:, 4], share * Y[:, 5]])
        return (res, det) if details else res

    def _local_constants(self, ends) -> dict:
        """Per-contact constants :meth:`mapped_local` takes besides its inputs (none; A2: the half signs)."""
        return {}

    def _mapped_contact_jacobian(self, q, v, reference: bool = False):
        """``((rows, cols, values), dD)``: the entries of ``dQ/dy`` of the mapped contacts (``y = [q, v]``) and
        ``-d P_fr / dy`` (2 n2,); compiled where :attr:`_compiled_mapped` offers it unless ``reference``, else per
        contact central differences of :meth:`mapped_local` (the same steps)."""
        ck = None if reference else self._compiled_mapped
        if ck is None:
            cols, coef, Jl = self._mapped_jacobian(q, v)
            return self._contact_entries(cols, coef, Jl), self._contact_power_gradient(cols, coef, Jl)
        return self._compiled_contact_jacobian(q, v)

    def _mapped_set(self, q, v, details: bool = False):
        e, k, j, cols, coef = self._mapped_pairs(q)
        Z = (coef * np.concatenate([q, v])[cols]).sum(axis=2)
        return e, k, j, cols, coef, Z, self.mapped_local(Z, k, j, details, **self._local_constants(e))

    def _contacts(self, q, v, details=False):
        e, k, j, cols, coef, Z, Y = self._mapped_set(q, v, details)
        return e, k, Z, Y

    # ----- right-hand side ---------------------------------------------------------------------
    def _forces(self, q, v, F, M, slip: bool = False):
        """Generalized forces (N, N m) and the friction power (W); with ``slip`` also the contact-force-weighted
        mean slip speed on each shaft (m/s, 0 without contact), as ChainCVT's."""
        nc = self._idx[0]
        Q = np.zeros(self.n2)
        Q[:nc] = self.family.forces(q[:nc], v[:nc])
        Pf, mean_slip = self._mapped_forces(q, v, Q, slip)
        self._add_structure_loads(q, v, F, M, Q)
        return (Q, Pf, mean_slip) if slip else (Q, Pf)

    def _add_structure_loads(self, q, v, F, M, Q) -> None:
        """Add to ``Q`` (n2,) the structure's linear forces, the shaft torques ``M`` (N m) and the clamping forces
        ``F`` (N) on the movable sheaves and their shaft nodes."""
        nc, iphi, iz, _ = self._idx
        vs = v[nc:]
        Q[nc:] -= self._structure_operator @ np.concatenate([q[nc:], vs, v[iphi[0]] * vs, v[iphi[1]] * vs])
        Q[iphi] += M
        side = self._sides[:, 1]
        Q[iz] -= side * F
        Q[self._movable_node_u3] += side * F

    @cached_property
    def _structure_operator(self) -> sp.csr_matrix:
        """The structure's linear forces in one product (:func:`~cvtfem.machines.shaft_structure.force_operator`)."""
        return force_operator(self.structure)

    def _mapped_forces(self, q, v, Q, slip: bool = False, reference: bool = False):
        """Add the mapped contacts' generalized forces to ``Q`` (n2,); return the friction power (W) and, with
        ``slip``, the contact-force-weighted mean slip speed per shaft (m/s; else None).  Compiled where
        :attr:`_compiled_mapped` offers it, unless ``reference`` or ``slip`` (the numpy path, its tested twin)."""
        if not (reference or slip) and self._compiled_mapped is not None:
            return self._compiled_mapped_forces(q, v, Q), None
        e, k, j, cols, coef, Z, Y = self._mapped_set(q, v, details=slip)
        mean_slip = None
        if slip:
            Y, det = Y
            N = np.bincount(k, det["N"], 2)
            mean_slip = np.bincount(k, det["N"] * np.linalg.norm(det["slip"], axis=1), 2) / np.maximum(N, 1e-300)
        rows, wr = self._output_rows(cols, coef)
        Q += np.bincount(rows.ravel(), (wr * Y[:, :-1, None]).ravel(), self.n2)
        return float(Y[:, -1].sum()), mean_slip

    @cached_property
    def _structure_inverse(self) -> np.ndarray:
        """``M^-1`` of the structure, dense, computed on one BLAS thread: a multi-threaded inverse rounds
        differently, and its bits would depend on where the model first needs it (inside a run, which steps on one
        thread, or before)."""
        with single_thread_blas():
            return sla.inv(self.structure.M.toarray())

    def solve_mass(self, Q):
        nc = self._idx[0]
        a = np.empty_like(Q)
        a[:nc] = self.family.solve_mass(Q[:nc])
        a[nc:] = self._structure_inverse @ Q[nc:]
        return a

    def evaluate(self, t: float, x, slip: bool = True):
        q, v, zc, _ = self.split(x)
        nc, iphi, iz, _ = self._idx
        w = v[iphi]
        F, M, dz, diag = self._controls(t, w, zc)
        Q, Pf, *mean_slip = self._forces(q, v, F, M, slip)
        vs = v[nc:]
        D = 2 * self.family.rayleigh(q[:nc], v[:nc]) - Pf + float(vs @ (self.structure.C @ vs))
        side = self._sides[:, 1]
        clamp = -float(np.sum(side * F * (v[iz] - v[self._movable_node_u3])))
        dW = np.array([M[0] * w[0], -M[1] * w[1], D, clamp])
        diag = dict(diag, F=F, M=M, w=w, friction_power=Pf, targets=self.regime.targets(t))
        if slip:
            diag["slip"] = mean_slip[0]
        return np.concatenate([v, self.solve_mass(Q), dz, dW]), diag

    # ----- Jacobian ----------------------------------------------------------------------------
    def _mapped_jacobian(self, q, v):
        """``(cols, coef, Jl)``: the contact map and the local Jacobians (m, 11, 19) of the mapped contacts."""
        e, k, j, cols, coef, Z, _ = self._mapped_set(q, v)
        n_pos = (Z.shape[1] - 1) // 2
        steps = difference_steps(n_pos)
        const = self._local_constants(e)
        Jl = central_local_jacobian(lambda Zp, kk: self.mapped_local(Zp, kk, j, **const), Z, k, steps, n_pos + 2)
        return cols, coef, Jl

    @cached_property
    def _inv_mass(self) -> sp.csr_matrix:
        import scipy.sparse.linalg as spla
        Mc = sp.csc_matrix(self.family.mass_matrix())
        return sp.block_diag([sp.csr_matrix(spla.inv(Mc)), sp.csr_matrix(self._structure_inverse)], format="csr")

    def jac(self, t: float, x) -> sp.csr_matrix:
        q, v, zc, _ = self.split(x)
        nc, iphi, iz, _ = self._idx
        s = self.structure
        n2, N = self.n2, self.size
        w = v[iphi]
        F, M, G = self._loop_gradient(t, w, zc)
        in_cols = np.concatenate([n2 + iphi, 2 * n2 + np.arange(self.control.size)])
        Kc, Cc = self.family.jacobian(q[:nc], v[:nc])
        side = self._sides[:, 1]
        mu3 = self._movable_node_u3
        parts = []
        acc = self._family_accelerations(Kc, Cc)
        if acc is None:                                      # the family's blocks on another pattern
            for Mx, off in ((Kc.tocoo(), 0), (Cc.tocoo(), n2)):
                parts.append((Mx.row, Mx.col + off, Mx.data))
        entries, dD_contact = self._mapped_contact_jacobian(q, v)
        parts.append(entries)
        vs = v[nc:]
        for kk in range(2):
            gv = -(s.G[kk] @ vs)
            nzr = np.flatnonzero(gv)
            parts.append((nc + nzr, np.full(len(nzr), n2 + iphi[kk]), gv[nzr]))
        for kk in range(2):
            parts.append((np.full(len(in_cols), iz[kk]), in_cols, -side[kk] * G[kk]))
            parts.append((np.full(len(in_cols), mu3[kk]), in_cols, side[kk] * G[kk]))
        parts.append((np.full(len(in_cols), iphi[1]), in_cols, G[2]))
        r, c, d = (np.concatenate([np.ravel(p[i]) for p in parts]) for i in range(3))
        dQ = sp.csr_matrix((d, (r, c)), shape=(n2, N))
        rest = self._inv_mass @ dQ + self._structure_accelerations(w)
        acc = rest if acc is None else acc + rest
        dD = self._chain_dissipation_gradient(q, v)
        dD[:2 * n2] += dD_contact
        dD[n2 + nc:2 * n2] += 2 * (s.C @ vs)
        Wr = np.zeros((4, N))
        Wr[0, n2 + iphi[0]] = M[0]
        Wr[1, in_cols] = -w[1] * G[2]
        Wr[1, n2 + iphi[1]] += -M[1]
        Wr[2] = dD
        Wr[3, n2 + iz] = -side * F
        Wr[3, n2 + mu3] = side * F
        Wr[3, in_cols] = -((side * (v[iz] - v[mu3])) @ G[:2])
        return self._stacked_jacobian(acc, G, in_cols, sp.csr_matrix(Wr))

    @cached_property
    def _structure_acceleration_parts(self) -> tuple:
        """:func:`~cvtfem.machines.shaft_structure.acceleration_parts` in this model's rows and columns."""
        nc, n2 = self._idx[0], self.n2
        return acceleration_parts(self.structure, self._structure_inverse, nc, (nc, n2 + nc), (n2, self.size))

    def _structure_accelerations(self, rates) -> sp.csr_matrix:
        """``M_s^-1 (-K q - (C + Omega_0 G_0 + Omega_1 G_1) v)`` as rows of ``d rhs / dx`` (n2 x state) at the spin
        rates ``rates`` (2,) rad/s."""
        indices, indptr, data = self._structure_acceleration_parts
        values = data[0] + data[1] + rates[0] * data[2] + rates[1] * data[3]
        return sp.csr_matrix((values, indices, indptr), shape=(self.n2, self.size))

    @cached_property
    def jac_sparsity(self) -> sp.csr_matrix:
        """Structural pattern: the chain stencil, every pin with both sheaves of every shaft, the structure
        (dense per shaft through its inverse mass), the loops, dense work-rate rows."""
        nc, iphi, iz, _ = self._idx
        n2, nz, N = self.n2, self.control.size, self.size
        ctrl = 2 * n2 + np.arange(nz)
        P = sp.csr_matrix(self.family.jac_sparsity, dtype=float).tocoo()
        rows, cols = [P.row, P.row], [P.col, P.col + n2]
        mc, mw = self._all_mapped()
        r, c, _ = self._contact_entries(mc, mw, np.ones((len(mc), (mc.shape[1] + 3) // 2, mc.shape[1])))
        rows.append(r)
        cols.append(c)
        S = (abs(self.structure.K) + abs(self.structure.C) + abs(self.structure.G[0]) + abs(self.structure.G[1]))
        S = S.tocoo()
        rows += [S.row + nc, S.row + nc]
        cols += [S.col + nc, S.col + n2 + nc]
        ns = self.structure.n
        rows.append(np.repeat(nc + np.arange(ns), 2))
        cols.append(np.tile(n2 + iphi, ns))
        in_cols = np.concatenate([n2 + iphi, ctrl])
        tgt = np.concatenate([iz, self._movable_node_u3, iphi])
        rows.append(np.repeat(tgt, len(in_cols)))
        cols.append(np.tile(in_cols, len(tgt)))
        dQ = sp.csr_matrix((np.ones(sum(len(x) for x in rows)), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(n2, N))
        acc = (abs(self._inv_mass) @ dQ) != 0
        top = sp.csr_matrix((np.ones(n2), (np.arange(n2), n2 + np.arange(n2))), shape=(n2, N))
        ctrl_rows = sp.csr_matrix((np.ones(nz * len(in_cols)), (np.repeat(np.arange(nz), len(in_cols)),
                                                                  np.tile(in_cols, nz))), shape=(nz, N))
        dense = np.arange(2 * n2 + nz)
        W = sp.csr_matrix((np.ones(4 * len(dense)), (np.repeat(np.arange(4), len(dense)), np.tile(dense, 4))),
                          shape=(4, N))
        return sp.vstack([top, acc.astype(float), ctrl_rows, W], format="csr").astype(bool)

    def _axial_outputs(self, k, j, c) -> dict[str, np.ndarray]:
        """Axial force of the pins on one sheave of each shaft (N, pushing it open): the pair's mean."""
        return {"contact.sheave_axial_force": -np.bincount(k, c["F"][:, 2], 2) / self.sheaves_per_end}

    def _all_mapped(self):
        """``(cols, coef)`` of every mapped contact the broad phase may return (the structural pattern)."""
        return self._pairs_map(*self._all_pairs())[3:]

    # ----- energy and outputs ------------------------------------------------------------------
    def energy(self, x) -> float:
        """Kinetic plus elastic energy: chain, structure (``v M v / 2 + q K q / 2``), Hertz potentials, J."""
        q, v, _, _ = self.split(x)
        nc, s = self._idx[0], self.structure
        _, _, _, (_, info) = self._contacts(q, v, details=True)
        qs, vs = q[nc:], v[nc:]
        return float(self.family.energy(q[:nc], v[:nc]) + 0.5 * vs @ (s.M @ vs) + 0.5 * qs @ (s.K @ qs)
                     + self.kernel_share * info["potential"].sum())

    def outputs(self, t: float, x) -> dict[str, Any]:
        """Named outputs; per pin end and shaft the contact values are the means over the two sheaves, the
        support force is the bearings' reaction on the shaft in the chain plane."""
        dx, diag = self.evaluate(t, x, slip=False)
        q, v, _, W = self.split(x)
        nc, n, s = self._idx[0], self.n_ends, self.structure
        e, k, j, _, _, _, (Y, c) = self._mapped_set(q, v, details=True)
        slot = 2 * e + k

        def per(values, width=1):
            out = np.zeros((2 * n, width))
            np.add.at(out, slot, np.reshape(values, (len(slot), width)) / self.sheaves_per_end)
            return out.ravel()
        P = dx[-4:]
        w, M, F = diag["w"], diag["M"], diag["F"]
        qs, vs = q[nc:], v[nc:]
        bearing = s.bearing_forces(qs, vs)
        tilt = qs[s.sheave_dofs[:, :, 3:5]].reshape(2, 4)
        shift = qs[s.sheave_dofs[:, :, 0:2]].reshape(2, 4)
        out = dict(self.family.outputs(q[:nc], v[:nc]))
        out.update({"chain.coordinates": q[:nc], "chain.span_tension": self.span_tensions(q, v, e, c["delta"]),
                    **self._contact_series(per, c),
                    "contact.friction_power": np.bincount(k, Y[:, -1], 2),
                    **self._axial_outputs(k, j, c),
                    "driving.speed": w[0], "driven.speed": w[1], "driving.torque": M[0], "driven.torque": M[1],
                    "driving.clamping_force": F[0], "driven.clamping_force": F[1],
                    "driving.support_force": -bearing[0, :, :2].sum(axis=0),
                    "driven.support_force": -bearing[1, :, :2].sum(axis=0),
                    "ratio": w[0] / w[1] if w[1] else np.nan, "efficiency": P[1] / P[0] if P[0] else 0.0,
                    "power": P, "work": W, "energy": self.energy(x),
                    "control.ratio_estimate": diag["ratio_estimate"], "control.resistance": diag["resistance"]})
        for i, name in enumerate(("driving", "driven")):
            out[f"{name}.bearing_force"] = bearing[i].ravel()
            out[f"{name}.sheave_tilt"] = tilt[i]
            out[f"{name}.sheave_shift"] = shift[i]
            out[f"{name}.shaft_coordinates"] = qs[s.offset[i]:s.offset[i] + 6 * len(s.x[i]) + 1]
            out[f"{name}.face_reference"] = self.face_ref[i]
        return {o.name: out[o.name] for o in self.output_specs}

    # ----- initial state -----------------------------------------------------------------------
    def rigid(self) -> ChainCVT:
        """The same chain, contact, loops and regime on the rigid shafts of model 1 (its ``J``, sheave mass)."""
        return ChainCVT(self.family, self.contact, self.J, self.m_sheave, self.regime, self.F_appl, self.control)

    def static_state(self, ratio: float, w1: float, tension: float | None = None, tol: float = 1e-10):
        """Quasi-static start on the elastic shafts: the rigid model's (:meth:`ChainCVT.static_state`, which
        also sets the faces' reference positions ``z_ref``), then the chain and the structure solved together
        (scipy ``least_squares``) for the balance of chain, Hertz, bearing and shaft forces with the driven
        clamping force and the chain's centrifugal forces; the spins and the driving movable sheave held (its
        clamping force is the reaction, ``report["F1"]``).  Returns ``(x0, report)`` as ChainCVT's, and
        ``report["model"]``: the model with ``z_ref`` set (use it for the run)."""
        rs = self.rigid_start if self.z_ref is not None else self._reference[1]
        if rs is not None and tension is None and (rs[0], rs[1]) == (ratio, w1):
            x0r, rep = rs[2], rs[3]
        else:
            x0r, rep = self._rigid_static_state(ratio, w1, tension, tol)
        model = replace(self, z_ref=self._face_reference(x0r), rigid_start=(ratio, w1, x0r, rep))
        return model._elastic_static(x0r, rep, w1, tol)

    def _rigid_static_state(self, ratio: float, w1: float, tension: float | None = None, tol: float = 1e-10):
        """``(x0, report)`` of the rigid model's quasi-static start (the hook a chain whose rigid start may fail
        overrides)."""
        return self.rigid().static_state(ratio, w1, tension, tol)

    def _solve_elastic_balance(self, residual, jacobian, y0, tol: float):
        """The elastic start's solve of ``residual(y) = 0`` with the sparse ``jacobian(y)``: scipy's dense
        Levenberg-Marquardt (the hook a chain with an indefinite, singular static stiffness overrides)."""
        return least_squares(residual, y0, jac=lambda y: jacobian(y).toarray(), method="lm", xtol=tol, ftol=tol,
                             gtol=tol, x_scale=1e-5, max_nfev=200)

    def _face_reference(self, x0r) -> np.ndarray:
        """``z_ref`` (2, 2) from the rigid start ``x0r``: both faces of a pair at its ``z``."""
        z = x0r[self.rigid()._idx[2]]
        return np.column_stack([z, z])

    def _elastic_static(self, x0r, rep, w1, tol):
        """The chain and structure balance from the rigid start ``(x0r, rep)`` (:meth:`static_state`)."""
        nc, _, iz, _ = self._idx
        s, n2, fam = self.structure, self.n2, self.family
        rig = self.rigid()
        r_iphi, r_n2 = rig._idx[1], rig.n2
        F2 = rep["F2"]
        q = np.zeros(n2)
        q[:nc] = x0r[:nc]
        pl = rep["placement"]
        speed = w1 * pl.r[0]
        a = np.zeros(nc)
        au = self.pin_positions(a)
        for kk in range(2):
            sel = pl.piece == kk
            au[sel] = -speed ** 2 / pl.r[kk] * (pl.u[sel] - self.contact.centres[kk]) / pl.r[kk]
        Q_cf = -(fam.mass_matrix() @ a)
        spins = nc + np.flatnonzero(s.dof_kind == 5)
        held = np.concatenate([spins, [iz[0]]])
        free = np.setdiff1d(np.arange(n2), held)
        vel = np.zeros(n2)
        F_stat = np.array([0.0, F2])
        mu3 = self._movable_node_u3

        def forces(y):
            qq = q.copy()
            qq[free] = y
            Q, _ = self._forces(qq, vel, F_stat, np.zeros(2))
            Q[:nc] += Q_cf
            Q[mu3[0]] += Q[iz[0]]                       # the held sheave's clamping reaction on its node
            return Q

        def jacobian(y):
            qq = q.copy()
            qq[free] = y
            x = np.concatenate([qq, vel, self.control.initial_state(0.0, 0.0), np.zeros(4)])
            K = self.jac(0.0, x)[n2:2 * n2, :n2]
            Ms = sp.block_diag([sp.csr_matrix(fam.mass_matrix()), self.structure.M], format="csr")
            held_reaction = sp.csr_matrix(([1.0], ([mu3[0]], [iz[0]])), shape=(n2, n2))
            dQ = (sp.identity(n2, format="csr") + held_reaction) @ (Ms @ K)
            return sp.csr_matrix(dQ)[free][:, free] / F2
        sol = self._solve_elastic_balance(lambda y: forces(y)[free] / F2, jacobian, q[free], tol)
        q[free] = sol.x
        Q = forces(sol.x)
        res = float(np.abs(Q[free]).max() / F2)
        unbalanced = None
        if not res <= self.static_residual_limit:
            unbalanced = NumericalError(f"the quasi-static solve on elastic shafts ended with a residual of {res:.3g} "
                                        f"of the clamping force after {sol.nfev} evaluations ({sol.message})",
                                        component="ElasticChainCVT.static_state")
            if not self.keeps_unbalanced_start:
                raise unbalanced
        side = self._sides[:, 1]
        F1 = float(Q[iz[0]] / side[0])
        v = np.zeros(n2)
        v[:nc] = x0r[r_n2:r_n2 + nc]
        w = x0r[r_n2 + r_iphi]
        for kk in range(2):
            sl = slice(nc + s.offset[kk], nc + s.offset[kk] + 6 * len(s.x[kk]))
            v[sl][5::6] = w[kk]
        self._turn_with_sheaves(q, v)
        x0 = np.concatenate([q, v, self.control.initial_state(*w), np.zeros(4)])
        _, _, _, (_, c) = self._contacts(q, v, details=True)
        report = dict(rep, residual=res, F1=F1, rigid_F1=rep["F1"], model=self, nfev_elastic=sol.nfev,
                      unbalanced=None if unbalanced is None else str(unbalanced),
                      max_penetration=float(c["delta"].max()),
                      tension=float(self._elastic_link_tension(q[:nc]).mean()))
        return x0, report

    def _turn_with_sheaves(self, q, v) -> None:
        """Set the velocities of the pin ends touching a fixed sheave to those of its material point (no slip): the
        spin about the sheave's displaced, tilted axis (to first order in the tilt)."""
        e, k, j, _, _, Z, (_, det) = self._mapped_set(q, v, details=True)
        on = (j == 0) & (det["delta"] > 0)
        arm = det["X"][on, :2] - self.contact.centres[k[on]]
        target = np.column_stack([-arm[:, 1], arm[:, 0], np.zeros(on.sum())]) * Z[on, 18, None]
        target[:, 2] *= det["side"][on]
        rate = target + np.cross(det["tilt"][on], target)
        rate[:, 2] *= det["side"][on]
        v[self._idx[3][e[on]]] = rate

    def start(self):
        w1, _, i = self.regime.targets(0.0)
        x0, rep = self.static_state(i, w1)
        if not np.array_equal(rep["model"].z_ref, self.face_ref):
            raise NumericalError("the model's face reference positions z_ref are not those of its start: leave them "
                                 "None (the rigid start's)", component="ElasticChainCVT.start")
        return x0, {"kind": f"quasi-static on elastic shafts (residual {rep['residual']:.1e} of F2, largest "
                            f"penetration {1e6 * rep['max_penetration']:.1f} um)", "model": rep["model"]}


@dataclass(frozen=True, eq=False)
class ElasticChainACVT(ElasticChainCVT, ChainACVT):
    """The whole-pin chain (A1) on elastic shafts: :class:`ElasticChainCVT`'s structure and sheave frames under
    :class:`~cvtfem.machines.chain_a_cvt.ChainACVT`'s pin ends, each meeting the one sheave on its side of a shaft
    (its movable or fixed sheave) with the pin end a combination of the pin's coordinates (its contact map).  The
    chain moves axially, so the sheaves' axial motion counts from the undeformed positions and the locating
    bearing carries the pulley's net axial force; the fixed faces start at ChainACVT's ``fixed_z``."""

    kernel_share: ClassVar[float] = 1.0
    sheaves_per_end: ClassVar[int] = 1
    axial_relative: ClassVar[bool] = False
    #: H2: the kernel's chain position inputs (without ``z``) and the slots of the end's ``X1, X2, X3`` among them.
    refined_chain_inputs: ClassVar[int] = N_REFINED_CHAIN
    refined_end_slots: ClassVar[tuple] = (2, 3, 6)

    #: The H2 contact is A5's half-end one (:mod:`~cvtfem.elements.chain.mapped_contact_kernel`'s maps around A1's
    #: frame: the half end and chord spread to three points, gathered back); A1: the frame's own inputs.
    half_end_frame: ClassVar[bool] = False

    def _mapped_kernel(self):
        """The pair kernel the compiled path runs: H2's :class:`RefinedSheaveContact` at whole-pin ends (A1) or inside
        the half-end contact (A5), H1 as :class:`ElasticChainCVT`'s; None for A2's coupled halves."""
        if not self.contact.refined:
            return super()._mapped_kernel()
        kernel = self.contact.pair.pair if self.half_end_frame else self.contact.pair
        return kernel if type(kernel) is RefinedSheaveContact else None

    @cached_property
    def _compiled_mapped(self) -> tuple | None:
        """Constants of :mod:`~cvtfem.elements.chain.mapped_contact_kernel`: H2 (A1, A5 half ends) or H1
        (:class:`ElasticChainCVT`'s); None for A2's coupled halves or without numba."""
        kernel = self._mapped_kernel()
        if not (self.contact.refined and HAVE_NUMBA and kernel is not None):
            return super()._compiled_mapped
        return MCK.pack_refined(kernel, self._sides, self.structure.sheave_x3, self.face_ref,
                                self.refined_end_slots[:2], self.half_end_frame, 0.5 * self.kernel_share)

    def _sheave_of(self, ends, shafts) -> np.ndarray:
        """Sheave (0 fixed, 1 movable) an end on side ``+-1`` (odd ends: ``x3 > 0``) meets on each shaft."""
        side = np.where(ends % 2 == 1, 1, -1)
        return (np.asarray(self.movable_side)[shafts] == side).astype(np.int64)

    def _pairs_map(self, ends, shafts):
        j = self._sheave_of(ends, shafts)
        cols, coef = ChainACVT._contact_map(self, ends, shafts)
        n_chain = self.refined_chain_inputs if self.contact.refined else 3   # the kernel's chain positions (no z)
        return (ends, shafts, j) + self._mapped_map(cols[:, :n_chain], coef[:, :n_chain], shafts, j)

    def mapped_local(self, Z, k, j, details: bool = False, sign=None):
        """H1: :meth:`ElasticChainCVT.mapped_local`.  H2 (variant (b)): outputs (m, 17) of the mapped contacts with
        inputs ``Z`` (m, 31): the generalized forces on the kernel's nine chain positions (mirrored frame), the
        sheave's translation (3), tilt (2), the other sheave's axial position (1, unused: absolute axial motion),
        on the spin, and the friction power (W); ``details`` as there.  ``sign`` (m,): the half signs of A2's
        coupled-halves kernel (variant (v)), an input of it before the spin rate."""
        if not self.contact.refined:
            return super().mapped_local(Z, k, j, details)
        nk = self.refined_chain_inputs
        n = nk + 6
        P, V = Z[:, :n], Z[:, n:2 * n]
        K, dK = self._refined_frame(P, k, j)
        extra = [] if sign is None else [sign]
        kin = np.column_stack([K, np.einsum("mij,mj->mi", dK, V)] + extra + [Z[:, -1]])
        out = self.contact.local(kin, k, details)
        Y, det = out if details else (out, None)
        Q = np.einsum("mij,mi->mj", dK[:, :nk], Y[:, :nk])                  # z_ref is a constant
        res = np.column_stack([Q, Y[:, -2], Y[:, -1]])
        if not details:
            return res
        return res, dict(det, X=K[:, list(self.refined_end_slots)], tilt=_tilt(P[:, nk + 3:nk + 5]),
                         side=self._sides[k, j].astype(float))

    def _refined_frame(self, P, k, j):
        """``(K, dK/dP)``: the H2 kernel's position inputs (m, 10) in the frame of the displaced, tilted sheave ``j``
        of shaft ``k`` and their derivative (m, 10, 15) in the mapped positions ``P`` (m, 15): pins ``p-1, p, p+1``
        at the end's offset (2 each), the end's ``x3``, its slope coordinates (2), all mirrored (``x3 -> s x3``), then
        the sheave's translation ``a`` (3), tilt (2) and the other sheave's axial position.  Every point goes
        through ``X = o + (I - theta x)(x - o - a)`` at the end's ``x3`` (the end's own ``X_3`` is the kernel's
        ``x3``); the end slope, the direction ``(gamma, 1)`` (true frame), through the same ``I - theta x``:
        ``gamma' = (gamma_1 - theta_2, gamma_2 + theta_1) / (1 + theta_2 gamma_1 - theta_1 gamma_2)``; the face stays
        at its reference ``z_ref``.  ``dK/dP`` is exact, so the rates are ``K' = dK/dP P'``."""
        m = len(P)
        s = self._sides[k, j].astype(float)
        c, o3 = self.contact.centres[k], self.structure.sheave_x3[k, j]
        a, t1, t2 = P[:, 9:12], P[:, 12], P[:, 13]
        d3 = s * P[:, 6] - o3 - a[:, 2]
        K, dK = np.zeros((m, 10)), np.zeros((m, 10, 15))
        one = np.ones(m)
        for i in range(3):
            d1, d2 = P[:, 2 * i] - c[:, 0] - a[:, 0], P[:, 2 * i + 1] - c[:, 1] - a[:, 1]
            K[:, 2 * i] = c[:, 0] + d1 - t2 * d3
            K[:, 2 * i + 1] = c[:, 1] + d2 + t1 * d3
            dK[:, 2 * i, [2 * i, 6, 9, 11, 13]] = np.column_stack([one, -s * t2, -one, t2, -d3])
            dK[:, 2 * i + 1, [2 * i + 1, 6, 10, 11, 12]] = np.column_stack([one, s * t1, -one, -t1, d3])
            if i == 1:                                                  # the end itself: its axial position
                K[:, 6] = s * (o3 + d3 - t1 * d2 + t2 * d1)
                dK[:, 6, [2, 3, 6, 9, 10, 11, 12, 13]] = s[:, None] * np.column_stack(
                    [t2, -t1, s, -t2, t1, -one, -d2, d1])
        e, g = END_SLOPE_FACTOR, s * END_SLOPE_FACTOR                  # slope coordinates: gamma_true = g sigma
        sg1, sg2 = P[:, 7], P[:, 8]
        n1, n2 = sg1 - s * t2 / e, sg2 + s * t1 / e
        den = 1.0 + g * (t2 * sg1 - t1 * sg2)
        K[:, 7], K[:, 8] = n1 / den, n2 / den
        dden = (g * t2, -g * t1, -g * sg2, g * sg1)                      # d(den)/d(sigma1, sigma2, theta1, theta2)
        for row, num, dnum in ((7, n1, (one, 0 * one, 0 * one, -s / e)), (8, n2, (0 * one, one, s / e, 0 * one))):
            dK[:, row, [7, 8, 12, 13]] = np.column_stack([(dn - num * dd / den) / den for dn, dd in zip(dnum, dden)])
        K[:, 9] = self.face_ref[k, j]
        return K, dK

    def rigid(self) -> ChainACVT:
        return ChainACVT(self.family, self.contact, self.J, self.m_sheave, self.regime, self.F_appl, self.control,
                         self.movable_side, self.fixed_z, self.start_chain)

    def _face_reference(self, x0r) -> np.ndarray:
        """``z_ref`` (2, 2): the fixed faces at ``fixed_z``, the movable ones at the rigid start's ``z``."""
        return np.column_stack([self.fixed_z, x0r[self.rigid()._idx[2]]])

    def _axial_outputs(self, k, j, c) -> dict[str, np.ndarray]:
        F3 = c["F"][:, 2]
        return {"contact.sheave_axial_force": -np.bincount(k[j == 1], F3[j == 1], 2),
                "contact.fixed_sheave_axial_force": -np.bincount(k[j == 0], F3[j == 0], 2)}

    def _turn_with_sheaves(self, q, v) -> None:
        """The pins on each arc turn with the spin about the sheaves' displaced axis (the tilt left out)."""
        nc, iphi = self._idx[0], self._idx[1]
        s = self.structure
        e, k, j, _, _, _, (_, det) = self._mapped_set(q, v, details=True)
        for kk in range(2):
            pins = np.unique(self.pin_of(e[(k == kk) & (det["delta"] > 0)]))
            centre = self.contact.centres[kk] + q[nc + s.sheave_dofs[kk, :, :2]].mean(axis=0)
            self._turn_with_sheave(q[:nc], v[:nc], pins, v[iphi[kk]], centre)


@dataclass(frozen=True, eq=False)
class ElasticChainA2CVT(ElasticChainACVT, ChainA2CVT):
    """Variant (v): the whole-pin chain with coupled pin halves (A2, :class:`~cvtfem.machines.chain_a2_cvt.ChainA2CVT`)
    on elastic shafts; each half end's H2 contact in the frame of its sheave as :class:`ElasticChainACVT`'s (the
    half offset ``sigma h_pin tau_p`` is formed from the mapped chords, in the sheave frame)."""

    def _local_constants(self, ends) -> dict:
        return {"sign": self.half_of(ends)}

    def rigid(self) -> ChainA2CVT:
        return ChainA2CVT(self.family, self.contact, self.J, self.m_sheave, self.regime, self.F_appl, self.control,
                          self.movable_side, self.fixed_z, self.start_chain)


#: Series holding each shaft's face reference ``z_ref`` (:meth:`ElasticChainCVT.outputs`).
FACE_REFERENCE = ("driving.face_reference", "driven.face_reference")


def with_face_reference(model, row):
    """``model`` with the faces' reference ``z_ref`` of ``row`` (the first row of a results file's
    :data:`FACE_REFERENCE` series, :func:`~cvtfem.io.results.read_first_row`), so that the rigid start need not be
    solved again and a resumed run keeps the faces where they were; ``model`` itself when it is not on elastic
    shafts or ``row`` is None (a file that predates the series)."""
    if row is None or not isinstance(model, ElasticChainCVT):
        return model
    return replace(model, z_ref=np.stack([np.asarray(row[name], float) for name in FACE_REFERENCE]))


def shaft_parameters(scene) -> tuple[ShaftParameters, ShaftParameters]:
    """The two shafts of a CVT scene's ``[cvt.driving]``, ``[cvt.driven]`` (movable sheaves on opposite sides)."""
    cvt = scene.cvt
    return tuple(ShaftParameters(s.shaft_length, s.shaft_diameter, s.shaft_elements, s.sheave_offset, s.inertia,
                                 s.sheave_mass, s.sheave_transverse_inertia, s.bearing_stiffness, s.bearing_damping,
                                 side)
                 for s, side in ((cvt.driving, 1), (cvt.driven, -1)))


def elastic(rigid: ChainCVT, structure: ShaftStructure) -> ElasticChainCVT:
    """The rigid transmission ``rigid`` (ChainCVT, or ChainACVT: :class:`ElasticChainACVT`) on ``structure``
    (``z_ref`` set by :meth:`ElasticChainCVT.static_state`)."""
    args = (rigid.family, rigid.contact, rigid.J, rigid.m_sheave, rigid.regime, rigid.F_appl, rigid.control)
    from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT   # the A5 transmissions build on this module
    if isinstance(rigid, ChainHalvesCVT):
        from cvtfem.machines.chain_halves_elastic_cvt import elastic_halves
        return elastic_halves(rigid, structure)
    if isinstance(rigid, ChainACVT):
        cls = ElasticChainA2CVT if isinstance(rigid, ChainA2CVT) else ElasticChainACVT
        return cls(*args, movable_side=rigid.movable_side, fixed_z=rigid.fixed_z,
                                start_chain=rigid.start_chain, structure=structure, z_ref=np.zeros((2, 2)))
    return ElasticChainCVT(*args, structure=structure, z_ref=np.zeros((2, 2)))


def from_scene(scene, geom, F_appl, **overrides) -> ElasticChainCVT:
    """:func:`cvtfem.machines.chain_cvt.from_scene` on the scene's elastic shafts (its ``effects.gyroscopic``,
    ``effects.damping``); the faces' references are the rigid start's, solved when first needed."""
    from cvtfem.machines.chain_cvt import from_scene as rigid_from_scene

    eff = scene.cvt.effects
    structure = build_structure(shaft_parameters(scene), scene.cvt.young_modulus, gyroscopic=eff.gyroscopic,
                                damping=eff.damping)
    return replace(elastic(rigid_from_scene(scene, geom, F_appl, **overrides), structure), z_ref=None)
