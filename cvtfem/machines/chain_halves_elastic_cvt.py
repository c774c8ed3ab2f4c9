"""Variants (e) and (zh) of the source's Table 1.1: the chain with independent pin halves (A5) on elastic shafts.

:class:`ElasticChainHalvesCVT` (variant (zh): H1, the Hertz contact at the point on the half's axis) and
:class:`ElasticChainHalvesRefinedCVT` (variant (e): the refined contact H2 at the half's own end) put the A5
transmission of :class:`~cvtfem.machines.chain_halves_cvt.ChainHalvesCVT` /
:class:`~cvtfem.machines.chain_halves_refined_cvt.ChainHalvesRefinedCVT` (four contact ends per pin, ``e = 4 p + 2 h
+ s``, each on the sheave on its side of each shaft) on the beam-FE shafts of
:class:`~cvtfem.machines.chain_cvt_elastic.ElasticChainACVT`: every half-end contact is evaluated in the frame of
its displaced, tilted sheave, ``X = o + (I - theta x)(x - o - a)`` (first order in the tilt), as variant (b)/(v)
do for A1/A2.

H2 (:meth:`ElasticChainHalvesRefinedCVT._refined_frame`): the half-end contact reads the half end ``x``, its link
chord ``c``, ``x3``, the end slope and ``z``; its kernel sees the three points ``x - c, x, x + c``
(:class:`~cvtfem.elements.chain.half_end_contact.HalfEndContact`).  Those are mapped exactly as A1's three pins
at the end's offset (:meth:`ElasticChainACVT._refined_frame`), so the half's map is A1's composed with two
constant linear maps (spread into the three points, gather back to end and chord): its derivative is exact,
the kernel's rates are ``dK/dP P'`` and its forces act back through ``dK/dP^T``, so the normal forces are the
gradient of the Hertz potential of the mapped positions and the friction power is the kernel's.  The chord, a
difference of two points at one ``x3``, is unchanged by the sheave's translation and tilt.

Start (:meth:`ElasticChainHalvesCVT.start`): the rigid A5 start (lifted Newton,
:func:`~cvtfem.machines.static_balance.lifted_newton`), then chain and structure together (lifted Newton too:
A5's static stiffness is indefinite and singular); where the rigid solve fails (it converges for the uniform and the
randomised reference chain since its rolling-tie continuation) the rigid placement on undeformed shafts, off balance,
and where the elastic solve ends above its limit the state it reached; the start's ``kind`` says which.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from functools import cached_property
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly import fixed_pattern as FP
from cvtfem.elements.chain import halves_kernel as HK
from cvtfem.elements.chain import mapped_contact_kernel as MCK
from cvtfem.elements.chain import mapped_half_end_slips as MHS
from cvtfem.elements.contact.friction import POTENTIAL_LAWS
from cvtfem.errors import NumericalError
from cvtfem.machines.chain_cvt_elastic import ElasticChainACVT, ElasticChainCVT
from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT, HalvesFamily
from cvtfem.machines.chain_halves_refined_cvt import ChainHalvesRefinedCVT
from cvtfem.machines.static_balance import lifted_newton


def _spread_matrix() -> np.ndarray:
    """``(15, 13)``: the half-end positions (end 2, chord 2, ``x3``, slope 2, sheave 6) to A1's frame inputs (rear
    ``x - c``, end ``x``, front ``x + c``, ``x3``, slope 2, sheave 6)."""
    A = np.zeros((15, 13))
    eye = np.eye(2)
    A[0:2, 0:2], A[0:2, 2:4] = eye, -eye
    A[2:4, 0:2] = eye
    A[4:6, 0:2], A[4:6, 2:4] = eye, eye
    A[6:, 4:] = np.eye(9)
    return A


def _gather_matrix() -> np.ndarray:
    """``(8, 10)``: A1's mapped kernel inputs (three points, ``x3``, slope 2, ``z``) back to the half end, its chord
    (half the front point less the rear one), ``x3``, slope 2, ``z``."""
    B = np.zeros((8, 10))
    B[0:2, 2:4] = np.eye(2)
    B[2:4, 4:6], B[2:4, 0:2] = 0.5 * np.eye(2), -0.5 * np.eye(2)
    B[4:, 6:] = np.eye(4)
    return B


SPREAD, GATHER = _spread_matrix(), _gather_matrix()
#: ElasticChainCVT's steps the one-pass :meth:`ElasticChainHalvesCVT.rhs` stands for (a subclass that changes one of
#: them keeps the general path).
_ELASTIC_STEPS = ("evaluate", "_forces", "_mapped_forces", "_add_structure_loads", "solve_mass", "_controls",
                  "split", "_idx")

#: Arm (m) at which the elastic start measures the structure's tilts (about the contact radii).
TILT_ARM = 0.05


@dataclass(frozen=True, eq=False)
class ElasticChainHalvesCVT(ElasticChainACVT, ChainHalvesCVT):
    """Variant (zh): the A5 chain with H1 at its half ends on elastic shafts (:class:`ElasticChainACVT`'s structure,
    sheave frames and start under :class:`ChainHalvesCVT`'s halves)."""

    #: The same transmission on the rigid shafts of model 1.
    rigid_class: ClassVar[type] = ChainHalvesCVT
    #: The elastic start's lifted Newton may end above ``static_residual_limit`` (the span halves' axial positions
    #: and the driven shaft's end tilts; docs/transmission.md): the run starts from the state it reached and says so.
    keeps_unbalanced_start: ClassVar[bool] = True

    @cached_property
    def _pair_map_table(self) -> tuple:
        """``(ends, shafts, sheaves, cols, coef)`` of the mapped contact of every ``(end, shaft)`` pair, row ``2 end +
        shaft`` (built once; the broad phase's candidates index it)."""
        return self._pairs_map(*self._all_pairs())

    def _mapped_pairs(self, q):
        ends, shafts = self._candidates(q)
        rows = 2 * ends + shafts
        return tuple(a[rows] for a in self._pair_map_table)

    # ----- one-pass right-hand side ---------------------------------------------------------------
    @cached_property
    def _elastic_one_pass(self) -> bool:
        """Whether :meth:`rhs` takes its one-pass form: the compiled chain pass of :class:`HalvesFamily` and
        ElasticChainCVT's own force, mass and evaluate steps."""
        cls = type(self)
        return (self.family.chain.backend == "numba" and type(self.family).forces is HalvesFamily.forces
                and all(getattr(cls, f) is getattr(ElasticChainCVT, f) for f in _ELASTIC_STEPS))

    def rhs(self, t: float, x):
        """``dx/dt`` in one pass: :meth:`evaluate` without its bookkeeping (the chain's compiled pass writes its
        forces and dissipated power straight into the model's force vector); equal to ``evaluate(t, x)[0]`` to
        round-off (``tests/machines/test_chain_halves_elastic.py``)."""
        if not self._elastic_one_pass:
            return super().rhs(t, x)
        n2, nz = self.n2, self.control.size
        nc, iphi, iz, _ = self._idx
        q, v = x[:n2], x[n2:2 * n2]
        w = v[iphi]
        F, M, dz, _ = self._controls(t, w, x[2 * n2:2 * n2 + nz])
        Q = np.zeros(n2)
        D = HK.add_forces_power(Q, x, v, *self.family.chain._kernel_args)
        Pf = self._mapped_forces(q, v, Q)[0]
        self._add_structure_loads(q, v, F, M, Q)
        vs, sF = v[nc:], self._sides[:, 1] * F
        out = np.empty(self.size)
        out[:n2] = v
        FP.csr_matvec_into(out, n2, *self._chain_inverse_mass, Q)
        out[n2 + nc:2 * n2] = self._structure_inverse @ Q[nc:]
        out[2 * n2:2 * n2 + nz] = dz
        out[2 * n2 + nz:] = (M[0] * w[0], -M[1] * w[1], D - Pf + float(vs @ (self.structure.C @ vs)),
                             -float(sF @ (v[iz] - v[self._movable_node_u3])))
        return out

    def rigid(self) -> ChainHalvesCVT:
        cls = self.rigid_class
        return cls(**{f.name: getattr(self, f.name) for f in fields(cls)})

    # ----- start -------------------------------------------------------------------------------------
    def _rigid_static_state(self, ratio: float, w1: float, tension: float | None = None, tol: float = 1e-10):
        """The rigid A5 start, or where its solve fails, the rigid placement (:meth:`ChainHalvesCVT.placed_state`)
        with ``report["placed"]`` the failure."""
        try:
            return super()._rigid_static_state(ratio, w1, tension, tol)
        except NumericalError as err:
            if tension is not None:
                raise
            return self.rigid().placed_state(ratio, w1), {"placed": str(err)}

    def _solve_elastic_balance(self, residual, jacobian, y0, tol: float):
        """:func:`~cvtfem.machines.static_balance.lifted_newton` with the rigid A5 start's settings (its lifted phase
        alone, the finer lifts and steps: the span halves' axial positions have no stiffness of their own, and the
        rolling halves make the static stiffness indefinite; with the default damped phase the solve from the
        tie-continued rigid balance stalled at 2.4e-2 of F2 for (zh), with these 3.6e-5) on the structure's tilts as
        arc lengths at :data:`TILT_ARM` (rotations and moments in the units of the rest: the lift compares diagonal
        stiffnesses, which would lift the tilts in rad as if they had none)."""
        nc, s = self._idx[0], self.structure
        held = np.concatenate([nc + np.flatnonzero(s.dof_kind == 5), self._idx[2][:1]])
        free = np.setdiff1d(np.arange(self.n2), held)                  # the unknowns of _elastic_static
        tilts = nc + np.flatnonzero(np.isin(s.dof_kind, (3, 4)))
        scale = np.where(np.isin(free, tilts), 1.0 / TILT_ARM, 1.0)
        D = sp.diags(scale)
        sol = lifted_newton(lambda z: scale * residual(scale * z), lambda z: D @ jacobian(scale * z) @ D,
                            np.asarray(y0) / scale, tol, damped=0, lifts=self.LIFTS, steps=self.STEPS)
        sol.x = scale * sol.x
        return sol

    def _elastic_static(self, x0r, rep, w1, tol):
        """:meth:`ElasticChainACVT._elastic_static` from a converged rigid start; from the rigid placement
        (``report["placed"]``) the chain as placed on the undeformed shafts (:meth:`_on_structure`), no solve."""
        if "placed" not in rep:
            return super()._elastic_static(x0r, rep, w1, tol)
        return self._on_structure(x0r), dict(rep, residual=np.nan, F1=float(self.F_appl[0]), model=self)

    def _on_structure(self, x0r) -> np.ndarray:
        """The rigid model's state ``x0r`` on the undeformed shafts: chain and loops as there, every node spinning at
        its shaft's speed, the faces at this model's references."""
        nc, n2, s = self._idx[0], self.n2, self.structure
        rig = self.rigid()
        q, v = np.zeros(n2), np.zeros(n2)
        q[:nc], v[:nc] = x0r[:nc], x0r[rig.n2:rig.n2 + nc]
        w = x0r[rig.n2 + rig._idx[1]]
        for kk in range(2):
            v[nc + s.offset[kk]:nc + s.offset[kk] + 6 * len(s.x[kk])][5::6] = w[kk]
        return np.concatenate([q, v, self.control.initial_state(*w), np.zeros(4)])

    def placed(self, ratio: float, w1: float) -> tuple["ElasticChainHalvesCVT", np.ndarray]:
        """``(model, x0)``: the rigid placement (:meth:`ChainHalvesCVT.placed_state`) at ``ratio`` and driving speed
        ``w1`` (rad/s) on the undeformed shafts, and this model with the faces' references there (off balance)."""
        x0r = self.rigid().placed_state(ratio, w1)
        model = replace(self, z_ref=self._face_reference(x0r), rigid_start=(ratio, w1, x0r, {"placed": "placed"}))
        return model, model._on_structure(x0r)

    def placed_state(self, ratio: float, w1: float) -> np.ndarray:
        """The state of :meth:`placed`; the model's face references must be the placement's (NumericalError)."""
        model, x0 = self.placed(ratio, w1)
        if not np.array_equal(model.z_ref, self.face_ref):
            raise NumericalError("the model's face reference positions z_ref are not those of the placement: use "
                                 "the model of placed()", component="ElasticChainHalvesCVT.placed_state")
        return x0

    def start(self):
        """``(x0, report)``: the quasi-static start on elastic shafts (:meth:`static_state`; where its solve ends above
        ``static_residual_limit``, the state it reached), or the placement (off balance) where the rigid A5 start
        fails; ``kind`` says which, with the residuals or the failure."""
        w1, _, i = self.regime.targets(0.0)
        x0, rep = self.static_state(i, w1)
        if not np.array_equal(rep["model"].z_ref, self.face_ref):
            raise NumericalError("the model's face reference positions z_ref are not those of its start: leave them "
                                 "None (the rigid start's)", component="ElasticChainHalvesCVT.start")
        if "placed" in rep:
            return x0, {"kind": f"placed on the sheaves on undeformed elastic shafts, off balance (rigid start: "
                                f"{rep['placed']})", "model": rep["model"]}
        what = "quasi-static" if rep["unbalanced"] is None else "off balance, the quasi-static solve not converged:"
        return x0, {"kind": f"{what} on elastic shafts (residual {rep['residual']:.1e} of F2 after "
                            f"{rep['nfev_elastic']} evaluations; rigid A5 start {rep['rigid_residual']:.1e}), largest "
                            f"penetration {1e6 * rep['max_penetration']:.1f} um", "model": rep["model"]}

    def static_state(self, ratio: float, w1: float, tension: float | None = None, tol: float = 1e-10):
        """:meth:`ElasticChainACVT.static_state` with ``report["rigid_residual"]``, the rigid A5 start's residual
        (NaN from the placement)."""
        x0, rep = super().static_state(ratio, w1, tension, tol)
        rigid = rep["model"].rigid_start[3]
        return x0, dict(rep, rigid_residual=rigid.get("residual", np.nan))


@dataclass(frozen=True, eq=False)
class ElasticChainHalvesRefinedCVT(ElasticChainHalvesCVT, ChainHalvesRefinedCVT):
    """Variant (e): the A5 chain with H2 at its half ends on elastic shafts; each half-end contact in the frame of
    its displaced, tilted sheave (:meth:`_refined_frame`)."""

    rigid_class: ClassVar[type] = ChainHalvesRefinedCVT
    #: The half-end contact's chain positions (end 2, chord 2, ``x3``, slope 2) and the end's ``X1, X2, X3``.
    refined_chain_inputs: ClassVar[int] = 7
    refined_end_slots: ClassVar[tuple] = (0, 1, 4)

    half_end_frame: ClassVar[bool] = True

    # ----- the friction split off (stiff, solved implicitly), on elastic shafts ---------------------------------------
    #: :attr:`ChainHalvesCVT.stiff_split` on elastic shafts: ``f_E`` the same model without the halves' internal
    #: friction (default) or without any friction (variant ``"all"``), each a frictionless twin of this model
    #: (:attr:`_frictionless`); ``f_I`` solved on the chain's velocities (halves) or on all velocities with the
    #: sheaves' structure coordinates as the border (``"all"``: :meth:`sheave_slips` through the sheave frames,
    #: :attr:`_masses` with the structure's consistent mass).
    _splits: ClassVar[bool] = True

    @cached_property
    def _frictionless(self) -> dict:
        """This model without the halves' internal friction (``"halves"``) and without any friction (``"all"``)."""
        fam, h2 = self.family, self.contact.pair.pair
        halves = replace(self, family=HalvesFamily(fam.chain.without_friction(), fam.geom))
        contact = replace(self.contact, pair=replace(self.contact.pair, pair=replace(h2, f0=0.0)))
        return {"halves": halves, "all": replace(halves, contact=contact)}

    def rhs_explicit(self, t: float, x):
        """:meth:`rhs` without the halves' internal friction: ``f_E`` of :attr:`stiff_split`."""
        return self._frictionless["halves"].rhs(t, x)

    def rhs_explicit_all(self, t: float, x):
        """:meth:`rhs` without any friction: ``f_E`` of the split's variant ``"all"``."""
        return self._frictionless["all"].rhs(t, x)

    @cached_property
    def _sheave_friction(self) -> tuple | None:
        """``(compiled mapped-contact constants, pin-sheave law (f0, v0, name))`` where the pin-sheave friction can
        join ``f_I`` (the compiled H2 half-end contact, a law with a potential, ``f0 > 0``), else None."""
        ck, h2 = self._compiled_mapped, self.contact.pair.pair
        if ck is None or ck[4] != MCK.REFINED_HALF_END or h2.law not in POTENTIAL_LAWS or h2.f0 == 0.0:
            return None
        return ck, (float(h2.f0), float(h2.v0), h2.law)

    def sheave_slips(self, x) -> tuple[sp.csr_matrix, np.ndarray]:
        """``(G, N)`` of :meth:`ChainHalvesCVT.sheave_slips` for the contacts in their sheaves' frames: ``G``'s
        columns reach the sheaves' translation, tilt and spin rates (:func:`~cvtfem.elements.chain.
        mapped_half_end_slips.slip_map`)."""
        n2, table, ck = self.n2, self._mapped_table, self._sheave_friction[0]
        cols = table[0]
        P, size = cols.shape[0], 2 * cols.shape[0] * cols.shape[1] * cols.shape[2]
        N, ptr, ind, d = np.empty(P), np.empty(2 * P + 1, np.int32), np.empty(size, np.int32), np.empty(size)
        m, k, bad = MHS.slip_map(np.ascontiguousarray(x[:2 * n2]), *table[:4], *ck[:4], *ck[5:11], n2, N, ptr, ind, d)
        self._raise_on_axis(bad)
        return sp.csr_matrix((d[:k], ind[:k], ptr[:2 * m + 1]), shape=(2 * m, n2)), N[:m]

    @cached_property
    def _masses(self) -> tuple:
        """``(M, M^-1, border)``: the mass matrix of all velocities (chain, structure), its inverse and the border:
        the structure coordinates the sheaves' frames read (their translation, tilt, axial position and spin)."""
        ch, s = self.family.chain, self.structure
        M = sp.block_diag([ch.mass_matrix, s.M], format="csr")
        Mi = sp.block_diag([ch.inverse_mass, sp.csr_matrix(self._structure_inverse)], format="csr")
        return M, Mi, self._idx[0] + np.unique(s.sheave_dofs)

    def _refined_frame(self, P, k, j):
        """``(K, dK/dP)``: the half-end contact's inputs (m, 8: end, chord, ``x3``, slope, ``z_ref``) in the frame of
        the displaced, tilted sheave ``j`` of shaft ``k`` and their exact derivative (m, 8, 13) in ``P`` (m, 13: the
        seven chain positions, mirrored, then the sheave's translation, tilt and the other sheave's axial position):
        A1's map (:meth:`ElasticChainACVT._refined_frame`) of the points ``x - c, x, x + c``, gathered back."""
        K, dK = super()._refined_frame(P @ SPREAD.T, k, j)
        return K @ GATHER.T, GATHER @ dK @ SPREAD


def elastic_halves(rigid: ChainHalvesCVT, structure) -> ElasticChainHalvesCVT:
    """The rigid A5 transmission ``rigid`` (H1: variant (zh); H2: (e)) on ``structure``
    (:class:`~cvtfem.machines.shaft_structure.ShaftStructure`; ``z_ref`` set by the start)."""
    cls = ElasticChainHalvesRefinedCVT if isinstance(rigid, ChainHalvesRefinedCVT) else ElasticChainHalvesCVT
    values = {f.name: getattr(rigid, f.name) for f in fields(rigid)}
    return cls(**values, structure=structure, z_ref=np.zeros((2, 2)))
