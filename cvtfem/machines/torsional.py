"""Torsional network scenes -> :class:`TorsionalNetwork` and layout (spec section 8.1).

Converts to circumferential coordinates at each shaft's gear radius ``r``:
``m = I / r^2``, ``b = b_phi / r^2``, shaft ``c = k_phi / r^2``, forces
``q = M / r``; mesh links are already in N/m along the pitch line.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from cvtfem.assembly.numbering import through_numbering
from cvtfem.elements.base import Layout
from cvtfem.elements.torsional import BACKLASH, GAP, LINEAR, TorsionalNetwork
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
    return (
        Layout("disks", "torsional-disk", net.n_nodes,
               outputs=(OutputSpec("disk.displacement", "m", "Circumferential displacement x = r phi.",
                                   net.n_nodes),),
               note=f"{net.n_nodes} disks; {shape}"),
        Layout("links", "torsional-link", 0, discrete=0,
               outputs=(OutputSpec("link.force", "N", "Link force along the pitch line (shaft: torque / r).",
                                   net.n_links),
                        OutputSpec("link.moment", "N m", "Link moment at its first disk.", net.n_links)),
               note=f"{net.n_links} links ({n_nl} backlash/gap, {int((net.j < 0).sum())} "
                    f"to ground)"),
    )
