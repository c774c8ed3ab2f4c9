"""The whole-pin asymmetric chains (A1; A3/A4) on two rigid shafts: :class:`ChainACVT`, the transmission of
:class:`~cvtfem.machines.chain_cvt.ChainCVT` with no symmetry plane.

Each pulley has a fixed sheave on one side of the chain and a movable sheave on the other (model 1 of
the shafts digest without its mirror plane, as the elastic models place them, digest §7): the movable
sheave's position ``z_k`` (counted outwards from the chain, m) is the coordinate ``shaft.z``, its mass half
the pair's, its virtual work ``-F_k dz_k`` with ``F_k`` the clamping force; the fixed sheave stays where
the wedge estimate puts it at the regime's ratio (aligned pulleys: the chain runs centred at ``x3 = 0``).
The default places the driving pulley's movable sheave at ``x3 > 0`` and the driven one's at ``x3 < 0``,
as in chain CVTs.  Every pin end touches the sheave on its side of each shaft
(:class:`~cvtfem.elements.chain.end_contact.EndContact`, H1 or the refined H2 of variant (a)); the ends,
their slopes and (H2) the neighbours' chords are linear in the pin coordinates (chain-models-2 §2.1-2.2),
which is the contact map of ChainCVT with two columns per input.  The chain family is wrapped in
:class:`WholePinFamily`, the interface ChainCVT drives.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.elements.chain.asymmetric import ChainA1
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.per_plate import ChainPerPlate
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.errors import InputError
from cvtfem.machines.chain import FreeChainA
from cvtfem.machines.chain_cvt import ChainCVT
from cvtfem.machines.static_balance import lifted_newton
from cvtfem.outputs import OutputSpec

#: Plate thickness along the pin (m): assumed, the per-plate models' default.
PLATE_THICKNESS = 1.5e-3
#: Plate height across the chain in its plane (m): assumed, a 9 mm pitch chain's plate.
PLATE_HEIGHT = 8e-3
#: Poisson's ratio of the steel plates (torsion stiffness ``G = E / (2 (1 + nu))``).
POISSON = 0.3
#: The per-plate chains' reduced plate moment output and its meaning on a running chain (WholePinFamily.outputs).
REDUCED_MOMENT = "chain.plate_reduced_moment"
REDUCED_MOMENT_DOC = ("Reduced bending moment m = 2M/(hT) at both ends of each plate (end 1, end 2; |m| <= 1 in A4, 1 at "
                      "a corner; 0 for a slack plate).")
#: The whole-pin models that run on the sheaves.
A_MODELS = {"chain-A1": None, "chain-A2": None, "chain-A3": "A3", "chain-A4": "A4"}


def whole_pin_family(model: str, geom, damping, E: float, plate_height: float = PLATE_HEIGHT,
                     plate_thickness: float = PLATE_THICKNESS, use_numba: bool = True):
    """A1 (or A3/A4) of a :class:`~cvtfem.elements.chain.geometry.ChainGeometry` with ``damping``
    (:class:`~cvtfem.elements.chain.symmetric.ChainDamping`): plates ``plate_height`` x ``plate_thickness``
    (m) of Young's modulus ``E`` (Pa) give the out-of-plane bending stiffness ``a = E b h^3 / 12`` (N m^2)
    and the torsion stiffness ``G b h^3 / (3 L)`` (N m/rad, chain-models-2 §2.4 [non-source]); the link
    damping time serves extension, twist and shear (rule (1.86) with one time), pins as the S models.

    A3's clamped plates keep pushing when compressed (``drop_compressed=False``; the source leaves it open, digest
    §4.8): dropped at ``Delta = 0``, a plate with tilted ends would lose its bending energy ``psi C psi / 2`` and
    moments at once (a force jump that breaks the energy balance of a run; H2's bent pins slacken the outer plates
    on the small arc).  A4's slack state is continuous (its moments vanish with ``T h/2``)."""
    if model not in A_MODELS:
        raise InputError("cvt.model", model, "must be one of " + ", ".join(A_MODELS))
    b, h = plate_height, plate_thickness
    G = E / (2 * (1 + POISSON))
    args = dict(pitch=geom.L, plate_xi=geom.xi, n_plates=geom.plate_mask.sum(axis=1),
                plate_stiffness=geom.c_plate, plate_bending_stiffness=E * b * h ** 3 / 12,
                plate_torsion_stiffness=(G * b * h ** 3 / 3) / geom.L[:, None], pin_length=geom.l,
                pin_mass=geom.m_eff, pin_axial_stiffness=geom.c_pin, pin_bending_tau=geom.A_tau,
                pin_bending_n=geom.A_n, beta_link_ext=damping.beta_link, beta_link_tors=damping.beta_link,
                beta_link_shear=damping.beta_link, beta_bend=damping.beta_bend,
                pin_axial_damping=damping.beta_pin * geom.c_pin, joint_damping=damping.b_joint,
                closed=geom.closed, use_numba=use_numba)
    if A_MODELS[model] is None:
        return WholePinFamily(ChainA1(**args), geom)
    clamped = ChainPerPlate(model="A3", plate_thickness=h, **args) if A_MODELS[model] == "A4" else None
    chain = ChainPerPlate(model=A_MODELS[model], plate_thickness=h, drop_compressed=A_MODELS[model] == "A4", **args)
    return WholePinFamily(chain, geom, homogenised=ChainA1(**args), clamped=clamped)


