"""Torsional network scenes -> :class:`TorsionalNetwork`, its time-domain :class:`TorsionalModel` and
layout (spec section 8.1).

Converts to circumferential coordinates at each shaft's gear radius ``r``:
``m = I / r^2``, ``b = b_phi / r^2``, shaft ``c = k_phi / r^2``, forces
``q = M / r``; mesh links are already in N/m along the pitch line.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from cvtfem.assembly.model import Linearization, ModelBase, StateLayout
from cvtfem.assembly.numbering import through_numbering
from cvtfem.elements.base import Block, Layout
from cvtfem.elements.torsional import BACKLASH, GAP, LINEAR, TorsionalNetwork, link_energy, link_force
from cvtfem.errors import InputError
from cvtfem.outputs import OutputSpec
from cvtfem.scene.loader import Scene
from cvtfem.scene.schema.base import validate
from cvtfem.scene.schema.torsional import PERIODIC, link_names

_LAW = {"shaft": LINEAR, "damper": LINEAR, "mesh": LINEAR, "backlash": BACKLASH, "gap": GAP}


def periodic_settings(scene: Scene) -> Any:
    """The scene's ``[periodic]`` table, or its defaults when absent."""
    from cvtfem.scene.node import Node

    return scene.periodic if scene.periodic is not None else Node(validate(PERIODIC, {}, "periodic"))


def _load_coefficients(load: Any, radius: float) -> dict[int, complex]:
    """Complex coefficients ``Q_n`` (N) of one load, ``q = sum Re(Q_n e^{i n w t})``."""
    out: dict[int, complex] = {0: load.mean / radius}
    if load.samples:
        c = np.fft.rfft(np.asarray(load.samples, float)) / len(load.samples)
        out[0] = c[0].real / radius + out[0]
        for n in range(1, len(c)):
            out[n] = out.get(n, 0) + (2 * c[n] if 2 * n != len(load.samples) else c[n]) / radius
        return out
    phases = load.phases or (0.0,) * len(load.orders)
    for n, A, ph in zip(load.orders, load.amplitudes, phases):
        out[n] = out.get(n, 0) + A * np.exp(1j * ph) / radius
    return out


def _check_grounded(names: tuple[str, ...], i: np.ndarray, j: np.ndarray, k: np.ndarray) -> None:
    """InputError unless every disk is tied to ground through links of non-zero stiffness (a floating group
    has no mean angle: the harmonic-0 equations of the periodic solution are singular)."""
    S = len(names)
    stiff = k > 0
    ends = np.where(j >= 0, j, S)   # node S stands for the ground
    graph = sp.coo_matrix((np.ones(int(stiff.sum())), (i[stiff], ends[stiff])), shape=(S + 1, S + 1))
    _, label = connected_components(graph, directed=False)
    floating = [name for s, name in enumerate(names) if label[s] != label[S]]
    if floating:
        raise InputError("torsional.link", floating, "must tie every disk to ground through links with stiffness "
                         "> 0 (these disks float: their mean angle is undetermined)")


