"""Rotor scenes -> layout and linear model (sparse M, K, C, G), a :class:`~cvtfem.assembly.model.Model`.

Nodes are numbered from 0 at the left end of the first shaft element; each
node has the 6 DOF ``(u1, u2, u3, theta1, theta2, phi)``.  Support (pedestal)
nodes named by a bearing's ``link_node`` follow the shaft nodes; disks with an
elastic connection get their own node after those.  Equation of
motion (spec §12.6): ``M q'' + (C + Omega G) q' + K q = 0``; the time-domain
model runs at the spin speed ``Omega = speed`` (rad/s).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.assembly import assemble
from cvtfem.assembly.model import Linearization, ModelBase, StateLayout
from cvtfem.elements.base import Block, Layout
from cvtfem.elements.beam import BeamFamily, BeamOptions
from cvtfem.elements.bearing import SPEED_COEFFICIENTS, BearingFamily, RadialLaw, SpeedTables
from cvtfem.elements.disk import DiskFamily, connection_stiffness, disc_profile, sheave_profile
from cvtfem.errors import InputError
from cvtfem.outputs import OutputSpec
from cvtfem.scene.loader import Scene
from cvtfem.scene.schema.rotor import MAX_ELEMENTS, right_diameters

#: Names of the 6 DOF of a node, in order.
DOF_NAMES = ("u1", "u2", "u3", "theta1", "theta2", "phi")


def _output_specs(nodes: int, n_bearings: int) -> tuple[tuple[OutputSpec, ...], tuple[OutputSpec, ...]]:
    """Outputs of the shaft (``nodes`` beam nodes) and of the bearings."""
    return ((OutputSpec("shaft.displacement", "m", "Nodal displacements and rotations.", 6 * nodes),),
            (OutputSpec("bearing.force", "N", "Bearing forces x, y.", 2 * n_bearings),) if n_bearings else ())


@dataclass(frozen=True)
class RotorModel(ModelBase):
    """Linear rotor model.

    Attributes
    ----------
    M, K, C, G : scipy.sparse.csr_matrix (n, n)
        Mass, stiffness, damping, gyroscopic per unit spin speed (skew).
    z : array (n_nodes,)
        Axial node positions, m (support nodes and elastic-connection disk nodes sit at their shaft node).
    beam, disks, bearings : element families
        For rendering and outputs.
    profiles : tuple
        Per disk its (r, z) section polygon relative to the centre of mass (m), or None.
    speed : float, rad/s
        Spin speed of the time-domain model (:meth:`rhs`); modal analyses take theirs from the caller.
    seats : tuple of int (n_disks,)
        Shaft node each disk sits on (its own node when elastically connected is ``disks.nodes``).
    extra_kinds : tuple of int
        Node DOF kind of each DOF after the nodes' (the modal coordinates of flexible sheaves,
        :func:`cvtfem.machines.sheave.flexible_sheaves`).
    tables : SpeedTables or None
        Bearing coefficients over speed; K and C hold them at ``speed``, :attr:`speed_terms` the rest.
    extra_diameters : tuple of int
        Nodal-diameter number of each flexible-sheave modal coordinate.
    K2 : scipy.sparse.csr_matrix (n, n) or None
        Flexible sheaves' stiffness per ``Omega^2`` (kg; spin stiffening and softening, fixed frame); K holds
        ``speed^2 K2``, :attr:`speed_terms` the change with the speed.
    sheave_faces : tuple of FaceModes
        Flexible sheaves' contact faces as their modal coordinates move them (for the radiated power,
        :class:`~cvtfem.machines.sheave_face_modes.FaceModes`).
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    C: sp.csr_matrix
    G: sp.csr_matrix
    z: np.ndarray
    beam: BeamFamily
    disks: DiskFamily
    bearings: BearingFamily
    profiles: tuple = ()
    speed: float = 0.0
    seats: tuple = ()
    extra_kinds: tuple = ()
    tables: SpeedTables | None = None
    extra_diameters: tuple = ()
    K2: sp.csr_matrix | None = None
    sheave_faces: tuple = ()

    @property
    def speed_terms(self) -> SpeedTerms | None:
        """What K and C gain away from the model's speed (speed-dependent bearings, spinning flexible sheaves), or
        None."""
        if self.tables is None and self.K2 is None:
            return None
        return SpeedTerms(self.n_dof, self.tables, self.speed, self.K2)

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    @property
    def layout(self) -> StateLayout:
        return StateLayout((Block("nodes", self.n_dof, "m (u1, u2, u3), rad (theta1, theta2, phi) per node"),))

    @property
    def n_shaft_nodes(self) -> int:
        return int(self.beam.nodes.max()) + 1

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        shaft, bearings = _output_specs(self.n_shaft_nodes, len(self.bearings.nodes))
        return shaft + bearings

    def bearing_force_map(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``(D, V)``, each ``(2 n_bearings, n)``: the x, y bearing forces are ``D u + V v`` (N); a bearing
        between two nodes carries ``B (u_i - u_j)``."""
        b, n = self.bearings, self.n_dof
        rows = np.repeat(np.arange(2 * len(b.nodes)), 6)
        cols = np.repeat(b.dofs, 2, axis=0).ravel()
        ln = np.repeat(b.linked, 2)
        other = np.repeat(np.where(b.linked, b.links if b.links is not None else 0, 0)[:, None] * 6 + np.arange(6),
                          2, axis=0)
        out = []
        for X in (b.stiffness(), b.damping()):
            rows_x = X[:, :2, :].reshape(-1, 6)
            own = sp.csr_matrix((rows_x.ravel(), (rows, cols)), shape=(2 * len(b.nodes), n))
            far = sp.csr_matrix((-rows_x[ln].ravel(), (rows.reshape(-1, 6)[ln].ravel(), other[ln].ravel())),
                                shape=(2 * len(b.nodes), n))
            out.append((own + far).tocsr())
        return tuple(out)

    def support_stiffness(self) -> sp.csr_matrix:
        """``(n, n)`` stiffness of the bearings on shaft nodes, to ground or linked to a support node (and the
        tabulated ones at the model's speed), N/m, N m/rad; the supports of pedestal nodes are not included."""
        blocks = self.bearings.stiffness()
        blocks[self.bearings.nodes >= self.n_shaft_nodes] = 0.0
        K = assemble(self.n_dof, self.bearings.relative(blocks))
        if self.tables is not None:
            K = K + _lateral(self.n_dof, self.tables.nodes, self.tables.blocks(self.speed)[0])
        return K.tocsr()

    def support_dofs(self, nodes) -> np.ndarray:
        """``(s, 2)`` DOFs ``(u1, u2)`` of the shaft nodes ``nodes``."""
        nodes = np.atleast_1d(np.asarray(nodes, int))
        if np.any((nodes < 0) | (nodes >= self.n_shaft_nodes)):
            raise InputError("support nodes", nodes.tolist(), f"must be shaft nodes 0..{self.n_shaft_nodes - 1}")
        return nodes[:, None] * 6 + np.arange(2)

    def unbalance_load(self, node: int, me: float, phase: float) -> np.ndarray:
        """Complex force amplitude per unit ``Omega^2`` of an unbalance ``me`` (kg m) at angle ``phase`` (rad).

        The force ``me Omega^2 (cos(Omega t + phase), sin(Omega t + phase))`` turns with the spin: its
        amplitude is ``me e^{i phase} (e1 - i e2)`` at the disk seated on shaft node ``node`` (on the
        disk's own node when it is elastically connected), else at the shaft node itself.
        """
        if not 0 <= node < self.n_shaft_nodes:
            raise InputError("unbalance node", node, f"must be a shaft node 0..{self.n_shaft_nodes - 1}")
        on = np.flatnonzero(np.asarray(self.seats) == node)
        target = int(self.disks.nodes[on[0]]) if len(on) else node
        f = np.zeros(self.n_dof, dtype=complex)
        f[6 * target: 6 * target + 2] = me * np.exp(1j * phase) * np.array([1.0, -1.0j])
        return f

    @cached_property
    def _lu(self):  # noqa: ANN202 - scipy SuperLU of M
        return spla.splu(sp.csc_matrix(self.M))

    def initial_state(self) -> np.ndarray:
        """At rest in the undeformed position."""
        return np.zeros(self.size)

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[v, M^-1 (-(C + speed G) v - K u)]``."""
        n = self.n_dof
        u, v = x[:n], x[n:]
        return np.concatenate([v, self._lu.solve(-(self.C @ v + self.speed * (self.G @ v)) - self.K @ u)])

    def jac(self, t: float, x: np.ndarray) -> sp.csr_matrix:
        """Constant ``[[0, I], [-M^-1 K, -M^-1 (C + speed G)]]`` (CSR; ``M^-1`` fills the lower blocks)."""
        n = self.n_dof
        lower = -self._lu.solve(sp.hstack([self.K, self.C + self.speed * self.G]).toarray())
        return sp.vstack([sp.hstack([sp.csr_matrix((n, n)), sp.eye(n)]), sp.csr_matrix(lower)], format="csr")

    @property
    def jac_sparsity(self) -> sp.csr_matrix:
        return self.jac(0.0, self.initial_state()) != 0

    def linearize(self, x0: np.ndarray) -> Linearization:
        """The model's own M, C, G, K (linear: the same at every state)."""
        return Linearization(M=self.M, C=self.C, G=self.G, K=self.K)

    def energy(self, x: np.ndarray) -> float:
        """``v M v / 2 + u K_s u / 2`` with the symmetric part ``K_s`` of K, J."""
        n = self.n_dof
        u, v = x[:n], x[n:]
        return float(v @ (self.M @ v) / 2 + u @ (self.K @ u) / 2)

    def power(self, t: float, x: np.ndarray) -> dict[str, float]:
        """Dissipated ``v C v`` and circulatory ``v K_a u`` power (K_a: skew part of K), W:
        ``dE/dt = -dissipated - circulatory`` (G is skew: no gyroscopic power)."""
        n = self.n_dof
        u, v = x[:n], x[n:]
        return {"dissipated": float(v @ (self.C @ v)), "circulatory": float(v @ ((self.K - self.K.T) @ u)) / 2}

    def outputs(self, t: float, x: np.ndarray) -> dict[str, np.ndarray]:
        """Shaft-node displacements and the x, y forces the bearings carry, ``K_b u + C_b v`` (N)."""
        n = self.n_dof
        u, v = x[:n], x[n:]
        out = {"shaft.displacement": u[:6 * self.n_shaft_nodes].copy()}
        if len(self.bearings.nodes):
            D, V = self.bearing_force_map()
            out["bearing.force"] = D @ u + V @ v
        return out

    @property
    def dof_kind(self) -> np.ndarray:
        """Index into :data:`DOF_NAMES` of every DOF (flexible sheaves' modal coordinates: the kind they move)."""
        return np.concatenate([np.tile(np.arange(6), self.n_node_dofs // 6), np.array(self.extra_kinds, int)])

    def sheave_share(self, shapes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per mode shape (columns): the share of its strain energy ``x^H K x`` in the flexible sheaves (their
        fixed-interface modes ``q``: ``q^H K_qq q``, an exact split because Craig–Bampton leaves no stiffness
        between them and the nodes), and the nodal-diameter number of the sheave mode storing most;
        ``(0, -1)`` for rotors without flexible sheaves."""
        k = shapes.shape[1]
        if not self.extra_kinds:
            return np.zeros(k), np.full(k, -1)
        q = shapes[self.n_node_dofs:]
        Kqq = self.K[self.n_node_dofs:, self.n_node_dofs:]
        energy = np.real(q.conj() * (Kqq @ q))
        share = energy.sum(axis=0) / np.real(np.sum(shapes.conj() * (self.K @ shapes), axis=0))
        return share, np.array(self.extra_diameters, dtype=np.int64)[np.argmax(energy, axis=0)]

    @property
    def n_node_dofs(self) -> int:
        """DOFs of the nodes (6 each), before the flexible sheaves' modal coordinates."""
        return self.n_dof - len(self.extra_kinds)


def _shaft_arrays(scene: Scene) -> dict[str, np.ndarray]:
    mats = {m.name: m for m in scene.material}
    n = sum(s.repeat for s in scene.shaft)
    if n > MAX_ELEMENTS:
        raise InputError("shaft[].repeat", n, f"must add up to at most {MAX_ELEMENTS} shaft elements "
                         f"({6 * (n + 1):.3g} DOF asked for)")
    rows = [s for s in scene.shaft for _ in range(s.repeat)]
    right = np.array([right_diameters(s) for s in rows]).reshape(-1, 2)
    return {"L": np.array([s.length for s in rows]), "parallel": np.array([s.parallel for s in rows], bool),
            "Do": np.array([s.outer_diameter for s in rows]),
            "Di": np.array([s.inner_diameter for s in rows]),
            "Do_right": right[:, 0], "Di_right": right[:, 1],
            "E": np.array([mats[s.material].E for s in rows]),
            "G": np.array([mats[s.material].G for s in rows]),
            "rho": np.array([mats[s.material].rho for s in rows])}


def _disk_properties(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
    mats = {m.name: m for m in scene.material}
    m, Id, Ip, profiles = [], [], [], []
    for d in scene.disk:
        if d.geometry:
            from cvtfem.elements.disk import axisymmetric_properties

            if d.geometry == "disc":
                prof = disc_profile(d.width, d.inner_diameter, d.outer_diameter)
            else:
                prof = sheave_profile(d.inner_diameter, d.outer_diameter, d.hub_diameter, d.hub_length,
                                      d.rim_thickness, d.cone_angle, d.face, d.torus_radius)
                if d.facing == "-z":
                    prof = (prof[0], -prof[1])
            p = axisymmetric_properties(*prof, mats[d.material].rho)
            m.append(p.m), Id.append(p.Id), Ip.append(p.Ip)
            profiles.append((prof[0], prof[1] - p.zc))
        else:
            m.append(d.mass), Id.append(d.Id), Ip.append(d.Ip)
            profiles.append(None)
    return np.array(m), np.array(Id), np.array(Ip), tuple(profiles)


def _bearings(scene: Scene) -> BearingFamily:
    entries = []
    for b in scene.bearing:
        e = {k: b[k] for k in ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy", "kzz", "czz",
                               "ktt", "ctt", "kphi", "cphi", "Id", "Ip")}
        e["m"] = b.mass
        e.update({c: 0.0 for c in SPEED_COEFFICIENTS if b[f"{c}_table"]})  # the table replaces the constant
        if b.law != "linear":
            law = RadialLaw(u=b.table_u, f=b.table_f) if b.law == "table" else RadialLaw(coeffs=b.coeffs)
            Kt = law.tangent(np.array(b.u0))
            Dt = law.damping(np.array(b.u0), b.beta)
            e.update(kxx=Kt[0, 0], kxy=Kt[0, 1], kyx=Kt[1, 0], kyy=Kt[1, 1], cxx=e["cxx"] + Dt[0, 0],
                     cxy=e["cxy"] + Dt[0, 1], cyx=e["cyx"] + Dt[1, 0], cyy=e["cyy"] + Dt[1, 1])
        entries.append(e)
    return BearingFamily.from_dicts(np.array([b.node for b in scene.bearing], dtype=np.int64), entries,
                                    np.array([b.link_node for b in scene.bearing], dtype=np.int64))


def _support_nodes(scene: Scene, n_shaft: int) -> int:
    """Number of support (pedestal) nodes: those after the shaft's that a bearing's ``link_node`` names."""
    return len({b.link_node for b in scene.bearing if b.link_node >= n_shaft})


def _support_positions(scene: Scene, z: np.ndarray, n_shaft: int, n_support: int) -> np.ndarray:
    """Axial position of each support node: that of the shaft node linked to it (through a chain of links), m."""
    links = {(b.node, b.link_node) for b in scene.bearing if b.link_node >= 0}
    pos = {}
    for _ in range(n_support):  # follow chains of pedestals out from the shaft
        for a, b in links:
            for here, there in ((a, b), (b, a)):
                if there >= n_shaft and there not in pos and (here < n_shaft or here in pos):
                    pos[there] = z[here] if here < n_shaft else pos[here]
    return np.array([pos.get(n_shaft + k, 0.0) for k in range(n_support)])


def _speed_tables(scene: Scene) -> SpeedTables | None:
    """The bearings' coefficient tables over speed (None without any); a coefficient without a table keeps its
    constant value (in the family's K and C, so the tables hold 0 for it)."""
    rows = [b for b in scene.bearing if b.speeds]
    if not rows:
        return None
    values = tuple(np.column_stack([np.asarray(b[f"{c}_table"], float) if b[f"{c}_table"]
                                    else np.zeros(len(b.speeds)) for c in SPEED_COEFFICIENTS]) for b in rows)
    return SpeedTables(np.array([b.node for b in rows], dtype=np.int64),
                       tuple(np.asarray(b.speeds, float) for b in rows), values)


def _lateral(n: int, nodes: np.ndarray, blocks: np.ndarray) -> sp.csr_matrix:
    """``(b, 2, 2)`` lateral blocks on the (u1, u2) DOFs of ``nodes``, as an ``(n, n)`` matrix."""
    dofs = nodes[:, None] * 6 + np.arange(2)
    return assemble(n, [(blocks, dofs)])


@dataclass(frozen=True)
class SpeedTerms:
    """Speed-dependent part of a rotor's K and C: ``(K(speed) - K(speed0), C(speed) - C(speed0))``.

    The model's own K and C hold the tabulated coefficients (``tables``, or None) and the spinning sheaves'
    ``speed0^2 K2`` (``K2``, or None) at ``speed0`` (``[rotor] speed``); solvers that follow the speed
    (``ModalProblem``, ``unbalance_response``) add these differences. ``pattern``: where they can be non-zero.
    """

    n: int
    tables: SpeedTables | None = field(repr=False)
    speed0: float = 0.0
    K2: sp.csr_matrix | None = field(default=None, repr=False)

    @cached_property
    def pattern(self) -> sp.csr_matrix:
        out = sp.csr_matrix((self.n, self.n))
        if self.tables is not None:
            out = out + _lateral(self.n, self.tables.nodes, np.ones((len(self.tables.nodes), 2, 2)))
        if self.K2 is not None:
            out = out + abs(self.K2)
        return out.tocsr()

    @cached_property
    def _base(self) -> tuple[np.ndarray, np.ndarray]:
        return self.tables.blocks(self.speed0)

    @property
    def damped(self) -> bool:
        return self.tables is not None and bool(np.any([v[:, 4:] for v in self.tables.values]))

    def __call__(self, speed: float) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        dK, dC = sp.csr_matrix((self.n, self.n)), sp.csr_matrix((self.n, self.n))
        if self.tables is not None:
            k, c = self.tables.blocks(speed)
            dK = _lateral(self.n, self.tables.nodes, k - self._base[0])
            dC = _lateral(self.n, self.tables.nodes, c - self._base[1])
        if self.K2 is not None:
            dK = (dK + (speed ** 2 - self.speed0 ** 2) * self.K2).tocsr()
        return dK, dC


def build_model(scene: Scene) -> RotorModel:
    """Assemble the linear rotor model of a rotor scene.

    Parameters
    ----------
    scene : Scene
        A scene with ``kind == "rotor"``.

    Returns
    -------
    RotorModel
    """
    opts = scene.rotor
    theory = opts.theory if opts else "timoshenko"
    arrays = _shaft_arrays(scene)
    parallel = arrays.pop("parallel")
    n_el = len(arrays["L"])
    left = np.cumsum(~parallel) - 1  # a sleeve lies on the nodes of the element before it
    kappa = None
    if opts and opts.shear_coefficient > 0:
        kappa = np.full(n_el, opts.shear_coefficient)
    beam = BeamFamily(nodes=np.stack([left, left + 1], axis=1), kappa=kappa,
                      options=BeamOptions(shear=theory == "timoshenko",
                                          rotary_inertia=opts.rotary_inertia if opts else True,
                                          gyroscopic=opts.gyroscopic if opts else True), **arrays)
    n_shaft = int(left[-1]) + 2
    n_support = _support_nodes(scene, n_shaft)
    elastic = [i for i, d in enumerate(scene.disk) if d.connection == "elastic"]
    disk_nodes = np.array([d.node for d in scene.disk], dtype=np.int64)
    disk_nodes[elastic] = n_shaft + n_support + np.arange(len(elastic))
    m, Id, Ip, profiles = _disk_properties(scene)
    disks = DiskFamily(disk_nodes, m, Id, Ip)
    bearings = _bearings(scene)
    n = 6 * (n_shaft + n_support + len(elastic))
    Kshaft = beam.stiffness(opts.axial_force if opts else 0.0)
    conn_dofs = np.zeros((0, 12), dtype=np.int64)
    conn = np.zeros((0, 12, 12))
    if elastic:
        ds = [scene.disk[i] for i in elastic]
        conn = connection_stiffness(*(np.array([d[k] for d in ds]) for k in ("c_u", "c_theta", "c_3", "c_phi")))
        shaft_nodes = np.array([d.node for d in ds], dtype=np.int64)
        conn_dofs = np.concatenate([shaft_nodes[:, None] * 6 + np.arange(6), disks.dofs[elastic]], axis=1)
    rigid = np.ones(len(scene.disk), bool)
    flexible = None
    if scene.sheave is not None and scene.sheave.flexibility != "rigid":
        from cvtfem.machines.sheave import flexible_sheaves

        flexible = flexible_sheaves(scene, disk_nodes, n)
        rigid[list(flexible.disks)] = False
        n += len(flexible.kinds)
    M = assemble(n, [(beam.mass(), beam.dofs), (disks.mass()[rigid], disks.dofs[rigid]),
                     (bearings.mass(), bearings.dofs), *(flexible.mass if flexible else ())])
    K = assemble(n, [(Kshaft, beam.dofs), *bearings.relative(bearings.stiffness()), (conn, conn_dofs),
                     *(flexible.stiffness if flexible else ())])
    beta = opts.damping_beta if opts else 0.0
    C = assemble(n, [*bearings.relative(bearings.damping()), (beta * Kshaft, beam.dofs),
                     *(flexible.damping if flexible else ())])
    G = assemble(n, [(beam.gyroscopic(), beam.dofs), (disks.gyroscopic()[rigid], disks.dofs[rigid]),
                     (bearings.gyroscopic(), bearings.dofs), *(flexible.gyroscopic if flexible else ())])
    K2 = assemble(n, flexible.spin_stiffness) if flexible else None
    z = np.concatenate([[0.0], np.cumsum(arrays["L"][~parallel]), np.zeros(n_support + len(elastic))])
    z[n_shaft + n_support:] = z[[scene.disk[i].node for i in elastic]]
    z[n_shaft:n_shaft + n_support] = _support_positions(scene, z, n_shaft, n_support)
    speed = opts.speed if opts else 0.0
    if K2 is not None:  # K holds the spinning sheaves' stiffness at the model's speed
        K = (K + speed ** 2 * K2).tocsr()
    tables = _speed_tables(scene)
    if tables is not None:  # M, K, C hold the tabulated coefficients at the model's speed
        Kb, Cb = (_lateral(n, tables.nodes, X) for X in tables.blocks(speed))
        K, C = (K + Kb).tocsr(), (C + Cb).tocsr()
    return RotorModel(M, K, C, G, z, beam, disks, bearings, profiles, speed,
                      tuple(d.node for d in scene.disk), tuple(flexible.kinds) if flexible else (),
                      tables, tuple(flexible.diameters) if flexible else (), K2, flexible.faces if flexible else ())


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of a rotor model: the beam carries all nodal DOFs."""
    nodes = sum(s.repeat for s in scene.shaft if not s.parallel) + 1
    theory = scene.rotor.theory if scene.rotor else "timoshenko"
    shaft, bearings = _output_specs(nodes, len(scene.bearing))
    parts = [Layout("shaft", f"{theory}-beam", 6 * nodes, outputs=shaft, note=f"{nodes} nodes x 6")]
    if scene.disk:
        extra = sum(d.connection == "elastic" for d in scene.disk)
        parts.append(Layout("disks", "rigid-disk", 6 * extra,
                            note=f"{len(scene.disk)} disks on shaft nodes, {extra} elastically connected"))
    flexibility = scene.sheave.flexibility if scene.sheave is not None else "rigid"
    if flexibility != "rigid":
        count = sum(d.geometry == "sheave" for d in scene.disk)
        size = (4 + 2 * max(scene.sheave.model_diameters - 1, 0)) * scene.sheave.modes * count \
            if flexibility == "reduced" else None
        parts.append(Layout("sheaves", f"craig-bampton-sheave ({flexibility})",
                            size if size is not None else build_model(scene).n_dof - 6 * nodes - 6 * sum(
                                d.connection == "elastic" for d in scene.disk) - 6 * _support_nodes(scene, nodes),
                            note=f"{count} sheaves: modal coordinates of n = 0 (axial, torsion), n = 1 (x, y)"
                                 + (f" and the waves of n = 2..{scene.sheave.model_diameters}"
                                    if scene.sheave.model_diameters > 1 else "")))
    if scene.bearing:
        supports = _support_nodes(scene, nodes)
        parts.append(Layout("bearings", "bearing", 6 * supports, outputs=bearings,
                            note=f"{len(scene.bearing)} bearings, {supports} support nodes x 6"))
    return tuple(parts)