class WholePinFamily:
    """An A-family chain (``ChainA1`` or ``ChainPerPlate``) with the interface of the symmetric families that
    :class:`~cvtfem.machines.chain_cvt.ChainCVT` drives (``forces``, ``solve_mass``, ``jacobian``, ...).

    The Jacobian blocks are those of :class:`~cvtfem.machines.chain.FreeChainA` (exact elastic and damping
    matrices plus coloured differences of the damping forces in ``q``)."""

    name = "chain"

    def __init__(self, chain, geom, homogenised=None, clamped=None):
        self.chain, self.geom = chain, geom
        self.homogenised = homogenised                # A3/A4: A1 of the same plates (the start's first step)
        self.clamped = clamped                        # A4: A3 of the same plates (the start's second step)
        self._a1 = getattr(chain, "base", chain)        # the ChainA1 layout of A3/A4
        self.n, self.size = chain.n_pins, chain.n2
        self.dof_index = chain.dof_index
        self.ip1 = (np.arange(self.n) + 1) % self.n
        self.on = geom.link_on
        self._free = FreeChainA(chain, np.zeros(chain.n2))
        self._last: tuple = (None, None, None)       # the blocks of the last state asked for
        self._last_plates: tuple = (None, None, None)  # per-plate chains: the plate forces of the last forces()

    @property
    def blocks(self):
        return self.chain.blocks

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        """The chain's outputs; a per-plate chain's reduced moment is 0 for a slack plate (:meth:`outputs`)."""
        return tuple(replace(s, doc=REDUCED_MOMENT_DOC) if s.name == REDUCED_MOMENT else s
                     for s in self.chain.output_specs)

    @property
    def jac_sparsity(self) -> sp.csr_matrix:
        return self.chain.jac_sparsity

    def split(self, q):
        """``(u (4, n, 2), w (2, n))`` views (chain-models-2 §2.1)."""
        return self._a1.split(q)

    def join(self, u, w):
        """Inverse of :meth:`split`."""
        return self._a1.join(u, w)

    def forces(self, q, v):
        if self.homogenised is None:
            return self.chain.forces(q, v)
        plates = self.chain.plate_forces(q, v)
        self._last_plates = (q.tobytes(), v.tobytes(), plates)
        return self.chain.base.forces(q, v) + plates

    def dissipative_forces(self, q, v):
        return self.chain.dissipative_forces(q, v)

    def rayleigh(self, q, v) -> float:
        """Rayleigh function (W).  A per-plate chain's plate part is ``-v . Q_d / 2`` (Euler's identity for ``Phi``
        quadratic in ``v`` within the current plate states) with ``Q_d`` the compiled plate forces less their
        elastic part (those of the last :meth:`forces` at the same state, as the RHS asks): the numpy plates'
        Rayleigh function costs about 15 ms, the RHS 0.5 ms."""
        if self.homogenised is None:
            return float(self.chain.rayleigh(q, v))
        key = self._last_plates
        plates = key[2] if key[0] == q.tobytes() and key[1] == v.tobytes() else self.chain.plate_forces(q, v)
        damping = plates - self.chain.plate_forces(q, None)
        return float(self.chain.base.rayleigh(q, v) - 0.5 * v @ damping)

    def energy(self, q, v) -> float:
        """Kinetic plus elastic energy of the chain, J."""
        return float(self.chain.kinetic_energy(v) + self.chain.potential_energy(q))

    def mass_matrix(self) -> sp.csr_matrix:
        return self.chain.mass_matrix

    @cached_property
    def _inv_mass(self) -> sp.csr_matrix:
        return sp.csr_matrix(spla.inv(sp.csc_matrix(self.chain.mass_matrix)))

    def solve_mass(self, Q):
        """``M^-1 Q`` (per-pin blocks)."""
        return self._inv_mass @ Q

    def jacobian(self, q, v, part: str = "all", wrt: tuple = (0, 1)):
        """``(dQ/dq, dQ/dq')`` (CSR) of all forces, or with ``part="dissipative"`` of the damping forces alone
        (their ``dQ/dq`` is the total's less the one at ``q' = 0``, where the damping forces vanish)."""
        x = np.concatenate([q, v])
        key = x.tobytes()
        if self._last[0] != key:                      # ChainCVT.jac asks for both parts at one state
            lin = self._free.linearize(x)
            self._last = (key, -lin.K, -lin.C)
        dq, dv = self._last[1:]
        if part == "dissipative":
            dq = dq + self._free.linearize(np.concatenate([q, np.zeros_like(v)])).K
        return tuple(sp.csr_matrix(dq if k == 0 else dv) for k in wrt)

    def outputs(self, q, v):
        """The chain's outputs; the reduced moment ``2M/(hT)`` of a slack plate (state 10, ``M = T = 0``: undefined, NaN
        in the plate law's outputs) is written as 0, the moment it carries, since a results file takes a non-finite
        value for a failed run."""
        out = self.chain.outputs(q, v)
        if REDUCED_MOMENT in out:
            out[REDUCED_MOMENT] = np.nan_to_num(out[REDUCED_MOMENT], nan=0.0)
        return out


