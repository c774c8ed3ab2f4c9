"""The discrete chain on two rigid shafts as a transmission (issue 13): a symmetric chain family (S2, S3)
in H1 contact with the rigid sheave pairs of two shafts of model 1, closed by the stabilisation loops.

State ``x = [q_chain, phi_1, phi_2, z_1, z_2, velocities, control states, W]``: the chain family's
coordinates, per shaft (1 driving, 2 driven) the spin angle ``phi_k`` (rad) and the sheave reference
position ``z_k`` (m) of model 1 (shafts-sheaves-supports §1: ``T = J phi'^2/2 + m z'^2/2``, ``m`` the
pair mass, ``delta W = -2 P delta z + M delta phi`` (1.229)), the states of the control family
(:class:`~cvtfem.control.stabilisation.Stabilisation` or ``OpenLoop``) and four work integrals
``W = [input, output, dissipated, clamping]`` (J) with ``d(T + V)/dt = M1 w1 + M2 w2 - 2 F.z' - D``.
Frame of the chain models: driven shaft axis at the origin, driving at ``(L, 0)``, chain counter-clockwise.

The contacts (:mod:`cvtfem.elements.chain.sheave_contact`) load both pin ends of every pin near a shaft
(mirror symmetry, ``2F``); the clamping forces ``F_k`` act per sheave.  A contact reads its local inputs
through the *contact map* (weighted state columns, :meth:`ChainCVT._contact_map`) and its forces act back
through the same map, so a family whose pin ends are linear combinations of its coordinates plugs in by
overriding the end hooks (:class:`~cvtfem.machines.chain_a_cvt.ChainACVT`, the whole-pin chains).  The
Jacobian is assembled from the chain family's blocks, per-contact central differences of the local contact
kernel (9 inputs, 6 outputs, all contacts at once) mapped on both sides, and differences of the cheap loop
outputs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import least_squares

from cvtfem.assembly.model import Linearization, ModelBase, StateLayout
from cvtfem.control.loop_start import integral_start
from cvtfem.control.regimes import Regime
from cvtfem.control.stabilisation import OpenLoop, Stabilisation, StabilisationParams
from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.base import Block
from cvtfem.elements.jit import HAVE_NUMBA
from cvtfem.elements.chain import sheave_contact_kernel as SK
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.placement import place_on_path
from cvtfem.elements.chain.sheave_contact import SheaveContact, hertz_constant
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.elements.chain.symmetric import ChainS1, ChainS2, ChainS3, damping_from_ratio
from cvtfem.errors import InputError, NumericalError
from cvtfem.machines.chain import pin_coordinate_label
from cvtfem.outputs import OutputSpec

FAMILIES = {"chain-S1": ChainS1, "chain-S2": ChainS2, "chain-S3": ChainS3}


@dataclass(frozen=True, eq=False)
class ChainCVT(ModelBase):
    """Chain family + sheave contact + two rigid shafts + regime + control family as ``x' = rhs(t, x)``.

    Attributes
    ----------
    family : ChainS2 or ChainS3
    contact : SheaveContact
    J, m_sheave : (2,) kg m^2, kg
        Axial inertia of shaft with sheaves, mass of the sheave pair (driving, driven).
    regime : Regime
        Targets ``(w1d, M1, i_d)``.
    F_appl : (2,) N
        Prescribed clamping force per sheave (the ratio loop corrects ``F1``).
    control : Stabilisation or OpenLoop
    """

    family: Any
    contact: Any
    J: np.ndarray
    m_sheave: np.ndarray
    regime: Regime
    F_appl: np.ndarray
    control: Any

    #: Sheaves the clamping force ``F`` acts on through one ``z`` coordinate: both of the symmetric pair.
    sheaves_per_z: ClassVar[float] = 2.0
    #: Largest residual (over the driven clamping force) the quasi-static start accepts.
    static_residual_limit: ClassVar[float] = 1e-6

    # ----- layout ------------------------------------------------------------------------------
    @cached_property
    def layout(self) -> StateLayout:
        return StateLayout(tuple(self.family.blocks) + (Block("shaft.phi", 2, "rad"), Block("shaft.z", 2, "m"))
                           + tuple(self.control.blocks) + (Block("work", 4, "J", order=1),))

    @cached_property
    def _idx(self):
        nc = self.family.size
        return nc, nc + np.arange(2), nc + 2 + np.arange(2), self.family.dof_index[:, :3]

    def split(self, x):
        """Views ``q, v, z_control, W`` of a state vector."""
        n, nz = self.n2, self.control.size
        return x[:n], x[n:2 * n], x[2 * n:2 * n + nz], x[2 * n + nz:]

    def state_label(self, i: int) -> str:
        """What state component ``i`` is, for failure messages: ``"pin 17, u3"``, ``"pin 17, du3/dt"``,
        ``"driven shaft, dphi/dt"``, ``"driving sheave, z"``, ``"control.speed[1]"``, ``"work: dissipated"``."""
        i, n2, nc = int(i), self.n2, self._idx[0]
        if i < 2 * n2:
            j, rate = i % n2, i >= n2
            if j < nc:
                return pin_coordinate_label(self.family, j, rate)
            shaft, coord = ("driving", "driven")[(j - nc) % 2], ("phi", "z")[(j - nc) // 2]
            part = "shaft" if coord == "phi" else "sheave"
            return f"{shaft} {part}, " + (f"d{coord}/dt" if rate else coord)
        j = i - 2 * n2
        for b in self.control.blocks:
            if j < b.size:
                return f"{b.name}[{j}]"
            j -= b.size
        return "work: " + ("input", "output", "dissipated", "clamping")[j]

    @cached_property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        n = self.n_ends
        return tuple(self.family.output_specs) + (
            OutputSpec("chain.coordinates", "m, rad",
                       "The chain family's coordinates q (its layout, `state_label`): the pin positions for "
                       "renderings and per-pin post-processing of a results file.", self.family.size),
            OutputSpec("contact.normal_force", "N",
                       "Normal contact force N per pin end and shaft (pin-major, driving then driven).", 2 * n),
            OutputSpec("contact.penetration", "m",
                       "Penetration Delta along the axis per pin end and shaft (<= 0: off; S1: how far the face "
                       "lies inside the free pin end).", 2 * n),
            OutputSpec("contact.radius", "m", "Contact radius per pin end and shaft (0 off contact).", 2 * n),
            OutputSpec("contact.slip_speed", "m/s", "Slip speed of the pin end on the sheave (0 off contact).", 2 * n),
            *((OutputSpec("contact.face_offset", "m", "Distance |x_*| of the refined (H2) contact point from the "
                          "pin-axis end per pin end and shaft (0 off contact); the pin's end face reaches width_n / 2 "
                          "from the axis (`cvtfem history`: the share of contacts beyond it).", 2 * n),)
              if self.refined_contact else ()),
            OutputSpec("contact.friction_force", "N",
                       "Friction force on one pin end, x1 x2 x3 per pin and shaft.", 6 * n),
            OutputSpec("contact.friction_power", "W", "Friction power of both sheaves of each shaft (<= 0).", 2),
            OutputSpec("contact.sheave_axial_force", "N",
                       "Sum of the pin axial contact forces on one sheave of each shaft.", 2),
            OutputSpec("chain.span_tension", "N", "Mean link tension of the tight (x2 < 0) and slack (x2 > 0) span: "
                       "links with both pins off contact.", 2),
            OutputSpec("driving.speed", "rad/s", "Angular speed of the driving shaft."),
            OutputSpec("driven.speed", "rad/s", "Angular speed of the driven shaft."),
            OutputSpec("driving.torque", "N m", "External torque on the driving shaft."),
            OutputSpec("driven.torque", "N m", "External torque on the driven shaft."),
            OutputSpec("driving.sheave_position", "m", "Axial position z of the driving pulley's sheave (the movable "
                       "one of an A chain), counted outwards from the chain plane: renderings of a results file."),
            OutputSpec("driven.sheave_position", "m", "Axial position z of the driven pulley's sheave (the movable "
                       "one of an A chain), counted outwards from the chain plane: renderings of a results file."),
            OutputSpec("driving.clamping_force", "N", "Clamping force per sheave, driving pulley."),
            OutputSpec("driven.clamping_force", "N", "Clamping force per sheave, driven pulley."),
            OutputSpec("driving.support_force", "N", "Bearing reaction on the rigid driving shaft in the chain "
                       "plane (x1, x2): minus the resultant of the pin contact forces (normal + friction) on its "
                       "sheaves.", 2),
            OutputSpec("driven.support_force", "N", "Bearing reaction on the rigid driven shaft in the chain "
                       "plane (x1, x2): minus the resultant of the pin contact forces (normal + friction) on its "
                       "sheaves.", 2),
            OutputSpec("ratio", "-", "Speed ratio omega1 / omega2."),
            OutputSpec("efficiency", "-", "Output over input power (instantaneous)."),
            OutputSpec("power", "W", "Input, output, dissipated and clamping power.", 4),
            OutputSpec("work", "J", "Input, output, dissipated and clamping work since t = 0.", 4),
            OutputSpec("energy", "J", "Kinetic plus elastic energy (chain, shafts, Hertz contacts)."),
        ) + tuple(self.control.output_specs)

    # ----- right-hand side ---------------------------------------------------------------------
    def _controls(self, t: float, w, z):
        w1d, M1, i_d = self.regime.targets(t)
        F, M2, dz, diag = self.control.outputs(w, z, i_d, w1d / i_d, M1, self.F_appl)
        return np.asarray(F, float), np.array([M1, M2]), dz, diag

    # ----- contact ends (the hooks a chain family with other pin ends overrides) --------------------
    @property
    def n_ends(self) -> int:
        """Pin ends that touch sheaves (one per pin: the mirror end is implied)."""
        return self.family.n

    def pin_of(self, ends):
        """Pin of each contact end."""
        return ends

    def pin_positions(self, q_chain):
        """In-plane pin positions (n, 2) m, a view of the chain coordinates."""
        return self.family.split(q_chain)[0]

    def _all_pairs(self):
        """Every ``(end, shaft)`` pair the broad phase may return (the structural pattern)."""
        return np.repeat(np.arange(self.n_ends), 2), np.tile(np.arange(2), self.n_ends)

    def _candidates(self, q):
        """Broad phase: ``(ends, shafts)`` within the sheaves' outer radius."""
        return self.contact.candidates(self.pin_positions(q[:self._idx[0]]))

    @property
    def _constants(self) -> np.ndarray:
        """Values appended to ``[q, v]`` that contact inputs may read (none here)."""
        return np.zeros(0)

    def _contact_map(self, ends, shafts):
        """``(cols, coef)`` (m, 9, k): local input ``j`` of a contact is ``sum_a coef[j, a] y[cols[j, a]]`` of
        ``y = [q, v, constants]``; its generalized forces act on the same coordinates (virtual work)."""
        cols = self._contact_columns(ends, shafts)
        return cols[:, :, None], np.ones(cols.shape + (1,))

    def _contact_set(self, q, v, details=False):
        """Broad phase, the input map, local inputs and outputs of the contacts."""
        ends, shafts = self._candidates(q)
        cols, coef = self._contact_map(ends, shafts)
        X = (coef * np.concatenate([q, v, self._constants])[cols]).sum(axis=2)
        return ends, shafts, cols, coef, X, self.contact.local(X, shafts, details)

    def _contacts(self, q, v, details=False):
        """``(ends, shafts, X, Y)``: broad phase, local inputs and outputs of the contacts."""
        ends, shafts, _, _, X, Y = self._contact_set(q, v, details)
        return ends, shafts, X, Y

    def _output_rows(self, cols, coef):
        """Rows (in ``q``) and weights (m, n_force, k) of the local force outputs: one per position input (the
        first ``(n_in - 1) / 2`` inputs: pin-end and sheave coordinates) and the last on ``phi`` (whose rate is
        the last input); weight 0 where an output acts on a constant (a fixed sheave)."""
        n2 = self.n2
        pick = list(range((cols.shape[1] - 1) // 2)) + [cols.shape[1] - 1]
        rows = cols[:, pick].copy()
        rows[:, -1] -= n2
        w = np.where(rows < n2, coef[:, pick], 0.0)
        return np.where(w != 0, rows, 0), w

    def _contact_entries(self, cols, coef, Jl, n_in: int | None = None):
        """``(rows, cols, values)`` of ``dQ/dy`` from the local Jacobians ``Jl`` (m, n_force + 1, n_in) over the
        first ``n_in`` inputs (default all; ``y = [q, v]``; constants dropped): ``R^T Jl P`` contact by contact
        (the last output, the friction power, is not a force)."""
        n_in = cols.shape[1] if n_in is None else n_in
        rows, rw = self._output_rows(cols, coef)
        cw = np.where(cols[:, :n_in] < 2 * self.n2, coef[:, :n_in], 0.0)
        vals = rw[:, :, :, None, None] * Jl[:, :-1, None, :n_in, None] * cw[:, None, None, :, :]
        shape = vals.shape
        R = np.broadcast_to(rows[:, :, :, None, None], shape)
        C = np.broadcast_to(cols[:, None, None, :n_in, :], shape)
        keep = vals != 0
        return R[keep], C[keep], vals[keep]

    @property
    def backend(self) -> str:
        """Which kernels the right-hand side runs (the run summary's label): ``"numba"`` (chain family and contacts
        compiled), ``"numba contacts"`` (the contacts only) or ``"numpy"``."""
        chain = getattr(self.family, "chain", self.family)
        family = getattr(chain, "backend", "numpy") == "numba"
        contacts = self._compiled_contact is not None
        return "numba" if family and contacts else "numba contacts" if contacts else "numba family" if family else "numpy"

    #: The compiled contact module whose ``jacobian`` :meth:`_contact_jacobian` calls (H1; A5's H2 sets its own).
    _contact_kernel: ClassVar = SK

    @cached_property
    def _compiled_contact(self) -> tuple | None:
        """Constants of the compiled H1 contact path (:mod:`~cvtfem.elements.chain.sheave_contact_kernel`) for a
        mirrored pair or single ends with :class:`SheaveContact`; None for the other kernels (H2, rigid, coupled
        halves) or without numba: those take the numpy path."""
        pair, scale = (self.contact.pair, 0.5) if isinstance(self.contact, EndContact) else (self.contact, 1.0)
        if not HAVE_NUMBA or type(pair) is not SheaveContact:
            return None
        return SK.pack(pair, scale)

    @cached_property
    def _pair_table(self) -> tuple:
        """``(cols, coef, shafts, rows, weights)`` of every ``(end, shaft)`` pair (contact map and output rows, built
        once): the table the compiled contact path loops over."""
        ends, shafts = self._all_pairs()
        cols, coef = self._contact_map(ends, shafts)
        rows, w = self._output_rows(cols, coef)
        return (np.ascontiguousarray(cols, np.int64), np.ascontiguousarray(coef, float), shafts.astype(np.int64),
                np.ascontiguousarray(rows, np.int64), np.ascontiguousarray(w, float))

    def _contact_forces(self, q, v, Q, slip: bool = False, reference: bool = False):
        """Add the contact forces to ``Q`` (n2,); return the friction power (W) and, with ``slip``, the
        contact-force-weighted mean slip speed on each shaft (m/s, 0 without contact).  Compiled where
        :attr:`_compiled_contact` offers it, unless ``reference`` (the numpy path, its tested twin)."""
        ck = None if reference else self._compiled_contact
        if ck is not None:
            stats = np.zeros((2, 2))
            Pf = SK.forces(np.concatenate([q, v, self._constants]), *self._pair_table, *ck, Q, stats)
            return Pf, stats[:, 1] / np.maximum(stats[:, 0], 1e-300)
        _, shafts, cols, coef, _, Y = self._contact_set(q, v, details=slip)
        mean_slip = None
        if slip:
            Y, det = Y
            N = np.bincount(shafts, det["N"], 2)
            mean_slip = np.bincount(shafts, det["N"] * np.linalg.norm(det["slip"], axis=1), 2) / np.maximum(N, 1e-300)
        rows, w = self._output_rows(cols, coef)
        Q += np.bincount(rows.ravel(), (w * Y[:, :-1, None]).ravel(), self.n2)
        return float(Y[:, -1].sum()), mean_slip

    def _forces(self, q, v, F, M, slip: bool = False):
        """Generalized forces on all coordinates (N, N m) and the friction power (W); with ``slip`` also the
        contact-force-weighted mean slip speed on each shaft (m/s, 0 without contact)."""
        nc, iphi, iz, _ = self._idx
        Q = np.zeros(self.n2)
        Q[:nc] = self.family.forces(q[:nc], v[:nc])
        Pf, mean_slip = self._contact_forces(q, v, Q, slip)
        Q[iphi] += M
        Q[iz] -= self.sheaves_per_z * F
        return (Q, Pf, mean_slip) if slip else (Q, Pf)

    def _contact_jacobian(self, q, v, reference: bool = False):
        """``(rows, cols, values)`` of ``dQ/dy`` of the contacts (``y = [q, v]``) and ``-d P_fr / dy`` (2 n2,)
        (compiled where offered, else, or with ``reference``, the numpy path)."""
        ck = None if reference else self._compiled_contact
        if ck is not None:
            table = self._pair_table
            cols, rows = table[0], table[3]
            size = cols.shape[0] * rows.shape[1] * cols.shape[1] * cols.shape[2] ** 2     # at most, all pairs near
            r, c, d = np.empty(size, np.int64), np.empty(size, np.int64), np.empty(size)
            dD = np.zeros(2 * self.n2)
            K = self._contact_kernel
            k = K.jacobian(np.concatenate([q, v, self._constants]), *table, *ck, K.STEPS, 2 * self.n2, r, c, d, dD)
            return (r[:k], c[:k], d[:k]), dD
        _, shafts, ccols, coef, X, _ = self._contact_set(q, v)
        Jl = self.contact.local_jacobian(X, shafts)            # (m, outputs, inputs)
        return self._contact_entries(ccols, coef, Jl), self._contact_power_gradient(ccols, coef, Jl)

    def solve_mass(self, Q):
        nc, iphi, iz, _ = self._idx
        a = np.empty_like(Q)
        a[:nc] = self.family.solve_mass(Q[:nc])
        a[iphi] = Q[iphi] / self.J
        a[iz] = Q[iz] / self.m_sheave
        return a

    def evaluate(self, t: float, x, slip: bool = True):
        """``(dx/dt, info)``: right-hand side and the loop's quantities (``targets`` of the regime, clamping
        forces ``F``, torques ``M``, speeds ``w``, friction power; with ``slip`` the mean slip speed per shaft)."""
        q, v, zc, _ = self.split(x)
        nc, iphi, iz, _ = self._idx
        w = v[iphi]
        F, M, dz, diag = self._controls(t, w, zc)
        Q, Pf, *mean_slip = self._forces(q, v, F, M, slip)
        D = 2 * self.family.rayleigh(q[:nc], v[:nc]) - Pf
        dW = np.array([M[0] * w[0], -M[1] * w[1], D, -self.sheaves_per_z * float(F @ v[iz])])
        diag = dict(diag, F=F, M=M, w=w, friction_power=Pf, targets=self.regime.targets(t))
        if slip:
            diag["slip"] = mean_slip[0]
        return np.concatenate([v, self.solve_mass(Q), dz, dW]), diag

    def rhs(self, t: float, x):
        return self.evaluate(t, x, slip=False)[0]

    # ----- Jacobian ----------------------------------------------------------------------------
    @cached_property
    def _inv_mass(self) -> sp.csr_matrix:
        Mc = sp.csc_matrix(self.family.mass_matrix())
        return sp.block_diag([sp.csr_matrix(spla.inv(Mc)), sp.diags(1 / self.J), sp.diags(1 / self.m_sheave)],
                             format="csr")

    def _loop_gradient(self, t, w, zc):
        """``d(F1, F2, M2, dz) / d(w1, w2, z_control)`` by forward differences (cheap, piecewise smooth)."""
        nz = self.control.size
        F, M, dz, _ = self._controls(t, w, zc)
        u0 = np.concatenate([F, M[1:], dz])
        G = np.zeros((3 + nz, 2 + nz))
        for j in range(2 + nz):
            wp, zp = w.copy(), zc.copy()
            h = 1e-7 * max(1.0, abs(w[j] if j < 2 else zc[j - 2]))
            if j < 2:
                wp[j] += h
            else:
                zp[j - 2] += h
            Fp, Mp, dzp, _ = self._controls(t, wp, zp)
            G[:, j] = (np.concatenate([Fp, Mp[1:], dzp]) - u0) / h
        return F, M, G

    def _contact_columns(self, pins, shafts):
        """State columns of the 9 local contact inputs, (m, 9)."""
        nc, iphi, iz, dof3 = self._idx
        n2 = self.n2
        return np.column_stack([dof3[pins], iz[shafts], n2 + dof3[pins], n2 + iz[shafts], n2 + iphi[shafts]])

    def jac(self, t: float, x) -> sp.csr_matrix:
        """Sparse ``d rhs / dx``."""
        q, v, zc, _ = self.split(x)
        nc, iphi, iz, _ = self._idx
        n2, nz, N = self.n2, self.control.size, self.size
        ctrl = 2 * n2 + np.arange(nz)
        w = v[iphi]
        F, M, G = self._loop_gradient(t, w, zc)
        in_cols = np.concatenate([n2 + iphi, ctrl])          # columns of the loops' inputs
        Kc, Cc = self.family.jacobian(q[:nc], v[:nc])
        rows, cols, vals = [], [], []

        def add(r, c, d):
            rows.append(np.ravel(r))
            cols.append(np.ravel(c))
            vals.append(np.ravel(d))
        acc = self._family_accelerations(Kc, Cc)
        if acc is None:                                      # the family's blocks on another pattern
            for Mx, off in ((Kc.tocoo(), 0), (Cc.tocoo(), n2)):
                add(Mx.row, Mx.col + off, Mx.data)
        entries, dD_contact = self._contact_jacobian(q, v)
        add(*entries)
        add(np.repeat(iz, len(in_cols)), np.tile(in_cols, 2), -self.sheaves_per_z * G[:2].ravel())   # -2 F on z
        add(np.full(len(in_cols), iphi[1]), in_cols, G[2])                              # M2 on phi2
        dQ = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n2, N))
        acc = self._inv_mass @ dQ if acc is None else acc + self._inv_mass @ dQ
        # work rates: [M1 w1, -M2 w2, 2 Phi - P_fr, -2 F.z']
        Wr = np.zeros((4, N))
        Wr[0, n2 + iphi[0]] = M[0]
        Wr[1, in_cols] = -w[1] * G[2]
        Wr[1, n2 + iphi[1]] += -M[1]
        Wr[2, :2 * n2] = dD_contact
        Wr[2] += self._chain_dissipation_gradient(q, v)
        Wr[3, n2 + iz] = -self.sheaves_per_z * F
        Wr[3, in_cols] = -self.sheaves_per_z * (v[iz] @ G[:2])
        return self._stacked_jacobian(acc, G, in_cols, sp.csr_matrix(Wr))

    @cached_property
    def _family_acceleration_map(self) -> tuple:
        """``(S, P, indices, indptr)``: the accelerations ``M^-1 [dQ/dq, dQ/dv]`` of the chain family's blocks as a
        linear map ``S`` of their data (``dQ/dq`` then ``dQ/dv``, both on the family's sorted pattern ``P``) onto the
        data of a fixed CSR structure ``(indices, indptr)`` of ``n2`` rows over the state (built once)."""
        P = sp.csr_matrix(self.family.jac_sparsity, dtype=bool)
        P.sort_indices()
        nnz, n2, N = P.nnz, self.n2, self.size
        row = np.repeat(np.arange(P.shape[0]), np.diff(P.indptr))
        col = np.concatenate([P.indices, n2 + P.indices]).astype(np.int64)
        row, label = np.concatenate([row, row]), np.arange(2 * nnz)
        Mi = sp.csc_matrix(self._inv_mass)
        count = np.diff(Mi.indptr)[row]                     # M^-1 entries in each source row's column
        start = np.repeat(Mi.indptr[row], count) + (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count))
        keys = Mi.indices[start].astype(np.int64) * N + np.repeat(col, count)
        uniq, pos = np.unique(keys, return_inverse=True)
        S = sp.csr_matrix((Mi.data[start], (pos, np.repeat(label, count))), shape=(len(uniq), 2 * nnz))
        indptr = np.searchsorted(uniq // N, np.arange(n2 + 1))
        return S, P, (uniq % N).astype(np.int32), indptr.astype(np.int32)

    def _family_accelerations(self, Kc, Cc) -> sp.csr_matrix | None:
        """``M^-1 [dQ/dq, dQ/dv]`` of the chain family's blocks (``n2 x`` state, CSR) through
        :attr:`_family_acceleration_map`, or None where the blocks are not on the family's sorted pattern."""
        S, P, indices, indptr = self._family_acceleration_map
        for B in (Kc, Cc):
            if not (isinstance(B, sp.csr_matrix) and B.nnz == P.nnz and np.array_equal(B.indptr, P.indptr)
                    and np.array_equal(B.indices, P.indices)):
                return None
        data = S @ np.concatenate([Kc.data, Cc.data])
        return sp.csr_matrix((data, indices, indptr), shape=(self.n2, self.size))

    def _dissipation_gradient(self, q, v, cols, coef, Jl) -> np.ndarray:
        """``d D / d y`` (N,) of the chain's dissipated power ``D = 2 Phi - P_fr`` (its Rayleigh function and the
        contact friction power, whose local Jacobians ``Jl`` act through the contact map ``cols``, ``coef``)."""
        dD = self._chain_dissipation_gradient(q, v)
        dD[:2 * self.n2] += self._contact_power_gradient(cols, coef, Jl)
        return dD

    def _contact_power_gradient(self, cols, coef, Jl) -> np.ndarray:
        """``-d P_fr / d y`` (2 n2,) of the contact friction power from the local Jacobians ``Jl``."""
        dD = np.zeros(2 * self.n2)
        cw = np.where(cols < 2 * self.n2, coef, 0.0)
        np.add.at(dD, np.where(cw != 0, cols, 0).ravel(), -(cw * Jl[:, -1, :, None]).ravel())
        return dD

    def _chain_dissipation_gradient(self, q, v) -> np.ndarray:
        """``d (2 Phi) / d y`` (N,) of the chain family's dissipated power: the family's own gradient where it offers
        one (``dissipation_gradient``, from its Jacobian pass), else ``-(dQ_d/dq)^T v`` and ``-2 Q_d``."""
        nc, n2 = self._idx[0], self.n2
        dD = np.zeros(self.size)
        if hasattr(self.family, "dissipation_gradient"):
            dD[:nc], dD[n2:n2 + nc] = self.family.dissipation_gradient(q[:nc], v[:nc])
            return dD
        Qd = self.family.dissipative_forces(q[:nc], v[:nc])
        Kd = self.family.jacobian(q[:nc], v[:nc], part="dissipative", wrt=(0,))[0]
        dD[:nc] = -(Kd.T @ v[:nc])
        dD[n2:n2 + nc] = -2 * Qd
        return dD

    def _stacked_jacobian(self, acc, G, in_cols, Wr) -> sp.csr_matrix:
        """``d rhs / dx`` from the acceleration rows ``acc``, the loops' gradient ``G`` over their inputs ``in_cols``
        and the work-rate rows ``Wr`` (``x' = v`` on top)."""
        n2, nz, N = self.n2, self.control.size, self.size
        ctrl_rows = sp.csr_matrix((G[3:].ravel(), (np.repeat(np.arange(nz), 2 + nz), np.tile(in_cols, nz))),
                                  shape=(nz, N))
        top = sp.csr_matrix((np.ones(n2), (np.arange(n2), n2 + np.arange(n2))), shape=(n2, N))
        return sp.vstack([top, acc, ctrl_rows, Wr.tocsr()], format="csr")

    @cached_property
    def jac_sparsity(self) -> sp.csr_matrix:
        """Structural pattern: chain stencil (pins ``p +- 2``), every pin with every shaft (broad phase
        may take any pin), the loops, and dense work-rate rows (all but the angles)."""
        iphi, iz = self._idx[1:3]
        n2, nz, N = self.n2, self.control.size, self.size
        ctrl = 2 * n2 + np.arange(nz)
        P = sp.csr_matrix(self.family.jac_sparsity, dtype=float).tocoo()
        rows = [P.row, P.row]
        cols = [P.col, P.col + n2]
        ccols, coef = self._contact_map(*self._all_pairs())
        n_force = (ccols.shape[1] - 1) // 2 + 1
        r, c, _ = self._contact_entries(ccols, coef, np.ones((len(ccols), n_force + 1, ccols.shape[1])))
        rows.append(r)
        cols.append(c)
        in_cols = np.concatenate([n2 + iphi, ctrl])
        rows.append(np.repeat(np.concatenate([iz, iphi]), len(in_cols)))
        cols.append(np.tile(in_cols, 4))
        dQ = sp.csr_matrix((np.ones(sum(len(r) for r in rows)), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(n2, N))
        acc = (abs(self._inv_mass) @ dQ) != 0
        top = sp.csr_matrix((np.ones(n2), (np.arange(n2), n2 + np.arange(n2))), shape=(n2, N))
        ctrl_rows = sp.csr_matrix((np.ones(nz * len(in_cols)), (np.repeat(np.arange(nz), len(in_cols)),
                                                                  np.tile(in_cols, nz))), shape=(nz, N))
        dense = np.setdiff1d(np.arange(2 * n2 + nz), iphi)
        W = sp.csr_matrix((np.ones(4 * len(dense)), (np.repeat(np.arange(4), len(dense)), np.tile(dense, 4))),
                          shape=(4, N))
        return sp.vstack([top, acc.astype(float), ctrl_rows, W], format="csr").astype(bool)

    def linearize(self, x0, t: float = 0.0) -> Linearization:
        """First-order ``A = d rhs / dx`` (the loops and work integrals are first-order)."""
        return Linearization(A=self.jac(t, x0))

    # ----- energy and outputs ------------------------------------------------------------------
    def energy(self, x) -> float:
        """Kinetic plus elastic energy: chain, shafts and sheaves, Hertz potentials of both pin ends, J."""
        q, v, _, _ = self.split(x)
        nc, iphi, iz, _ = self._idx
        _, _, _, (_, info) = self._contacts(q, v, details=True)
        return float(self.family.energy(q[:nc], v[:nc]) + 0.5 * self.J @ v[iphi] ** 2
                     + 0.5 * self.m_sheave @ v[iz] ** 2 + info["potential"].sum())

    def power(self, t: float, x) -> np.ndarray:
        """``[M1 w1, -M2 w2, dissipation, clamping power]``, W."""
        return self.rhs(t, x)[-4:]

    def outputs(self, t: float, x) -> dict[str, Any]:
        """Named outputs of :attr:`output_specs` at ``(t, x)``."""
        dx, diag = self.evaluate(t, x, slip=False)      # the contact details come below
        q, v, _, W = self.split(x)
        nc, _, iz, _ = self._idx
        n = self.n_ends
        pins, shafts, _, (Y, c) = self._contacts(q, v, details=True)
        k = 2 * pins + shafts

        def per(values, width=1):
            out = np.zeros((2 * n, width))
            out[k] = np.reshape(values, (len(k), width))
            return out.ravel()
        P = dx[-4:]
        w, M, F = diag["w"], diag["M"], diag["F"]
        support = np.column_stack([np.bincount(shafts, Y[:, j], 2) for j in (0, 1)])   # forces on the pin ends
        out = dict(self.family.outputs(q[:nc], v[:nc]))
        out.update({"chain.coordinates": q[:nc], "chain.span_tension": self.span_tensions(q, v, pins, c["delta"]),
                    **self._contact_series(per, c),
                    "contact.friction_power": np.bincount(shafts, Y[:, -1], 2),
                    **self._sheave_outputs(pins, shafts, c),
                    "driving.speed": w[0], "driven.speed": w[1], "driving.torque": M[0], "driven.torque": M[1],
                    "driving.sheave_position": q[iz[0]], "driven.sheave_position": q[iz[1]],
                    "driving.clamping_force": F[0], "driven.clamping_force": F[1],
                    "driving.support_force": support[0], "driven.support_force": support[1],
                    "ratio": w[0] / w[1] if w[1] else math.nan, "efficiency": P[1] / P[0] if P[0] else 0.0,
                    "power": P, "work": W, "energy": self.energy(x),
                    "control.ratio_estimate": diag["ratio_estimate"], "control.resistance": diag["resistance"]})
        out.update(self._more_outputs(x))
        return {s.name: out[s.name] for s in self.output_specs}

    @property
    def refined_contact(self) -> bool:
        """The contact is H2 (its details hold the contact point's ``offset`` from the pin-axis end)."""
        return isinstance(self.contact, RefinedSheaveContact) or getattr(self.contact, "refined", False)

    @staticmethod
    def _contact_series(per, c) -> dict[str, np.ndarray]:
        """The per-end contact outputs from the contact details ``c``, spread over ends and shafts by ``per``:
        normal force (N), penetration, contact radius (m), slip speed (m/s), friction force (N), H2's face offset
        (m); radius, slip and offset are 0 off contact."""
        on = c["delta"] > 0
        out = {"contact.normal_force": per(c["N"]), "contact.penetration": per(c["delta"]),
               "contact.radius": per(np.where(on, c["radius"], 0.0)),
               "contact.slip_speed": per(np.where(on, np.linalg.norm(c["slip"], axis=1), 0.0)),
               "contact.friction_force": per(c["F_fr"], 3)}
        if "offset" in c:
            out["contact.face_offset"] = per(np.where(on, np.linalg.norm(c["offset"], axis=1), 0.0))
        return out

    def _more_outputs(self, x) -> dict[str, Any]:
        """Outputs a subclass adds to :attr:`output_specs` (none here)."""
        return {}

    def span_tensions(self, q, v, pins, delta):
        """Mean link tension (N) of the tight and the slack span: links with both pins off contact
        (``pins``, ``delta`` of the candidate contacts), split by the sign of the link midpoint's ``x2``."""
        nc = self._idx[0]
        fam = self.family
        u = self.pin_positions(q[:nc])
        touching = np.zeros(fam.n, bool)
        touching[self.pin_of(pins)[delta > 0]] = True
        free = ~touching & ~touching[fam.ip1] & (fam.on > 0)
        y = 0.5 * (u[:, 1] + u[fam.ip1, 1])
        T = fam.outputs(q[:nc], v[:nc])[f"{fam.name}.link_tension"]
        return np.array([T[free & (y < 0)].mean() if (free & (y < 0)).any() else math.nan,
                         T[free & (y > 0)].mean() if (free & (y > 0)).any() else math.nan])

    def _sheave_outputs(self, ends, shafts, c) -> dict[str, np.ndarray]:
        """Axial force of the chain on one sheave of each shaft (N, positive pushing it open)."""
        return {"contact.sheave_axial_force": -np.bincount(shafts, c["F"][:, 2], 2)}

    def _elastic_link_tension(self, q_chain):
        """Elastic link tensions (n,) N."""
        return self.family.outputs(q_chain, np.zeros_like(q_chain))[f"{self.family.name}.link_tension_elastic"]

    def _placed(self, pl, u3):
        """Chain coordinates of the pins at ``pl.u`` with their pin-axis ends at ``x3 = +-u3`` (n,) m."""
        fam = self.family
        return fam.join(*([pl.u, u3] + ([np.zeros((fam.n, 2))] if fam.ndof == 5 else [])))

    def _turn_with_sheave(self, q_chain, v_chain, pins, w, centre):
        """Set the velocities of ``pins`` to those of a rigid turn at ``w`` (rad/s) about ``centre`` (2,) m."""
        vu = self.pin_positions(v_chain)
        vu[pins] = w * (self.pin_positions(q_chain)[pins] - centre) @ np.array([[0.0, 1.0], [-1.0, 0.0]])

    def wedge_guess(self, ratio: float, F2: float):
        """The start of the quasi-static solve at ``ratio`` and driven clamping force ``F2`` (N): placement
        (:func:`~cvtfem.elements.chain.placement.place_on_path`), the pin-end axial coordinates (n,) m of the
        wedge estimate (tension ``T = F2 tan(g2) / theta2*``, per-pin axial forces ``T L / (2 r tan g)``, pin
        compression) and the sheave positions ``z`` (2,) m with the Hertz penetration of those forces."""
        fam, faces = self.family, self.contact.faces
        pl = self._placement(ratio)
        if not (pl.r.max() < self.contact.r_outer and pl.r.min() > fam.geom.L.max()):
            raise InputError("ratio", ratio, f"must put both arcs between one pitch and the sheaves' outer radius "
                             f"{self.contact.r_outer:g} m (radii {pl.r[0]:.4g}, {pl.r[1]:.4g} m)")
        l = fam.geom.l
        tg = np.array([faces[k].tan_gamma(pl.r[k]) for k in range(2)])
        T = F2 * tg[1] / (np.pi / 2 - pl.phi)
        Nk = T * fam.geom.L.mean() / (2 * pl.r * tg)
        dk = (Nk / self.contact.c) ** (2 / 3)
        u3 = np.full(fam.n, l / 2)
        for k in range(2):
            u3[pl.piece == k] -= Nk[k] / (2 * fam.geom.c_pin[pl.piece == k])
        u3k = l / 2 - Nk / (2 * fam.geom.c_pin.mean())
        return pl, u3, np.array([u3k[k] - faces[k].lever(pl.r[k]) - dk[k] + self._extra_approach(k, pl.r[k])
                                 for k in range(2)])

    def _placement(self, ratio: float):
        """The pins on the band path of ``ratio`` with unstretched links (the hook a chain whose pitch changes with
        the joint angles overrides)."""
        return place_on_path(self.family.geom.L, ratio, self.contact.centres[0, 0])

    def _extra_approach(self, k: int, r: float) -> float:
        """Penetration of the contact beyond H1's for a pin end at radius ``r`` (m) on shaft ``k`` (0 for H1)."""
        return 0.0

    # ----- initial state -----------------------------------------------------------------------
    def static_state(self, ratio: float, w1: float, tension: float | None = None, tol: float = 1e-10):
        """Pins on the sheaves at ``ratio`` in quasi-static balance, and the running state around it.

        With ``tension`` (N) the driven clamping force is not ``F_appl[1]`` but the one that gives that mean
        link tension (secant steps on the affine law ``T = m' v^2 + F2 tan(gamma2) / theta2*`` of the wedge,
        started from it, to 1e-6 relative; ``report["F2"]``).

        The pins are placed on the band path of the ratio with unstretched links
        (:func:`~cvtfem.elements.chain.placement.place_on_path`); the driving sheave ``z_1`` is held where
        its face meets the pin ends at ``r1`` with the wedge estimate of their Hertz penetration; the
        chain coordinates and ``z_2`` are solved (scipy ``least_squares``) for the balance of the chain's
        elastic forces, the Hertz forces, the clamping force ``F_appl[1]`` on the driven sheave and the
        centrifugal forces of steady running at the driving speed ``w1`` (rad/s; chain speed ``w1 r1``)
        on the arcs.  Friction is not loaded (no slip).  The driving clamping force that holds the
        ratio is the reaction on ``z_1``.

        Returns ``(x0, report)``: the state with the span pins moving along the path at ``w1 r1``, the
        shafts at ``w1 r1 / r_k``, the pins in contact turning with their sheave (no slip) and the loops
        at those speeds; ``report`` with ``residual`` (largest generalized force over ``F2``),
        ``max_penetration`` (m), ``F1``, ``F2`` (N), ``tension`` (mean elastic link tension, N), ``placement``.
        """
        if tension is None:
            return self._static(ratio, w1, float(self.F_appl[1]), tol)
        if not tension > 0:
            raise InputError("tension", tension, "must be positive")
        F2, T_c = None, None
        for _ in range(8):
            if F2 is None:                                    # the wedge estimate
                pl = place_on_path(self.family.geom.L, ratio, self.contact.centres[0, 0])
                geo = self.family.geom
                T_c = geo.m_eff.mean() / geo.L.mean() * (w1 * pl.r[0]) ** 2
                F2 = (tension - T_c) * (np.pi / 2 - pl.phi) / self.contact.faces[1].tan_gamma(pl.r[1])
            else:                                             # secant through the centrifugal offset
                F2 *= (tension - T_c) / (rep["tension"] - T_c)
            if not F2 > 0:
                raise InputError("tension", tension, f"must exceed the centrifugal tension {T_c:.4g} N")
            x0, rep = self._static(ratio, w1, float(F2), tol)
            if abs(rep["tension"] / tension - 1) < 1e-6:
                return x0, rep
        raise NumericalError(f"the pretension {tension} N was not reached (last {rep['tension']:.6g} N at F2 = "
                             f"{F2:.6g} N)", component="ChainCVT.static_state")

    def _static(self, ratio: float, w1: float, F2: float, tol: float):
        """:meth:`static_state` at the driven clamping force ``F2`` (N)."""
        fam, nc = self.family, self._idx[0]
        _, iphi, iz, _ = self._idx
        pl, u3, z = self.wedge_guess(ratio, F2)
        speed = w1 * pl.r[0]
        n2 = self.n2
        q = np.zeros(n2)
        q[:nc] = self._placed(pl, u3)
        q[iz] = z
        vel = np.zeros(n2)
        a = np.zeros(nc)
        au = self.pin_positions(a)
        for k in range(2):
            sel = pl.piece == k
            au[sel] = -speed ** 2 / pl.r[k] * (pl.u[sel] - self.contact.centres[k]) / pl.r[k]
        Q_cf = -(fam.mass_matrix() @ a)                        # d'Alembert forces of steady running
        free = np.concatenate([np.arange(nc), iz[1:]])
        F_stat = np.array([0.0, F2])

        def forces(y):
            qq = q.copy()
            qq[free] = y
            Q, _ = self._forces(qq, vel, F_stat, np.zeros(2))
            Q[:nc] += Q_cf
            return Q

        def residual(y):
            return forces(y)[free] / F2

        def jacobian(y):
            qq = q.copy()
            qq[free] = y
            Kc = fam.jacobian(qq[:nc], vel[:nc], wrt=(0,))[0].tocoo()
            _, shafts, cols, coef, X, _ = self._contact_set(qq, vel)
            r, c, d = self._contact_entries(cols, coef, self.contact.local_jacobian(X, shafts),
                                            n_in=(cols.shape[1] - 1) // 2)            # the position inputs
            rows, cols = np.concatenate([Kc.row, r]), np.concatenate([Kc.col, c])
            K = sp.csr_matrix((np.concatenate([Kc.data, d]), (rows, cols)), shape=(n2, n2))
            return (K[free][:, free] / F2).toarray()
        sol = self._solve_balance(residual, jacobian, q[free], tol)
        q[free] = sol.x
        Q = forces(sol.x)
        pins, shafts, _, (_, c) = self._contacts(q, vel, details=True)
        F1 = float(Q[iz[0]] / self.sheaves_per_z)                             # reaction that holds z_1 (Q excludes F1)
        res = float(np.abs(Q[free]).max() / F2)
        if not res <= self.static_residual_limit:
            raise NumericalError(f"the quasi-static solve at ratio {ratio} ended with a residual of {res:.3g} of the "
                                 f"clamping force after {sol.nfev} evaluations ({sol.message})",
                                 component="ChainCVT.static_state")
        v = np.zeros(n2)
        self.pin_positions(v[:nc])[:] = speed * pl.tangent
        v[iphi] = speed / pl.r
        pins = self.pin_of(pins)
        for k in (0, 1):                                        # pins in contact turn with their sheave
            on = np.unique(pins[(shafts == k) & (c["delta"] > 0)])
            self._turn_with_sheave(q[:nc], v[:nc], on, v[iphi[k]], self.contact.centres[k])
        x0 = np.concatenate([q, v, self.control.initial_state(*v[iphi]), np.zeros(4)])
        report = {"residual": res, "max_penetration": float(c["delta"].max()), "F1": F1, "F2": F2,
                  "tension": float(self._elastic_link_tension(q[:nc]).mean()), "placement": pl,
                  "nfev": sol.nfev, "status": sol.status}
        return x0, report

    def _solve_balance(self, residual, jacobian, y0, tol: float):
        """Least squares of the quasi-static balance (scipy Levenberg-Marquardt, dense Jacobian); the result's
        ``x``, ``nfev``, ``status``, ``message``."""
        return least_squares(residual, y0, jac=jacobian, method="lm", xtol=tol, ftol=tol, gtol=tol, x_scale=1e-5,
                             max_nfev=200)

    def initial_state(self) -> np.ndarray:
        """The quasi-static state (:meth:`static_state`) at the regime's ratio and driving speed at ``t = 0``."""
        return self.start()[0]

    def start(self) -> tuple[np.ndarray, dict[str, Any]]:
        """``(x0, report)`` of :meth:`initial_state`; ``report["kind"]`` says how the run starts (the run
        driver's interface)."""
        w1, _, i = self.regime.targets(0.0)
        x0, rep = self.static_state(i, w1)
        return x0, {"kind": f"quasi-static on the sheaves (residual {rep['residual']:.1e} of F2, largest "
                            f"penetration {1e6 * rep['max_penetration']:.1f} um)"}

    def with_clamping(self, F_appl) -> "ChainCVT":
        """The same model with other prescribed clamping forces (N per sheave)."""
        return replace(self, F_appl=np.asarray(F_appl, float))

    # ----- construction ------------------------------------------------------------------------
    @classmethod
    def from_parameters(cls, geom, *, model: str = "chain-S2", centre_distance: float, face: Sheave,
                        r_outer: float, J, m_sheave, f0: float, v0: float, law: str = "linear-saturated",
                        regime: Regime, F_appl, control: StabilisationParams | None = None,
                        damping_ratio: float = 0.05, b_joint: float = 0.0, face_radius: float = 0.02,
                        face_inclination: float = 0.0, E: float = 2.1e11, poisson: float = 0.3, r_hertz: float | None = None,
                        contact: str = "hertz") -> "ChainCVT":
        """Build the model from plain parameters (SI units).

        ``geom`` a :class:`~cvtfem.elements.chain.geometry.ChainGeometry`; ``model`` ``chain-S1``, ``chain-S2``
        or ``chain-S3``; ``face`` the sheave face (its ``w`` is replaced by half the pin length); ``J``,
        ``m_sheave`` per shaft (driving, driven); ``F_appl`` clamping forces per sheave; ``control``
        the loop parameters (None: open loop, ``M2 = -b20 w2``); ``contact`` ``"hertz"`` (H1), ``"hertz-refined"``
        (H2, :class:`~cvtfem.machines.chain_cvt_refined.RefinedChainCVT`) or, for S1 and only for it, ``"rigid"``
        (:class:`~cvtfem.machines.chain_s1_cvt.ChainS1CVT`).  The Hertz stiffness is held
        constant (digest §4.3) for a pin end crowned with ``face_radius`` (m), inclined by ``face_inclination``
        (rad, H2 only) at the contact radius ``r_hertz`` (default: the mean radius of ratio 1, ``(l - 2 L) / (2 pi)``).
        """
        family = cls._family_for(model, geom, damping_from_ratio(geom, damping_ratio, b_joint), E)
        face = Sheave(face.profile, face.gamma, face.R, face.y, geom.l / 2)
        r_h = (geom.length - 2 * centre_distance) / (2 * np.pi) if r_hertz is None else r_hertz
        c = hertz_constant(face, r_h, face_radius, E, poisson, face_inclination)
        centres = np.array([[centre_distance, 0.0], [0.0, 0.0]])
        if (contact == "rigid") != (model == "chain-S1"):
            raise InputError("cvt.effects.contact", contact, "must be 'rigid' for chain-S1 (its pins have no axial "
                             "coordinate: the ends follow the faces) and 'hertz' or 'hertz-refined' for the others")
        if contact == "rigid" and cls is ChainCVT:
            from cvtfem.elements.chain.sheave_contact_rigid import RigidSheaveContact
            from cvtfem.machines.chain_s1_cvt import ChainS1CVT
            cls, pair = ChainS1CVT, RigidSheaveContact(centres, (face, face), np.array([np.inf, np.inf]), r_outer, f0,
                                                       v0, law, half_length=geom.l / 2)
        elif contact == "hertz-refined" and cls is ChainCVT:
            from cvtfem.machines.chain_cvt_refined import RefinedChainCVT, refined_contact
            cls, pair = RefinedChainCVT, refined_contact(family, centres, face, c, r_outer, f0, v0, law, face_radius,
                                                           face_inclination)
        elif contact == "hertz":
            pair = cls._contact_for(SheaveContact(centres, (face, face), np.array([c, c]), r_outer, f0, v0, law))
        else:
            raise InputError("cvt.effects.contact", contact, "must be 'hertz' (or 'hertz-refined' for chain-S2 and "
                             "chain-S3) for a running chain")
        loop = OpenLoop() if control is None else Stabilisation(control)
        m_z = np.asarray(m_sheave, float) * cls.sheaves_per_z / 2      # mass moved by one z coordinate
        return cls(family, pair, np.asarray(J, float), m_z, regime, np.asarray(F_appl, float), loop)._settled()

    @classmethod
    def _family_for(cls, model: str, geom, damping, E: float):
        """The chain family of ``model`` (InputError naming ``cvt.model`` for another)."""
        if model not in FAMILIES:
            raise InputError("cvt.model", model, "must be one of " + ", ".join(FAMILIES))
        return FAMILIES[model](geom, damping)

    @classmethod
    def _contact_for(cls, contact: SheaveContact):
        """The contact kernel of this model's pin ends (the mirrored pair: as is)."""
        return contact

    def _settled(self) -> "ChainCVT":
        """The model with the parameters that depend on the built model (none here)."""
        return self


def from_scene(scene, geom, F_appl, model: str = "chain-S2", **overrides) -> ChainCVT:
    """:meth:`ChainCVT.from_parameters` with the values of a CVT scene's existing keys (geometry, shafts,
    friction, control, regime, ``chain.damping_ratio``) for the chain ``geom`` and clamping forces
    ``F_appl`` (N per sheave); ``overrides`` replace keyword arguments (e.g. ``law``)."""
    from cvtfem.elements.band.geometry import phi_for_ratio, radii

    cvt = scene.cvt
    g, rg, c = cvt.geometry, cvt.regime, cvt.control
    shafts = (cvt.driving, cvt.driven)
    r2 = radii(phi_for_ratio(rg.ratio, geom.length, g.centre_distance), geom.length, g.centre_distance)[0][1]
    J = tuple(s.inertia for s in shafts)
    loop = StabilisationParams(c.tau_omega, c.eps, c.i_min, c.i_max, c.k_sat, c.c_f0, c.c_f1, c.c_sat, c.tau, c.nu,
                               J[0] * rg.ratio ** 2 + J[1] + cvt.chain.mass * r2 ** 2,
                               integral_start(c.ratio_loop_start, c.start_force_ratio, F_appl, c.k_sat))
    kw = dict(model=model, centre_distance=g.centre_distance,
              face=Sheave(g.sheave_profile, g.flank_angle, g.torus_radius, g.torus_offset),
              r_outer=g.sheave_outer_radius, J=J, m_sheave=tuple(s.sheave_mass for s in shafts),
              f0=cvt.friction.f0, v0=cvt.friction.v0, law=cvt.friction.law,
              regime=Regime(rg.kind, rg.input_speed, rg.torque, rg.ratio, rg.end_value, rg.ramp_time),
              F_appl=F_appl, control=loop if cvt.effects.stabilisation else None,
              damping_ratio=cvt.chain.damping_ratio, E=cvt.young_modulus, face_radius=cvt.chain.face_radius,
              face_inclination=cvt.chain.face_inclination)
    kw.update(overrides)
    if kw["model"] in FAMILIES:
        return ChainCVT.from_parameters(geom, **kw)
    if kw["model"].startswith("chain-A5"):
        from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT   # independent pin halves
        return ChainHalvesCVT.from_parameters(geom, **kw)
    from cvtfem.machines.chain_a_cvt import ChainACVT   # the whole-pin chains build on this module
    return ChainACVT.from_parameters(geom, **kw)


def band_span_tensions(band, x) -> np.ndarray:
    """Tight and slack span tension (N) of a compressible band CVT (6+2n, :class:`~cvtfem.machines.band_cvt.BandCVT`)
    at state ``x``: the radial balance of a band element ``T = rho v^2 + 2 r N sin(gamma)`` (``N`` per sheave
    and unit length; no radial slip in steady running) at the arc ends, extrapolated to ``xi = +-1`` by a
    parabola through the three end Gauss nodes.  The band runs counter-clockwise: the tight span leaves
    the driven arc at ``xi = +1`` and enters the driving arc at ``xi = -1``."""
    from cvtfem.elements.band.geometry import radii
    from cvtfem.elements.band.params import gauss_nodes

    p = band.model.p
    q, v, _, _ = band.split(x)
    r = radii(q[0], p.length, p.L)[0]
    N = np.asarray(band.outputs(0.0, x)["band.normal_force"]).reshape(2, -1)
    sg = np.array([np.sin(p.sheaves[k].gamma_at(r[k])) for k in range(2)])
    T = p.rho * v[1] ** 2 + 2 * r[:, None] * N * sg[:, None]
    xi = gauss_nodes(N.shape[1])[0]
    end = lambda k, s: np.polyval(np.polyfit(xi[::s][:3], T[k][::s][:3], 2), -s)  # noqa: E731  s=1: xi=-1
    return np.array([0.5 * (end(0, 1) + end(1, -1)), 0.5 * (end(0, -1) + end(1, 1))])
