"""The chain with independent pin halves (A5) on two rigid shafts: :class:`ChainHalvesCVT`, variants (e) and (zh)
of the source's Table 1.1 with rigid shafts instead of elastic ones (issue 13).

Each half of every pin carries A1's ten coordinates (chain-models-2 §5.1), so each half has two ends,
``u_0 -+ u_1`` in-plane and ``w_0 -+ w_1`` axially, linear in its coordinates; every half end touches the
sheave on its side of each shaft with H1 (Hertz at the point on the half's axis, :class:`EndContact`; the
contact of variant (zh)), as the whole-pin ends of :class:`~cvtfem.machines.chain_a_cvt.ChainACVT` do: four
contact ends per pin, end ``e = 4 p + 2 h + s`` (half ``h`` 0 = ``p-``, 1 = ``p+``; side ``s`` 0 = ``x3 < 0``,
1 = ``x3 > 0``).  The sheaves, clamping, loops and work integrals are ChainACVT's (a fixed and a movable sheave
per shaft).  :class:`HalvesFamily` wraps :class:`~cvtfem.elements.chain.halves.ChainA5` in the chain-family
interface ChainCVT drives; the internal friction of the chain (axial (1.221) and rolling) counts in the
dissipated work with the Rayleigh damping.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, replace
from functools import cached_property, lru_cache
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly import fixed_pattern as FP
from cvtfem.elements.base import Block
from cvtfem.elements.chain import half_end_contact_kernel as HEK
from cvtfem.elements.chain import half_end_slips as HES
from cvtfem.elements.chain import halves_kernel as HK
from cvtfem.elements.chain import sheave_contact_kernel as SK
from cvtfem.elements.chain.halves import ChainA5
from cvtfem.elements.chain.halves_placement import half_centres, rolling_link_directions, rolling_spacing
from cvtfem.elements.chain.implicit_friction import FrictionRate, FrictionSet, friction_step
from cvtfem.elements.chain.placement import Placement, place_on_path
from cvtfem.elements.contact.friction import POTENTIAL_LAWS
from cvtfem.errors import InputError, NumericalError
from cvtfem.machines.chain_a_cvt import PLATE_HEIGHT, PLATE_THICKNESS, POISSON, ChainACVT
from cvtfem.machines.chain_cvt import ChainCVT
from cvtfem.machines.static_balance import lifted_newton
from cvtfem.outputs import OutputSpec

#: Assumed half-pin and contact parameters (no source values; docs/chain.md "Parameters assumed"): half offset
#: ``h_pin`` (m), rolling radii (m), rolling and hole penalties (N/m^2), hole contour, back face, its extent and
#: the clearance (m), stopper stiffness (N/m) and play (m), turn of the section axes ``gamma_0`` (rad); the chain's
#: internal friction (axial (1.221), rolling): ``f_0`` 0.1 (the source's estimate, §1.5.1.2), ``v_0`` (m/s) and law.
HALF_PARAMETERS = dict(h_pin=1.2e-3, roll_radius=(0.004, 0.004), roll_stiffness=1e11, hole_radius=0.0031,
                       back_radius=0.0024, back_extent=0.0025, hole_clearance=5e-4, hole_stiffness=1e11,
                       stopper_stiffness=1e6, stopper_play=5e-4, gamma0=np.radians(5.0),
                       friction_coefficient=0.1, friction_speed=0.01, friction_law="tanh")
#: The chains with independent halves that run on the sheaves (both with H1: the contact point on the half's axis).
HALVES_MODELS = ("chain-A5", "chain-A5-point")
_ROT = np.array([[0.0, 1.0], [-1.0, 0.0]])      # a @ _ROT = k x a
#: ChainCVT's steps the one-pass ``rhs`` and ``jac`` of :class:`ChainHalvesCVT` stand in for: a subclass that overrides
#: one of them keeps the general path.
_GENERAL_STEPS = ("evaluate", "_forces", "solve_mass", "split", "layout", "_idx", "_controls", "_loop_gradient",
                  "jac_sparsity")


def halves_family(geom, damping, E: float, plate_model: str = "A4", use_numba: bool = True, **half_parameters) -> "HalvesFamily":
    """A5 of a :class:`~cvtfem.elements.chain.geometry.ChainGeometry` with ``damping``
    (:class:`~cvtfem.elements.chain.symmetric.ChainDamping`).

    The geometry's pitch ``L`` is the pin pitch; the plates hang on the halves ``2 h_pin`` further apart.  Plates
    ``PLATE_HEIGHT`` x ``PLATE_THICKNESS`` of Young's modulus ``E`` (Pa) as A1's; each half has half the pin's axial
    and bending stiffnesses (§5.3: pair = 2 halves).  Damping times as A1's (the link time for plate extension,
    shear and twist; ``beta_pin`` for the half axial damping ``b = beta c_p/2``), the rolling contact's normal
    damping ``beta_link k_n``.  ``half_parameters`` override :data:`HALF_PARAMETERS`.
    """
    unknown = set(half_parameters) - set(HALF_PARAMETERS)
    if unknown:
        raise InputError("half_parameters", sorted(unknown), "must be among " + ", ".join(HALF_PARAMETERS))
    hp = dict(HALF_PARAMETERS, **half_parameters)
    mask = np.asarray(geom.plate_mask)
    order = np.argsort(~mask, axis=1, kind="stable")                 # the existing plates first in every link
    take = lambda a: np.take_along_axis(np.asarray(a, float), order, 1)  # noqa: E731
    b, h = PLATE_HEIGHT, PLATE_THICKNESS
    G = E / (2 * (1 + POISSON))
    c_pin = np.asarray(geom.c_pin, float)
    if np.ptp(c_pin) > 1e-12 * c_pin.max():
        raise InputError("ChainGeometry.c_pin", (c_pin.min(), c_pin.max()), "must be equal for all pins (A5)")
    chain = ChainA5(pitch=geom.L + 2 * hp["h_pin"], plate_offset=geom.l / 2 * take(geom.xi),
                    n_plates=np.maximum(mask.sum(1), 1), plate_stiffness=take(geom.c_plate),
                    plate_bending_stiffness=E * b * h ** 3 / 12, plate_thickness=h,
                    plate_torsion_stiffness=(G * b * h ** 3 / 3) / (geom.L[:, None] + 2 * hp["h_pin"]),
                    plate_mass=np.asarray(geom.m_plate).sum(1), pin_length=geom.l, pin_mass=geom.m_pin,
                    pin_axial_stiffness=float(c_pin[0]), half_bending_tau=geom.A_tau / 2,
                    half_bending_n=geom.A_n / 2, roll_damping=damping.beta_link * hp["roll_stiffness"],
                    plate_model=plate_model,
                    half_axial_damping=damping.beta_pin * float(c_pin[0]) / 2, beta_plate_ext=damping.beta_link,
                    beta_plate_shear=damping.beta_link, beta_twist=damping.beta_link, beta_bend=damping.beta_bend,
                    joint_damping=damping.b_joint, closed=geom.closed, use_numba=use_numba, **hp)
    return HalvesFamily(chain, geom)


class HalvesFamily:
    """:class:`ChainA5` with the interface of the chain families :class:`~cvtfem.machines.chain_cvt.ChainCVT`
    drives (``forces``, ``solve_mass``, ``jacobian``, ``rayleigh``, ...).

    ``rayleigh`` and ``dissipative_forces`` describe the chain's whole dissipated power ``D = 2 Phi - P_fr``
    (Rayleigh damping and internal friction, ``P_fr <= 0``): ``rayleigh = D / 2``, ``dissipative_forces =
    -dD/dv / 2``, which is what ChainCVT's work integral and its Jacobian row read."""

    name = "chain"
    #: No homogenised A1 pre-solve of the start (ChainACVT's for A3/A4): the halves' start is their own.
    homogenised = None
    #: How the compiled Jacobian takes the links' blocks (:meth:`ChainA5.jacobian`'s ``scheme``); the quasi-static
    #: start switches to "central" (:meth:`ChainHalvesCVT._solve_balance`).
    scheme = "analytic"

    def __init__(self, chain: ChainA5, geom):
        self.chain, self.geom = chain, geom
        self.n, self.size = chain.n_pins, chain.n2
        self.dof_index = chain.dof_index
        self.ip1 = (np.arange(self.n) + 1) % self.n
        self.on = geom.link_on
        self._last: tuple = (None, None, None)
        self._power: tuple = (None, 0.0)                # (state, dissipated power W) of the last force pass

    @property
    def blocks(self) -> tuple[Block, ...]:
        """Half ``-`` and half ``+`` in A1's layout, then the plate packs (§5.1)."""
        n = self.n
        one = lambda s: (Block(f"chain.{s}.u_perp0", 2 * n, "m"), Block(f"chain.{s}.u_perp1", 2 * n, "m"),  # noqa: E731
                         Block(f"chain.{s}.u_perp2", 2 * n, "-"), Block(f"chain.{s}.u_perp3", 2 * n, "-"),
                         Block(f"chain.{s}.u_par0", n, "m"), Block(f"chain.{s}.u_par1", n, "m"))
        return one("minus") + one("plus") + (Block("chain.pack", n, "m"),)

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        return tuple(self.chain.output_specs)

    @property
    def jac_sparsity(self) -> sp.csr_matrix:
        return self.chain.jac_sparsity

    def split(self, q):
        """``(u (2, 4, n, 2), w (2, 2, n), q_pack (n,))`` views (half -, half +)."""
        return self.chain.split(q)

    def join(self, u, w, qp):
        return self.chain.join(u, w, qp)

    def forces(self, q, v):
        """All forces of the chain (N, N m); their pass also gives the dissipated power :meth:`rayleigh` reads."""
        Q, D = self.chain.forces_and_dissipation(q, v)
        self._power = (q.tobytes() + v.tobytes(), D)
        return Q

    def _nonconservative(self, q, v):
        """Damping and friction forces: ``Q(q, v) - Q(q, 0)`` (both vanish at rest)."""
        return self.chain.forces(q, v) - self.chain.forces(q, np.zeros_like(v))

    def rayleigh(self, q, v) -> float:
        """Half the dissipated power ``D = -(Q_d + Q_fr) . v`` (W); ChainCVT asks for it right after :meth:`forces`
        at the same state, whose pass computed it."""
        if self._power[0] != q.tobytes() + v.tobytes():
            self.forces(q, v)
        return 0.5 * self._power[1]

    def dissipative_forces(self, q, v):
        """``-dD/dv / 2 = (Q_nc + (dQ/dv)^T v) / 2``, N (``Q_nc`` damping and friction forces)."""
        return 0.5 * (self._nonconservative(q, v) + self.jacobian(q, v, wrt=(1,))[0].T @ v)

    def energy(self, q, v) -> float:
        """Kinetic plus elastic energy of the chain, J."""
        return float(self.chain.kinetic_energy(v) + self.chain.potential_energy(q))

    def mass_matrix(self) -> sp.csr_matrix:
        return self.chain.mass_matrix

    def solve_mass(self, Q):
        """``M^-1 Q`` (constant block-diagonal inverse)."""
        return self.chain.inverse_mass @ Q

    def jacobian(self, q, v, part: str = "all", wrt: tuple = (0, 1)):
        """``(dQ/dq, dQ/dq')`` (CSR) of all forces, or with ``part="dissipative"`` of the damping and friction
        forces alone (their ``dQ/dq`` is the total's less the one at ``q' = 0``)."""
        dq, dv = self._blocks(q, v)[:2]
        if part == "dissipative":
            dq = dq - self.chain.jacobian(q, np.zeros_like(v), damping=False)[0]
        return tuple(dq if k == 0 else dv for k in wrt)

    def _blocks(self, q, v) -> tuple:
        """``(dQ/dq, dQ/dv, dD/dq, dD/dv)`` at ``(q, v)`` (the gradients None with the numpy backend), cached:
        ChainCVT.jac asks for the matrices and the gradient at one state."""
        key = np.concatenate([q, v]).tobytes() + self.scheme.encode()
        if self._last[0] != key:
            compiled = self.chain.backend == "numba"
            blocks = self.chain.jacobian_and_power_gradient(q, v, self.scheme) if compiled else (
                *self.chain.jacobian(q, v), None, None)
            self._last = (key, *blocks)
        return self._last[1:]

    def dissipation_gradient(self, q, v) -> tuple[np.ndarray, np.ndarray]:
        """``(dD/dq, dD/dv)`` (W/m, W s/m) of the dissipated power ``D = 2`` :meth:`rayleigh`: from the compiled
        Jacobian pass, or ``-(dQ_nc/dq)^T v`` and ``2`` :meth:`dissipative_forces` with the numpy backend."""
        dDq, dDv = self._blocks(q, v)[2:]
        if dDq is None:
            Kd = self.jacobian(q, v, part="dissipative", wrt=(0,))[0]
            return -(Kd.T @ v), -2 * self.dissipative_forces(q, v)
        return dDq, dDv

    def outputs(self, q, v):
        return self.chain.outputs(q, v)