_ROT = np.array([[0.0, 1.0], [-1.0, 0.0]])      # a @ _ROT = k x a


@dataclass(frozen=True, eq=False)
class ChainACVT(ChainCVT):
    """A whole-pin chain (A1, A3, A4) on two rigid shafts, each with a fixed and a movable sheave.

    Attributes (besides ChainCVT's; ``m_sheave`` is the movable sheave's mass, ``z`` its position)
    ----------
    movable_side : (2,) +-1
        Side (sign of ``x3``) of the movable sheave of each shaft (driving, driven).
    fixed_z : (2,) m
        Position of each fixed sheave, counted outwards from ``x3 = 0`` as ``z`` (set by ``from_parameters``
        from the wedge estimate at the regime's ratio).
    start_chain : (n2_chain,) or None
        Chain coordinates the quasi-static solve starts from (None: the pins placed on the band path); A3/A4
        set it to the balance of A1 with the same plates (:meth:`_static`).
    start_z : (2,) m or None
        Movable sheave positions the quasi-static solve starts from (None: the wedge estimate); A3/A4 set them to
        A1's balance with ``start_chain``.
    """

    movable_side: tuple = (1, -1)
    fixed_z: tuple = (0.0, 0.0)
    start_chain: Any = field(default=None, repr=False)
    start_z: Any = field(default=None, repr=False)

    sheaves_per_z: ClassVar[float] = 1.0

    def __post_init__(self):
        if not set(self.movable_side) <= {1, -1} or len(self.movable_side) != 2:
            raise InputError("movable_side", self.movable_side, "must be two signs (+1 or -1), driving then driven")

    @cached_property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        return super().output_specs + (
            OutputSpec("contact.fixed_sheave_axial_force", "N",
                       "Sum of the pin axial contact forces on the fixed sheave of each shaft.", 2),)

    # ----- contact ends: far (x3 < 0) and near (x3 > 0) end of each pin, end e = 2 p + (near) -------------
    @property
    def n_ends(self) -> int:
        return 2 * self.family.n

    def pin_of(self, ends):
        return ends // 2

    def pin_positions(self, q_chain):
        return self.family.split(q_chain)[0][0]

    def _candidates(self, q):
        u = self.family.split(q[:self._idx[0]])[0]
        ends = np.stack([u[0] - u[1], u[0] + u[1]], axis=1).reshape(-1, 2)
        return self.contact.candidates(ends)

    @property
    def _constants(self) -> np.ndarray:
        return np.array([*self.fixed_z, 0.0])

    @cached_property
    def _map_table(self):
        """The contact map of every ``(end, shaft)`` pair, row ``2 end + shaft`` (built once)."""
        return self._build_contact_map(*self._all_pairs())

    def _contact_map(self, ends, shafts):
        cols, coef = self._map_table
        k = 2 * ends + shafts
        return cols[k], coef[k]

    def _build_contact_map(self, ends, shafts):
        """Inputs in the mirrored frame of each end: ``x_perp = u_0 + s u_1``, ``x3 = s w_0 + w_1`` with ``s``
        the end's side; the sheave on that side is the movable one (``z_k``) or the fixed one (a constant).
        H2 (:meth:`_refined_positions`) reads the end slope and the neighbours too."""
        _, iphi, iz, _ = self._idx
        n2, m = self.n2, len(ends)
        d = self._end_dofs(ends)
        side = np.where(ends % 2 == 1, 1.0, -1.0)
        one = np.ones(m)
        movable = np.asarray(self.movable_side)[shafts] == side
        zc = np.where(movable, iz[shafts], 2 * n2 + shafts)             # z_k or the fixed sheave's constant
        zv = np.where(movable, n2 + iz[shafts], 2 * n2 + 2)             # its rate (0 for the fixed one)
        if self.contact.refined:
            pos = self._refined_positions(ends, d, side)
        else:
            pos = [(d[:, 0], d[:, 2], one, side), (d[:, 1], d[:, 3], one, side), (d[:, 8], d[:, 9], side, one)]
        n_pos = len(pos) + 1                                            # and z
        cols = np.empty((m, 2 * n_pos + 1, 2), np.int64)
        coef = np.zeros((m, 2 * n_pos + 1, 2))
        for j, (a, b, ca, cb) in enumerate(pos):
            cols[:, j] = np.column_stack([a, b])
            cols[:, n_pos + j] = n2 + cols[:, j]
            coef[:, j] = coef[:, n_pos + j] = np.column_stack([ca, cb])
        for j, c in ((n_pos - 1, zc), (2 * n_pos - 1, zv), (2 * n_pos, n2 + iphi[shafts])):
            cols[:, j] = c[:, None]
            coef[:, j, 0] = 1.0
        return cols, coef

    def _refined_positions(self, ends, d, side):
        """H2's position inputs as ``(column a, column b, weight a, weight b)``: the pins ``p-1, p, p+1`` at the
        end's in-plane offset ``s u_1`` of pin ``p`` (their chords are the mean-axis chords, which give the pin
        spin (1.138)), ``x3 = s w_0 + w_1``, and the end slope in the mirrored frame,
        ``s (2/l u_1 + u_2)`` (far, ``s = -1``) or ``s (2/l u_1 + u_3)`` (near), over ``END_SLOPE_FACTOR``
        (chain-models-2 §2.2)."""
        fam = self.family
        pins = self.pin_of(ends)
        dm, dn = fam.dof_index[(pins - 1) % fam.n], fam.dof_index[fam.ip1[pins]]
        one = np.ones(len(ends))
        bend = np.where(side > 0, d[:, 6:8].T, d[:, 4:6].T).T          # u_3 (near) or u_2 (far)
        k = side / END_SLOPE_FACTOR
        return [(dm[:, 0], d[:, 2], one, side), (dm[:, 1], d[:, 3], one, side),
                (d[:, 0], d[:, 2], one, side), (d[:, 1], d[:, 3], one, side),
                (dn[:, 0], d[:, 2], one, side), (dn[:, 1], d[:, 3], one, side),
                (d[:, 8], d[:, 9], side, one),
                (d[:, 2], bend[:, 0], 2 / fam.geom.l * k, k), (d[:, 3], bend[:, 1], 2 / fam.geom.l * k, k)]

    def outputs(self, t: float, x):
        """ChainCVT's outputs; the support forces are the resultant of the contact forces on the pin ends (the
        H2 kernel's first outputs are the spin couple on the neighbours, not the end force)."""
        out = super().outputs(t, x)
        q, v, _, _ = self.split(x)
        _, shafts, _, (_, c) = self._contacts(q, v, details=True)
        out["driving.support_force"], out["driven.support_force"] = (
            np.column_stack([np.bincount(shafts, c["F"][:, j], 2) for j in (0, 1)]))
        return out

    def _extra_approach(self, k, r):
        return self.contact.extra_approach(k, r)

    def _end_dofs(self, ends):
        """``(m, 10)`` coordinate positions (A1 order) of the pin (or pin half) carrying each end."""
        return self.family.dof_index[self.pin_of(ends)]

    def _sheave_outputs(self, ends, shafts, c) -> dict[str, np.ndarray]:
        movable = np.asarray(self.movable_side)[shafts] == np.where(ends % 2 == 1, 1, -1)
        F3 = c["F"][:, 2]
        return {"contact.sheave_axial_force": -np.bincount(shafts[movable], F3[movable], 2),
                "contact.fixed_sheave_axial_force": -np.bincount(shafts[~movable], F3[~movable], 2)}

    # ----- quasi-static start ----------------------------------------------------------------------
    def _elastic_link_tension(self, q_chain):
        return self.family.outputs(q_chain, None)["chain.link_tension"]

    def _static(self, ratio, w1, F2, tol):
        """ChainCVT's quasi-static solve; a per-plate chain (A3, A4) first solves A1 of the same plates (the
        homogenised layer, ``family.homogenised``) and continues from that balance (its chain coordinates and movable
        sheaves): from the placement guess the plate states make Levenberg–Marquardt stall (A3 at 1.1e-2 of F2).
        A4 continues through the balance of A3 (``family.clamped``): where no plate bears on a corner (state 1
        everywhere, as on the reference chain) A3's balance is A4's, and the A4 solve ends in a few evaluations
        instead of about 1800 from A1's balance."""
        fam = self.family
        if fam.homogenised is None or self.start_chain is not None:
            return super()._static(ratio, w1, F2, tol)
        x, _ = replace(self, family=WholePinFamily(fam.homogenised, fam.geom))._static(ratio, w1, F2, tol)
        if fam.clamped is not None:
            clamped = WholePinFamily(fam.clamped, fam.geom, homogenised=fam.homogenised)
            x, _ = self._continued(x, clamped)._static(ratio, w1, F2, tol)
        return self._continued(x, fam)._static(ratio, w1, F2, tol)

    def _continued(self, x, family) -> "ChainACVT":
        """This transmission with ``family`` whose quasi-static solve starts from the chain and movable sheaves of
        ``x`` (a balance of another family of the same layout)."""
        return replace(self, family=family, start_chain=x[:family.size], start_z=x[self._idx[2]])

    def _solve_balance(self, residual, jacobian, y0, tol: float):
        """A per-plate chain (A3, A4) from A1's balance: :func:`~cvtfem.machines.static_balance.lifted_newton` (scipy's
        dense Levenberg-Marquardt left A4 at 4.1e-5 of F2 after 200 evaluations); A1: ChainCVT's."""
        if self.family.homogenised is None:
            return super()._solve_balance(residual, jacobian, y0, tol)
        return lifted_newton(residual, jacobian, y0, tol)

    def wedge_guess(self, ratio: float, F2: float):
        """ChainCVT's wedge estimate; the sheaves at ``start_z`` where it is set."""
        pl, u3, z = super().wedge_guess(ratio, F2)
        return pl, u3, (z if self.start_z is None else np.array(self.start_z, float))

    def _placed(self, pl, u3):
        if self.start_chain is not None:
            return np.array(self.start_chain, float)
        u = np.zeros((4, self.family.n, 2))
        u[0] = pl.u
        return self.family.join(u, np.stack([np.zeros(self.family.n), u3]))

    def _turn_with_sheave(self, q_chain, v_chain, pins, w, centre):
        """The pins' in-plane vectors (position about ``centre``, tilt, slopes) turn at ``w`` (rad/s)."""
        u, vu = self.family.split(q_chain)[0], self.family.split(v_chain)[0]
        vu[0, pins] = w * (u[0, pins] - centre) @ _ROT
        vu[1:, pins] = w * u[1:, pins] @ _ROT

    # ----- construction ----------------------------------------------------------------------------
    @classmethod
    def _family_for(cls, model: str, geom, damping, E: float):
        return whole_pin_family(model, geom, damping, E)

    @classmethod
    def _contact_for(cls, contact):
        return EndContact(contact)

    @classmethod
    def from_parameters(cls, geom, *, contact: str = "hertz", face_radius: float = 0.02, **kw) -> "ChainACVT":
        """:meth:`ChainCVT.from_parameters`; ``contact = "hertz-refined"`` puts H2 at both ends of every pin
        (:class:`RefinedSheaveContact` with the end slopes, crown radius ``face_radius``, m): variant (a)."""
        if kw.get("model") == "chain-A2" and cls is ChainACVT:
            from cvtfem.machines.chain_a2_cvt import ChainA2CVT    # builds on this module
            return ChainA2CVT.from_parameters(geom, contact=contact, face_radius=face_radius, **kw)
        if contact not in ("hertz", "hertz-refined"):
            raise InputError("cvt.effects.contact", contact, "must be 'hertz' or 'hertz-refined' for a whole-pin chain")
        model = super().from_parameters(geom, contact="hertz", face_radius=face_radius, **kw)
        if contact == "hertz":
            return model
        h1 = model.contact.pair
        fam = model.family
        h2 = RefinedSheaveContact(h1.centres, h1.faces, h1.c, h1.r_outer, h1.f0, h1.v0, face_radius,
                                  (np.arange(fam.n) - 1) % fam.n, fam.ip1, slopes=True, law=h1.law, eps=h1.eps,
                                  face_inclination=kw.get("face_inclination", 0.0))
        return replace(model, contact=EndContact(h2))._settled()

    def _settled(self) -> "ChainACVT":
        """The fixed sheaves where the wedge estimate at the regime's start ratio and ``F_appl[1]`` puts them."""
        _, _, z = self.wedge_guess(self.regime.targets(0.0)[2], float(self.F_appl[1]))
        return replace(self, fixed_z=tuple(float(zk) for zk in z))