def build(scene: Scene) -> TorsionalNetwork:
    """The network of a torsional scene in circumferential coordinates."""
    net = scene.torsional
    index = {d.name: s for s, d in enumerate(net.disk)}
    r = np.array([d.radius for d in net.disk])
    links = net.link
    i = np.array([index[link.a] for link in links], int)
    j = np.array([-1 if link.b == "ground" else index[link.b] for link in links], int)
    rot = np.array([link.kind in ("shaft", "damper") for link in links])
    scale = np.where(rot, 1 / r[i] ** 2, 1.0)
    k = np.array([link.stiffness for link in links]) * scale
    law = np.array([_LAW[link.kind] for link in links], int)
    k_in = np.where(law == LINEAR, k, [link.gap_stiffness for link in links])
    coeffs: dict[int, np.ndarray] = {}
    for load in net.load:
        s = index[load.disk]
        for n, q in _load_coefficients(load, r[s]).items():
            coeffs.setdefault(n, np.zeros(len(r), complex))[s] += q
    _check_grounded(tuple(index), i, j, k)
    orders = np.array(sorted(coeffs), int)
    Q = np.stack([coeffs[n] for n in orders], axis=1) if len(orders) else np.zeros((len(r), 0), complex)
    return TorsionalNetwork(
        names=tuple(index), m=np.array([d.inertia for d in net.disk]) / r ** 2,
        b=np.array([d.damping for d in net.disk]) / r ** 2, radius=r, link_names=tuple(link_names(net)),
        i=i, j=j, law=law, k_out=k, k_in=k_in.astype(float), h=np.array([link.clearance for link in links]),
        zone=np.array([link.zone for link in links]), d=np.array([link.damping for link in links]) * scale,
        orders=orders, Q=Q)


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of a torsional network: one coordinate per disk, one link family."""
    net = build(scene)
    topo = through_numbering(net.n_nodes, net.i, net.j)
    n_nl = int((net.law != LINEAR).sum())
    shape = ("loop (sparse LU)" if topo is None else
             f"tree, through-numbered with {len(topo.fictitious)} fictitious nodes")
    disks, links = _output_specs(net)
    return (
        Layout("disks", "torsional-disk", net.n_nodes, outputs=disks, note=f"{net.n_nodes} disks; {shape}"),
        Layout("links", "torsional-link", 0, discrete=0, outputs=links,
               note=f"{net.n_links} links ({n_nl} backlash/gap, {int((net.j < 0).sum())} "
                    f"to ground)"),
    )


def _output_specs(net: TorsionalNetwork) -> tuple[tuple[OutputSpec, ...], tuple[OutputSpec, ...]]:
    """Outputs of the disks and of the links."""
    return ((OutputSpec("disk.displacement", "m", "Circumferential displacement x = r phi.", net.n_nodes),),
            (OutputSpec("link.force", "N", "Link force along the pitch line (shaft: torque / r).", net.n_links),
             OutputSpec("link.moment", "N m", "Link moment at its first disk.", net.n_links)))


@dataclass(frozen=True)
class TorsionalModel(ModelBase):
    """Time-domain model of a torsional network: ``m x'' = q(t) - b x' - D^T (f(D x) + d D x')``.

    State ``[x (S), v (S)]`` in circumferential coordinates (m, m/s); ``omega`` (rad/s) is the base
    frequency of the loads; the backlash/gap links act through their smooth contact law.
    """

    net: TorsionalNetwork
    omega: float

    @property
    def layout(self) -> StateLayout:
        return StateLayout((Block("disk", self.net.n_nodes, "m"),))

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        disks, links = _output_specs(self.net)
        return disks + links

    @cached_property
    def _D(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        D = self.net.incidence()
        return D, D.T.tocsr()

    def initial_state(self) -> np.ndarray:
        """At rest, undeflected."""
        return np.zeros(self.size)

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[v, a]``."""
        net, (D, DT), S = self.net, self._D, self.net.n_nodes
        u, v = x[:S], x[S:]
        a = (net.load(t, self.omega)[:, 0] - net.b * v - DT @ net.forces(D @ u, D @ v)) / net.m
        return np.concatenate([v, a])

    def _tangent(self, u: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Tangent stiffness ``D^T f'(D u) D`` and damping ``diag(b) + D^T diag(d) D`` (N/m, N s/m)."""
        net, (D, DT) = self.net, self._D
        _, df = link_force(D @ u, net.law, net.k_in, net.k_out, net.h, net.zone)
        return (DT @ sp.diags(df) @ D).tocsr(), (sp.diags(net.b) + DT @ sp.diags(net.d) @ D).tocsr()

    def jac(self, t: float, x: np.ndarray) -> sp.csr_matrix:
        """Analytic ``[[0, I], [-M^-1 K_t, -M^-1 C]]`` (sparse)."""
        S = self.net.n_nodes
        K, C = self._tangent(x[:S])
        Minv = sp.diags(1 / self.net.m)
        return sp.bmat([[None, sp.eye(S)], [-Minv @ K, -Minv @ C]], format="csr")

    @property
    def jac_sparsity(self) -> sp.csr_matrix:
        """Links couple their two disks: ``|D|^T |D| + I`` in both lower blocks, identity in ``u' = v``."""
        D, DT = self._D
        S = self.net.n_nodes
        P = (abs(DT) @ abs(D) + sp.eye(S)).astype(bool)
        return sp.bmat([[None, sp.eye(S, dtype=bool)], [P, P]], format="csr")

    def linearize(self, x0: np.ndarray) -> Linearization:
        """``M = diag(m)``, ``C``, ``G = 0`` and the contact stiffness ``K = D^T f'(D u0) D`` at ``x0``."""
        S = self.net.n_nodes
        K, C = self._tangent(x0[:S])
        return Linearization(M=sp.diags(self.net.m).tocsr(), C=C, G=sp.csr_matrix((S, S)), K=K)

    def energy(self, x: np.ndarray) -> float:
        """Kinetic plus elastic energy, J."""
        net, (D, _), S = self.net, self._D, self.net.n_nodes
        u, v = x[:S], x[S:]
        V = link_energy(D @ u, net.law, net.k_in, net.k_out, net.h, net.zone)
        return float(net.m @ v ** 2 / 2 + V.sum())

    def power(self, t: float, x: np.ndarray) -> dict[str, float]:
        """Input power of the loads and dissipated power of dampers and links, W (``dE/dt = input - dissipated``)."""
        net, (D, _), S = self.net, self._D, self.net.n_nodes
        v = x[S:]
        return {"input": float(net.load(t, self.omega)[:, 0] @ v),
                "dissipated": float(net.b @ v ** 2 + net.d @ (D @ v) ** 2)}

    def outputs(self, t: float, x: np.ndarray) -> dict[str, np.ndarray]:
        """Displacements, link forces and moments (see :attr:`output_specs`)."""
        net, (D, _), S = self.net, self._D, self.net.n_nodes
        f = net.forces(D @ x[:S], D @ x[S:])
        return {"disk.displacement": x[:S].copy(), "link.force": f, "link.moment": f * net.radius[net.i]}


def build_model(scene: Scene, omega: float | None = None) -> TorsionalModel:
    """The time-domain model of a torsional scene: loads at base frequency ``omega`` (rad/s; default
    ``2 pi periodic.frequency``), the backlash and gap laws unless ``periodic.backlash`` is false."""
    cfg = periodic_settings(scene)
    omega = 2 * np.pi * cfg.frequency if omega is None else omega
    if not (np.isfinite(omega) and omega > 0):
        raise InputError("omega", omega, "must be a positive base frequency of the loads in rad/s")
    net = build(scene)
    return TorsionalModel(net if cfg.backlash else net.linearized("contact"), float(omega))