@dataclass(frozen=True)
class RollingPlacement(Placement):
    """A :class:`~cvtfem.elements.chain.placement.Placement` of rolling points with the link directions ``tau``
    (n, 2) of the halves around them and the pressing ``delta`` (m) of their rolling faces."""

    tau: np.ndarray = None
    delta: float = 0.0


def _hashable(a):
    """A float, or an array as a tuple (an argument of the cached :func:`_rolling_placement`)."""
    a = np.asarray(a, float)
    return float(a) if a.ndim == 0 else tuple(a.tolist())


@lru_cache(maxsize=16)
def _rolling_placement(L, ratio: float, L_c: float, R, h, delta, stretch) -> RollingPlacement:
    """:meth:`ChainHalvesCVT._placement` at link lengths ``L`` (m), ``ratio``, centre distance ``L_c`` (m), roll
    radius ``R`` and pin height ``h`` (m), face pressing ``delta`` and link stretch ``stretch`` (m): fixed-point
    passes of the link directions (each shrinks the change a hundredfold) until the spacing changes by less than
    1e-11 m.  Pure geometry, cached: a model's construction (the fixed sheaves' wedge estimate) and its start ask for
    the same placement, about 1 s each."""
    L, R, h, delta, stretch = (np.asarray(a) if isinstance(a, tuple) else a for a in (L, R, h, delta, stretch))
    spacing = L + stretch
    for _ in range(12):
        pl = place_on_path(spacing, ratio, L_c)
        tau = rolling_link_directions(pl.u, R, h, delta)
        new = rolling_spacing(tau, L, R, delta, stretch)
        if np.abs(new - spacing).max() < 1e-11:
            return RollingPlacement(**vars(pl), tau=tau, delta=delta)
        spacing = new
    raise NumericalError(f"the rolling points did not settle on the path of ratio {ratio} (last change "
                         f"{np.abs(new - spacing).max():.3g} m)", component="ChainHalvesCVT placement")


class _HalfCentres:
    """The in-plane positions ``u_0`` of both halves of every pin as one array: reading gives their mean (the pin
    centre), writing sets both (the quasi-static start places and moves whole pins)."""

    def __init__(self, u):
        self.u = u

    def __getitem__(self, key):
        return (0.5 * (self.u[0, 0] + self.u[1, 0]))[key]

    def __setitem__(self, key, value):
        self.u[0, 0][key] = value
        self.u[1, 0][key] = value


class ChainHalvesCVT(ChainACVT):
    """The A5 chain (independent pin halves) on two rigid shafts, each with a fixed and a movable sheave; H1 contact
    at both ends of every half (:class:`ChainACVT`'s hooks for four ends per pin)."""

    #: The quasi-static start leaves about 1 N (2e-5 of F2) on the axial positions of the halves on the spans, which
    #: only the plates' station terms hold (no stiffness of their own: :func:`lifted_newton`); the sheaves' axial
    #: balances hold to 2e-5 there (docs/chain.md).
    static_residual_limit: ClassVar[float] = 1e-4
    #: The quasi-static start's continuation in the rolling tie ``k_t`` (N/m^2; :meth:`_static`), and the residual
    #: (of F2) to which each tied stage is solved (each converges quadratically to it in 2-6 Jacobians; below, the
    #: span halves' axial positions, which nothing stiffens, make it crawl).
    ROLL_TIES: ClassVar[tuple[float, ...]] = (1e10, 1e9, 1e8)
    TIED_RESIDUAL: ClassVar[float] = 1e-4
    #: Lift floors and step lengths of the solves (:func:`lifted_newton`): besides its defaults the floor 1e-3 and the
    #: steps 0.003, 0.001, without which the untied solve of variant (e) (H2) stopped at 2.7e-3 of F2.
    LIFTS: ClassVar[tuple[float, ...]] = (1e-9, 1e-7, 1e-5, 1e-4, 1e-3)
    STEPS: ClassVar[tuple[float, ...]] = (1.0, 0.5, 0.25, 0.1, 0.03, 0.01, 0.003, 0.001)
    #: Lifted Newton iterations per stage: the untied stage crawls (about 0.5 % of ``|r|`` per iteration) where the
    #: span halves' axial positions hold nothing; at ratio 0.45 (chapter 2) the uniform chain of variant (e) stopped at
    #: 7.4e-4 of F2 after the default 150 and converges to 3.7e-5 after 461 (docs/accuracy-cost.md, session 9).
    NEWTON_ITERATIONS: ClassVar[int] = 600
    #: The implicit friction solve of all friction (:meth:`friction_solve_all`) stops when a Newton step changes every
    #: slip by less than this fraction of its law's ``v0`` (the kinetic energy it removes is booked exactly whatever
    #: the tolerance).  On the short window (imex-rk4, 2e-6 s) 1e-6, 1e-4, 1e-2, 0.1, 1 gave 4.4, 3.7, 2.9, 2.3, 1.3 LUs
    #: per solve and E 2.770e-3 (the first three), 2.768e-3, 2.894e-3 (docs/accuracy-cost.md, session 12).  Since
    #: session 15 a small Newton step is checked by a chord step, whose end is only linearly converged: 0.03 keeps
    #: the slips closer to the exact root than 0.1 without the chord did (median 1.4e-4 against 6.6e-4 ``v0``, largest
    #: 3.5e-3 against 5.5e-3, over the first 30 solves on elastic (e)) with 17 % fewer LUs.
    FRICTION_TOL: ClassVar[float] = 0.03

    @property
    def n_ends(self) -> int:
        return 4 * self.family.n

    def pin_of(self, ends):
        return ends // 4

    def pin_positions(self, q_chain):
        return _HalfCentres(self.family.split(q_chain)[0])

    def _candidates(self, q):
        u = self.family.split(q[:self._idx[0]])[0]                      # (2, 4, n, 2)
        ends = np.stack([u[:, 0] - u[:, 1], u[:, 0] + u[:, 1]], axis=2)  # (2 halves, n, 2 sides, 2)
        return self.contact.candidates(ends.transpose(1, 0, 2, 3).reshape(-1, 2))

    def _end_dofs(self, ends):
        half = (ends // 2) % 2
        return self.family.dof_index[ends // 4][np.arange(len(ends))[:, None], 10 * half[:, None] + np.arange(10)]

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        specs = []
        for s in super().output_specs:
            if s.name.startswith("contact.") and s.size in (2 * self.n_ends, 6 * self.n_ends) and s.name not in (
                    "contact.sheave_axial_force", "contact.fixed_sheave_axial_force", "contact.friction_power"):
                s = OutputSpec(s.name, s.unit, s.doc.replace("per pin end", "per pin-half end (4 per pin: "
                                                                     "half -, half +; x3 < 0, x3 > 0)"), s.size)
            specs.append(s)
        return tuple(specs)

    # ----- one-pass right-hand side and Jacobian ---------------------------------------------------
    @cached_property
    def _one_pass(self) -> bool:
        """Whether :meth:`rhs` and :meth:`jac` take their one-pass forms: the compiled chain pass of
        :class:`HalvesFamily` and ChainCVT's own state layout, pattern, force, mass, loop and evaluate steps
        (:data:`_GENERAL_STEPS`; a subclass that changes one of them, as the elastic shafts do, keeps the general
        path)."""
        cls = type(self)
        return (self.family.chain.backend == "numba" and type(self.family).forces is HalvesFamily.forces
                and all(getattr(cls, f) is getattr(ChainCVT, f) for f in _GENERAL_STEPS))

    @cached_property
    def _chain_inverse_mass(self) -> tuple:
        """The CSR arrays ``(indptr, indices, data)`` of the chain's block-diagonal inverse mass (sorted)."""
        Mi = sp.csr_matrix(self.family.chain.inverse_mass)
        Mi.sort_indices()
        return Mi.indptr.astype(np.int64), Mi.indices.astype(np.int64), Mi.data.astype(float)

    def rhs(self, t: float, x):
        """``dx/dt`` in one pass: ChainCVT's :meth:`evaluate` without its bookkeeping (the chain's compiled pass
        writes its forces and dissipated power straight into the model's force vector, the mass solve is compiled);
        equal to ``evaluate(t, x)[0]`` to round-off (``tests/machines/test_chain_halves_one_pass.py``)."""
        if not self._one_pass:
            return super().rhs(t, x)
        return self._rhs_with(t, x, self.family.chain._kernel_args)

    def _rhs_with(self, t: float, x, chain_args: tuple, contact_args: tuple | None = None):
        """The one-pass :meth:`rhs` with the chain's compiled pass on the kernel constants ``chain_args`` (and the H2
        contacts' on ``contact_args`` where given, :mod:`~cvtfem.elements.chain.half_end_contact_kernel`)."""
        n2, nz = self.n2, self.control.size
        nc, iphi, iz, _ = self._idx
        v = x[n2:2 * n2]
        w = v[iphi]
        F, M, dz, _ = self._controls(t, w, x[2 * n2:2 * n2 + nz])
        Q = np.zeros(n2)
        D = HK.add_forces_power(Q, x, v, *chain_args)
        if contact_args is None:
            Pf = self._contact_forces(x[:n2], v, Q)[0]
        else:
            Pf = self._contact_forces_with(x, Q, contact_args)
        Q[iphi] += M
        Q[iz] -= self.sheaves_per_z * F
        out = np.empty(self.size)
        out[:n2] = v
        FP.csr_matvec_into(out, n2, *self._chain_inverse_mass, Q)
        out[n2 + iphi] = Q[iphi] / self.J
        out[n2 + iz] = Q[iz] / self.m_sheave
        out[2 * n2:2 * n2 + nz] = dz
        out[2 * n2 + nz:] = (M[0] * w[0], -M[1] * w[1], D - Pf, -self.sheaves_per_z * float(F @ v[iz]))
        return out

    # ----- the friction split off (stiff, solved implicitly) ------------------------------------------------------
    @cached_property
    def stiff_split(self) -> tuple | None:
        """``x' = f_E(x) + f_I(x)`` with ``f_I`` the halves' internal friction (axial (1.221) and rolling; velocity rows
        and the dissipated-work row only): ``(rhs_explicit, friction_solve, friction_hold, variants)``, the fields of
        :class:`cvtfem.integrate.system.StiffSplit`, with the variant ``"all"`` where the pin-sheave friction can join
        ``f_I`` (:attr:`_sheave_friction`): all friction implicit (:meth:`rhs_explicit_all`,
        :meth:`friction_solve_all`); None without friction in the halves or where :attr:`_splits` is False."""
        if not self._splits or self.family.chain.f0 == 0.0:
            return None
        variants = {"all": (self.rhs_explicit_all, self.friction_solve_all, self.friction_hold, None,
                            self.friction_rate)} if self._sheave_friction else {}
        return self.rhs_explicit, self.friction_solve, self.friction_hold, variants

    @property
    def _splits(self) -> bool:
        """Whether the split's parts exist here: on the one-pass path (not the numpy chain backend; the elastic shafts
        bring their own parts)."""
        return self._one_pass

    @cached_property
    def _frictionless_args(self) -> tuple:
        return self.family.chain.without_friction()._kernel_args

    def rhs_explicit(self, t: float, x):
        """:meth:`rhs` without the halves' internal friction (their ``f_0 = 0``): ``f_E`` of :attr:`stiff_split`."""
        return self._rhs_with(t, x, self._frictionless_args)

    def friction_solve(self, t: float, x, h: float) -> tuple[np.ndarray, int]:
        """Backward Euler over ``h`` (s) of ``x' = f_I(x)`` (positions frozen): the chain's velocities from
        :meth:`ChainA5.friction_step` and its dissipated work added to the work integral ``D - P_fr``, so the run's
        energy balance closes exactly.  Newton starts from the friction's acceleration of the previous solve (a guess
        only: the solution is unique).  Returns the new state and the Newton iterations (each one sparse LU)."""
        chain, nc, n2 = self.family.chain, self.family.size, self.n2
        key, kept = x[:nc].tobytes(), self._friction_kept
        if kept.get("halves", (None,))[0] != key:
            kept["halves"] = (key, *chain.friction_slips(x[:nc]))
        v_star = x[n2:n2 + nc]
        accel = self._friction_accel.get("halves")
        guess = None if accel is None else v_star + h * accel
        v, W, its = chain.friction_step(*kept["halves"][1:], v_star, h, guess)
        self._friction_accel["halves"] = (v - v_star) / h
        out = np.array(x, float)
        out[n2:n2 + nc] = v
        out[2 * n2 + self.control.size + 2] += W
        return out, its

    @cached_property
    def _friction_accel(self) -> dict:
        """The friction accelerations of the last solve of each split (Newton's start guess)."""
        return {}

    @cached_property
    def _friction_kept(self) -> dict:
        """The slips of the last positions each split solved at, by split (``(key, ...)``: its stages share them)."""
        return {}

    # ----- all friction implicit: the pin-sheave friction of the H2 half ends joins f_I ---------------------------
    @cached_property
    def _sheave_friction(self) -> tuple | None:
        """``(frictionless contact constants, pin-sheave law (f0, v0, name))`` where the pin-sheave friction can be
        split off (the compiled H2 contact of variant (e), a law with a potential, ``f0 > 0``), else None."""
        ck = self._compiled_contact
        if self._contact_kernel is not HEK or ck is None:
            return None
        h2 = self.contact.pair.pair
        if h2.law not in POTENTIAL_LAWS or h2.f0 == 0.0:
            return None
        par = np.array(ck[6], float)
        par[0] = 0.0
        return (*ck[:6], par, ck[7]), (float(h2.f0), float(h2.v0), h2.law)

    def rhs_explicit_all(self, t: float, x):
        """:meth:`rhs` without any friction (the halves' ``f_0 = 0``, the pin-sheave ``f0 = 0``): ``f_E`` of the
        split's variant ``"all"``."""
        return self._rhs_with(t, x, self._frictionless_args, self._sheave_friction[0])

    def _contact_forces_with(self, x, Q, contact_args: tuple) -> float:
        """The H2 contact forces on the constants ``contact_args`` added to ``Q``; returns their friction power (W)."""
        Pf, bad = HEK.forces(np.concatenate([x[:2 * self.n2], self._constants]), *self._pair_table, *contact_args, Q)
        if bad >= 0:
            raise NumericalError(f"H2 contact: a pin-half end on the shaft axis (pair {bad})",
                                 component="contact.refined")
        return Pf

    def sheave_slips(self, x) -> tuple[sp.csr_matrix, np.ndarray]:
        """``(G, N)``: the slips of the pin-sheave contacts in touch at the positions of ``x``, ``s = G v`` (2 rows per
        contact: the tangent-plane slip in an orthonormal basis of the plane, m/s; columns the velocities ``v``
        (n2,)), and their normal forces ``N`` (N): the contacts' friction forces are ``-G^T (N psi(|s|) s)``
        (:func:`~cvtfem.elements.chain.half_end_slips.slip_map`)."""
        n2, table = self.n2, self._pair_table
        P, K = table[0].shape[0], table[0].shape[2]
        N, size = np.empty(P), 2 * P * HES.N_VEL * K
        r, c, d = np.empty(size, np.int64), np.empty(size, np.int64), np.empty(size)
        m, k, bad = HES.slip_map(np.concatenate([x[:2 * n2], self._constants]), *table[:3], *self._compiled_contact,
                                 n2, N, r, c, d)
        if bad >= 0:
            raise NumericalError(f"H2 contact: a pin-half end on the shaft axis (pair {bad})",
                                 component="contact.refined")
        return sp.csr_matrix((d[:k], (r[:k], c[:k])), shape=(2 * m, n2)), N[:m]

    def friction_sets(self, x) -> list:
        """The :class:`~cvtfem.elements.chain.implicit_friction.FrictionSet` of all friction at the positions of
        ``x``: the halves' (:meth:`ChainA5.friction_slips`, on the chain's velocities) and the pin-sheave contacts'
        (:meth:`sheave_slips`)."""
        chain, nc, n2 = self.family.chain, self.family.size, self.n2
        B, c = chain.friction_slips(x[:nc])
        B = sp.csr_matrix((B.data, B.indices, B.indptr), shape=(B.shape[0], n2))
        G, N = self.sheave_slips(x)
        return [FrictionSet(B, c, 1, chain.f0, chain.v0, chain.law), FrictionSet(G, N, 2, *self._sheave_friction[1])]

    @cached_property
    def _masses(self) -> tuple:
        """``(M, M^-1, border)``: the mass matrix of all velocities (chain, shafts, sheaves), its inverse and the
        shafts' and sheaves' indices."""
        nc, iphi, iz, _ = self._idx
        ch = self.family.chain
        border = np.concatenate([iphi, iz])
        diag = np.empty(self.n2 - nc)
        diag[iphi - nc], diag[iz - nc] = self.J, self.m_sheave
        M = sp.block_diag([ch.mass_matrix, sp.diags(diag)], format="csr")
        Mi = sp.block_diag([ch.inverse_mass, sp.diags(1 / diag)], format="csr")
        return M, Mi, border

    def friction_solve_all(self, t: float, x, h: float) -> tuple[np.ndarray, int]:
        """:meth:`friction_solve` of all friction (:meth:`friction_sets`) on all velocities (chain, shafts and sheaves:
        :func:`~cvtfem.elements.chain.implicit_friction.friction_step`, the shafts' and sheaves' as its border)."""
        n2 = self.n2
        key, kept = x[:n2].tobytes(), self._friction_kept
        if kept.get("all", (None,))[0] != key:
            kept["all"] = (key, self.friction_sets(x))
        v_star = x[n2:2 * n2]
        accel = self._friction_accel.get("all")
        guess = None if accel is None else v_star + h * accel
        M, Mi, border = self._masses
        v, W, its = friction_step(M, Mi, kept["all"][1], v_star, h, guess, border=border, tol=self.FRICTION_TOL)
        self._friction_accel["all"] = (v - v_star) / h
        out = np.array(x, float)
        out[n2:2 * n2] = v
        out[2 * n2 + self.control.size + 2] += W
        return out, its

    def friction_rate(self, x) -> FrictionRate:
        """All friction at the positions of ``x`` frozen (:meth:`friction_sets`) as the compiled rate of multirate-rk4:
        its accelerations at given velocities on all velocities (chain, shafts or structure) and its stiffness bound
        (:class:`~cvtfem.elements.chain.implicit_friction.FrictionRate`)."""
        return FrictionRate(self._inverse_mass_arrays, self.friction_sets(x))

    @cached_property
    def _inverse_mass_arrays(self) -> tuple:
        """``M^-1`` of :attr:`_masses` as CSR arrays ``(indptr, indices, data)`` for the compiled friction rate."""
        Mi = sp.csr_matrix(self._masses[1])
        return Mi.indptr.astype(np.int64), Mi.indices.astype(np.int64), Mi.data.astype(float)

    def friction_hold(self, x, d):
        """The rate at ``x`` of the friction forces ``M d_v`` held constant (``d_v``: ``d``'s velocity rows, m/s^2 and
        rad/s^2): those accelerations, and their dissipated power ``-(M d_v) . v`` on the work row ``D - P_fr``."""
        n2 = self.n2
        out = np.zeros(self.size)
        out[n2:2 * n2] = d[n2:2 * n2]
        out[2 * n2 + self.control.size + 2] = -float((self._masses[0] @ d[n2:2 * n2]) @ x[n2:2 * n2])
        return out

    @cached_property
    def _jac_plan(self) -> dict | None:
        """Positions in the data of the sorted :attr:`jac_sparsity` of every constant part of :meth:`jac` (built once):
        the ``x' = v`` rows, the chain family's entries after ``M^-1`` (the rows a mass block couples share the family
        pattern's column list), the loops' rows, the work rows and, per contact pair of the table, the offsets of its
        local entries after ``M^-1`` (:func:`~cvtfem.assembly.fixed_pattern.pair_offsets`: no search per call); None
        where the family's pattern does not allow that (ChainCVT's general assembly then)."""
        if not self._one_pass:
            return None
        P = sp.csr_matrix(self.jac_sparsity, dtype=bool, copy=True)
        P.sort_indices()
        n2, nz = self.n2, self.control.size
        nc, iphi, _, _ = self._idx
        fp = self.family.jac_sparsity
        mi_ptr, mi_idx, _ = self._chain_inverse_mass
        for r in range(nc):                       # rows a mass block couples: one column list
            cols = fp.indices[fp.indptr[r]:fp.indptr[r + 1]]
            for s in mi_idx[mi_ptr[r]:mi_ptr[r + 1]]:
                if not np.array_equal(fp.indices[fp.indptr[s]:fp.indptr[s + 1]], cols):
                    return None
        rows = np.repeat(np.arange(nc), np.diff(fp.indptr))
        fam_q = FP.positions(P, n2 + rows, fp.indices)
        fam_v = FP.positions(P, n2 + rows, n2 + fp.indices)
        in_cols = np.concatenate([n2 + iphi, 2 * n2 + np.arange(nz)])
        ctrl = FP.positions(P, 2 * n2 + np.repeat(np.arange(nz), len(in_cols)), np.tile(in_cols, nz))
        top = FP.positions(P, np.arange(n2), n2 + np.arange(n2))
        if min(fam_q.min(), fam_v.min(), ctrl.min() if nz else 0, top.min()) < 0:
            return None
        first = P.indptr[2 * n2 + nz]
        work_rows = np.repeat(np.arange(4), np.diff(P.indptr[2 * n2 + nz:]))
        Mc = sp.csc_matrix(self._inv_mass)
        Mc.sort_indices()
        runs = [FP.runs(t, fp.indptr) for t in (fam_q, fam_v)]
        shared = FP.shared_rows(P, n2, Mc)
        fam = [(FP.add_mixed_rows, t) if r is None else (FP.add_mixed_runs, r) for t, r in zip((fam_q, fam_v), runs)]
        table = self._pair_table
        contact = (FP.pair_offsets(P, n2, Mc, table[0], table[3]) if shared and self._compiled_contact is not None
                   and type(self)._contact_jacobian is ChainCVT._contact_jacobian else None)
        return dict(P=P, fam=fam, ctrl=ctrl, top=top, in_cols=in_cols, contact=contact,
                    work=(first, work_rows, P.indices[first:].astype(np.int64)),
                    mixing=(Mc.indptr.astype(np.int64), Mc.indices.astype(np.int64), Mc.data.astype(float), shared))

    def jac(self, t: float, x) -> sp.csr_matrix:
        """Sparse ``d rhs / dx`` written into the data of the sorted :attr:`jac_sparsity` in place (then compacted: the
        entries idle at ``x`` dropped), from the compiled chain Jacobian's data, the contacts' entries and the loops, as
        ChainCVT's :meth:`~ChainCVT.jac` assembles them (its twin; it serves where a contact entry falls outside the
        pattern or a subclass changes the path)."""
        plan = self._jac_plan
        if plan is None:
            return super().jac(t, x)
        q, v, zc, _ = self.split(x)
        nc, iphi, iz, _ = self._idx
        n2, N, P = self.n2, self.size, plan["P"]
        w = v[iphi]
        F, M, G = self._loop_gradient(t, w, zc)
        in_cols = plan["in_cols"]
        fam, mi = self.family, self._chain_inverse_mass
        Jq, Jv, dDq, dDv = fam.chain.jacobian_data(q[:nc], v[:nc], fam.scheme)
        data = np.zeros(P.nnz)
        data[plan["top"]] = 1.0
        for (add, where), J in zip(plan["fam"], (Jq, Jv)):
            add(data, where, J, fam.jac_sparsity.indptr, *mi)
        if plan["contact"] is None:
            (r, c, d), dD_contact = self._contact_jacobian(q, v)
        else:                                     # straight into the pattern through the positions built once
            r, c, d = np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
            dD_contact = np.zeros(2 * n2)
            table, K = self._pair_table, self._contact_kernel
            pair, Jl = K.local_jacobians(np.concatenate([q, v, self._constants]), *table, *self._compiled_contact,
                                         K.STEPS)
            if SK.scatter_jacobian_into(pair, Jl, table[0], table[1], table[3], table[4], 2 * n2, dD_contact,
                                        plan["contact"], data, P.indptr, n2, *plan["mixing"][:3]):
                return super().jac(t, x)
        r = np.concatenate([r, np.repeat(iz, len(in_cols)), np.full(len(in_cols), iphi[1])])
        c = np.concatenate([c, np.tile(in_cols, 2), in_cols])
        d = np.concatenate([d, -self.sheaves_per_z * G[:2].ravel(), G[2]])
        if FP.add_mixed_entries(data, P.indptr, P.indices, n2, r, c, d, *plan["mixing"]):
            return super().jac(t, x)
        data[plan["ctrl"]] = G[3:].ravel()
        Wr = np.zeros((4, N))                           # work rates: [M1 w1, -M2 w2, 2 Phi - P_fr, -2 F.z']
        Wr[0, n2 + iphi[0]] = M[0]
        Wr[1, in_cols] = -w[1] * G[2]
        Wr[1, n2 + iphi[1]] += -M[1]
        Wr[2, :2 * n2] = dD_contact
        Wr[2, :nc] += dDq
        Wr[2, n2:n2 + nc] += dDv
        Wr[3, n2 + iz] = -self.sheaves_per_z * F
        Wr[3, in_cols] = -self.sheaves_per_z * (v[iz] @ G[:2])
        if Wr[:, iphi].any():
            return super().jac(t, x)
        first, work_rows, work_cols = plan["work"]
        data[first:] = Wr[work_rows, work_cols]
        # the idle entries out (new arrays): the integrators' reduced Newton matrices cost twice as much with them
        return sp.csr_matrix(FP.compact(data, P.indptr, P.indices), shape=(N, N))

    # ----- quasi-static start ----------------------------------------------------------------------
    def _placement(self, ratio: float, tension: float | None = None) -> "RollingPlacement":
        """Rolling points ``U_p`` of the pins on the path of ``ratio``, spaced so that with the halves of
        :meth:`_placed` every link carries ``tension`` (N; stretched by ``T / c_link``, the rolling faces pressed by
        ``T / (l k_roll)``): :func:`~cvtfem.elements.chain.halves_placement.rolling_spacing` (rolling shortens a link,
        and where the joint angles at its ends differ, as for links of unequal lengths on an arc, its direction is
        not the chord of ``U``; :func:`_rolling_placement`, to 1e-11 m: 0.01 N in a link).  ``tension`` None: the pins
        at their pitches on the path (ChainCVT's placement: the path's radii and span angle for the wedge
        estimate)."""
        if tension is None:
            return super()._placement(ratio)
        fam, ch = self.family, self.family.chain
        delta, R = tension / (ch.l * ch.roll_stiffness), float(np.min(ch.roll_radius))
        if not delta < R:        # the rolling model's faces pressed through their radius: no placement exists
            raise InputError("cvt.chain.pin_length", ch.l, f"must let the pin halves' rolling faces carry the wedge "
                             f"tension {tension:.4g} N pressed by T / (l k_roll) = {delta:.3g} m, less than their "
                             f"radius {R:.3g} m (k_roll {ch.roll_stiffness:.3g} N/m^2); or lower the clamping forces")
        pl = _rolling_placement(*map(_hashable, (fam.geom.L, ratio, self.contact.centres[0, 0], ch.roll_radius,
                                                 ch.h_pin, tension / (ch.l * ch.roll_stiffness),
                                                 tension / fam.geom.c_link)))
        return copy.deepcopy(pl)

    @staticmethod
    def _joint_angles(tau):
        """Turn ``d_p`` (rad) at each pin of the links of directions ``tau (n, 2)``."""
        t_prev = np.roll(tau, 1, 0)
        return np.abs(np.arctan2(t_prev[:, 0] * tau[:, 1] - t_prev[:, 1] * tau[:, 0], np.sum(t_prev * tau, 1)))

    def wedge_guess(self, ratio: float, F2: float):
        """ChainCVT's wedge estimate of the tension ``T`` and the sheave positions, then the halves placed at that
        tension (:meth:`_placement`), the pins compressed by their own wedge forces ``T d_p / (2 tan(gamma))``
        (``d_p`` the turn of the chain at the pin) and the sheaves moved to the half ends: on an arc both halves'
        axes run ``(R - h_pin) sin(d/2)`` inside the rolling points ``U`` (:meth:`_placed`), where the wedge is
        narrower.  With ``start_chain`` set (the stages of :meth:`_static`), ChainACVT's estimate on the plain
        placement (``start_z`` where it is set)."""
        free, u3, z = super().wedge_guess(ratio, F2)
        if self.start_chain is not None:          # given coordinates: the plain placement serves loads and speeds
            return free, u3, z
        faces = self.contact.faces
        tg = np.array([faces[k].tan_gamma(free.r[k]) for k in range(2)])
        T = F2 * tg[1] / (np.pi / 2 - free.phi)
        pl = self._placement(ratio, T)
        fam = self.family
        R, h = np.mean(fam.chain.roll_radius), fam.chain.h_pin
        d = self._joint_angles(pl.tau)
        u3 = np.full(fam.n, fam.geom.l / 2)
        for k in range(2):
            on = pl.piece == k
            u3[on] -= T * d[on] / (2 * tg[k]) / (2 * fam.geom.c_pin[on])
            r_half = pl.r[k] - (R - h) * np.sin(0.5 * np.median(d[on]))
            z[k] += faces[k].lever(free.r[k]) - faces[k].lever(r_half)
        return pl, u3, (z if self.start_z is None else np.array(self.start_z, float))

    def placed_state(self, ratio: float, w1: float) -> np.ndarray:
        """The start of the quasi-static solve as a running state: halves placed by :meth:`_placed` on the path of
        ``ratio``, sheaves at the wedge estimate for ``F_appl[1]``, the chain moving along the path at ``w1 r1``
        (rad/s, m) with the pins on the arcs turning with their sheave, shafts and loops at those speeds."""
        pl, u3, z = self.wedge_guess(ratio, float(self.F_appl[1]))
        nc, iphi, iz, _ = self._idx
        q, v = np.zeros(self.n2), np.zeros(self.n2)
        q[:nc], q[iz] = self._placed(pl, u3), z
        speed = w1 * pl.r[0]
        self.pin_positions(v[:nc])[:] = speed * pl.tangent
        v[iphi] = speed / pl.r
        for k in range(2):
            self._turn_with_sheave(q[:nc], v[:nc], np.flatnonzero(pl.piece == k), v[iphi[k]], self.contact.centres[k])
        return np.concatenate([q, v, self.control.initial_state(*v[iphi]), np.zeros(4)])

    def start(self):
        """``(x0, report)``: the quasi-static state of :meth:`static_state`, or, where its solve stalls (it does at the
        reference operating point: docs/chain.md), :meth:`placed_state`, off balance, with the stall in ``kind``."""
        try:
            return super().start()
        except NumericalError as err:
            w1, _, i = self.regime.targets(0.0)
            return self.placed_state(i, w1), {"kind": f"placed on the sheaves, off balance ({err})"}

    def _static(self, ratio: float, w1: float, F2: float, tol: float):
        """ChainCVT's quasi-static solve by continuation in the rolling tie: first with the halves' rolling held by
        ties of the stiffnesses ``ROLL_TIES`` in turn (static friction as a holonomic no-slip constraint: it makes
        stiff the relative slides and yaws of the halves whose negative stiffness under tension makes the frictionless
        balance a saddle), each to ``TIED_RESIDUAL`` of F2 from the last, then the chain's own forces (no tie) from
        there.  From ``start_chain`` where it is set: that last solve alone.  ``report["nfev"]`` counts all."""
        if self.start_chain is not None or not self.ROLL_TIES:
            return super()._static(ratio, w1, F2, tol)
        start, nfev = {}, 0
        for k in self.ROLL_TIES:
            stage = replace(self, family=HalvesFamily(self.family.chain.with_roll_tie(k), self.family.geom), **start)
            x, rep = ChainACVT._static(stage, ratio, w1, F2, 1e3 * self.TIED_RESIDUAL)
            start, nfev = dict(start_chain=x[:self.family.size], start_z=x[self._idx[2]]), nfev + rep["nfev"]
        x, report = replace(self, **start)._static(ratio, w1, F2, tol)
        report["nfev"] += nfev
        return x, report

    def _solve_balance(self, residual, jacobian, y0, tol: float):
        """:func:`~cvtfem.machines.static_balance.lifted_newton` on the sparse Jacobian, its lifted Newton phase alone
        (the static stiffness of A5 is indefinite and singular; the damped phase 1 stalls at about 2e-2 of F2 without
        the tie and led the tied solve of the uniform chain astray, to 4.6e-2), with central link differences: from
        the placement half the plates sit at the slack/taut kink, where the exact link blocks are one-sided, and the
        lifted Newton stalled on them at 2.5e-2 of F2 (central differences average the two sides)."""
        scheme, self.family.scheme = self.family.scheme, "central"
        try:
            return lifted_newton(residual, jacobian, y0, tol, damped=0, lifts=self.LIFTS, steps=self.STEPS,
                                 iterations=self.NEWTON_ITERATIONS)
        finally:
            self.family.scheme = scheme

    def _placed(self, pl, u3):
        """Straight halves rolling on each other at ``pl.u`` (the rolling faces touch on the joint's bisector
        ``b_p``): ``u-_p = U_p - R_- b_p - (h_pin - R_-) tau_p``, ``u+_p = U_p + R_+ b_p - (R_+ - h_pin) tau_{p-1}``,
        ``tau`` the directions of the links these halves make
        (:func:`~cvtfem.elements.chain.halves_placement.rolling_link_directions`); half lengths ``u3`` (n,) m, packs
        centred (``start_chain`` where it is set)."""
        if self.start_chain is not None:
            return np.array(self.start_chain, float)
        fam = self.family
        R, h = fam.chain.roll_radius, fam.chain.h_pin
        tau, delta = (pl.tau, pl.delta) if isinstance(pl, RollingPlacement) else (rolling_link_directions(pl.u, R, h),
                                                                                 0.0)
        q = fam.chain.rest_state(pl.u, tau) + self._axial(u3)
        fam.split(q)[0][:, 0] = half_centres(pl.u, tau, R, h, delta)
        return q

    def _axial(self, u3):
        """The half lengths ``w_1 = u3`` as an increment over the rest state's ``l/2``."""
        fam = self.family
        dq = np.zeros(fam.size)
        fam.split(dq)[1][:, 1] = np.asarray(u3) - fam.chain.l / 2
        return dq

    def _turn_with_sheave(self, q_chain, v_chain, pins, w, centre):
        u, vu = self.family.split(q_chain)[0], self.family.split(v_chain)[0]
        vu[:, 0, pins] = w * (u[:, 0, pins] - centre) @ _ROT
        vu[:, 1:, pins] = w * u[:, 1:, pins] @ _ROT

    # ----- construction ----------------------------------------------------------------------------
    @classmethod
    def from_parameters(cls, geom, *, contact: str = "hertz", **kw) -> "ChainHalvesCVT":
        """:meth:`ChainACVT.from_parameters`; ``contact = "hertz-refined"`` builds variant (e) on rigid shafts
        (:class:`~cvtfem.machines.chain_halves_refined_cvt.ChainHalvesRefinedCVT`: H2 at every half end)."""
        if contact == "hertz-refined" and cls is ChainHalvesCVT:
            from cvtfem.machines.chain_halves_refined_cvt import ChainHalvesRefinedCVT   # builds on this module
            return ChainHalvesRefinedCVT.from_parameters(geom, contact=contact, **kw)
        return super().from_parameters(geom, contact=contact, **kw)

    @classmethod
    def _family_for(cls, model: str, geom, damping, E: float):
        if model not in HALVES_MODELS:
            raise InputError("cvt.model", model, "must be one of " + ", ".join(HALVES_MODELS))
        return halves_family(geom, damping, E)
