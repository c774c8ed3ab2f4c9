"""Noise spectra of a rotor scene over a speed sweep: order map, excitation lines, ERP of the sheave faces.

Excitation sources (:mod:`cvtfem.modal.excitation`): pin entry of a (randomised) chain at the sheaves' contact arc,
torque-ripple orders, user lines.  Responses by modal superposition on one basis for the whole sweep
(:class:`~cvtfem.modal.forced.ModalBasis`, ``modes="sweep"``); ERP from the sheaves' axial and tilt motion
(:mod:`cvtfem.modal.radiation`), and for flexible sheaves their own modes' face motion.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from cvtfem.analysis.response import rotor_of
from cvtfem.errors import InputError
from cvtfem.machines.rotor import RotorModel
from cvtfem.modal import ModalProblem, campbell, shaft_orders
from cvtfem.modal.campbell import Campbell
from cvtfem.modal.excitation import Lines, a_weighting_db, pin_entry_lines
from cvtfem.modal.forced import ModalBasis, OutputMap, displacement
from cvtfem.modal.radiation import Face, annulus_panels, erp, power_db, rigid_annulus
from cvtfem.scene.loader import Scene

#: Highest frequency of a map or an excitation line, rad/s (1 GHz: far above any structural mode).
FMAX = 2 * np.pi * 1e9
#: DOF names of a rotor node, in order.
DOF_NAMES = ("u1", "u2", "u3", "theta1", "theta2", "phi")


@dataclass(frozen=True)
class PinEntry:
    """Pin entry of a chain on the shaft's sheaves.

    Attributes
    ----------
    link_lengths : array (N,), m
        The chain's links in order (e.g. :func:`cvtfem.elements.link_pattern.link_lengths`).
    radius : float, m
        Pitch radius on this shaft (chain speed ``Omega radius``).
    impulse : float, N s
        Impulse of one entry on each sheave, along the face normal (radial part ``sin(cone_angle)``, axial part
        ``cos(cone_angle)`` pushing the sheave away from the groove).
    angle : float, rad
        Angle of the entry point on the sheave (from e1 towards e2).
    n_link_harmonics : int
        Lines up to this multiple of f_link.
    """

    link_lengths: np.ndarray
    radius: float
    impulse: float = 1e-3
    angle: float = 0.0
    n_link_harmonics: int = 3


@dataclass(frozen=True)
class Ripple:
    """Torque ripple ``torque`` (N m amplitude) at shaft order ``order`` on the disk (or shaft) at node ``node``."""

    node: int
    order: float
    torque: float


@dataclass(frozen=True)
class UserLine:
    """A user force line: ``amplitude e^{i phase}`` (N or N m) on DOF ``dof`` of node ``node`` at
    ``w = order Omega + 2 pi freq_hz``."""

    node: int
    dof: str
    order: float
    freq_hz: float
    amplitude: float
    phase: float


@dataclass(frozen=True)
class Spectrum:
    """Order map, line responses and ERP over speed.

    Attributes
    ----------
    speeds : array (s,), rad/s
    node : int
        Node whose ``|(u1, u2, u3)|`` the map and the order responses show.
    map_input : str
        What drives the map: the pin-entry force distribution (per N s of impulse) or a unit x force.
    freqs : array (w,), rad/s
    map : array (s, w)
        ``|(u1, u2, u3)|`` per unit input, m/N (or m/(N s) per unit impulse rate).
    orders : tuple of float
        Lines drawn on the map (shaft orders).
    order_amplitude : array (s, orders)
        The map's value along each order line (0 at speed 0).
    line_labels : tuple of str (l,)
    line_freqs : array (s, l), rad/s
    line_amplitude : array (s, l)
        ``|(u1, u2, u3)|`` at the node per line, m.
    line_erp : array (s, l)
        ERP of the sheave faces per line, W.
    erp_db, erp_a_db : arrays (s,)
        Total ERP (sum over lines) in dB re 1 pW, and A-weighted.
    campbell : Campbell
    wmax : float, rad/s
        Highest natural frequency in the modal basis: lines and map above it rest on the residual vectors alone
        (raise ``n_modes`` to cover them).
    """

    speeds: np.ndarray
    node: int
    map_input: str
    freqs: np.ndarray
    map: np.ndarray
    orders: tuple[float, ...]
    order_amplitude: np.ndarray
    line_labels: tuple[str, ...] = ()
    line_freqs: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    line_amplitude: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    line_erp: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    erp_db: np.ndarray = field(default_factory=lambda: np.zeros(0))
    erp_a_db: np.ndarray = field(default_factory=lambda: np.zeros(0))
    campbell: Campbell | None = None
    wmax: float = 0.0

    def to_dict(self) -> dict[str, object]:
        """JSON-ready data (SI units; ERP levels in dB re 1 pW)."""
        out: dict[str, object] = {
            "speeds_rad_s": self.speeds.tolist(), "node": self.node, "map_input": self.map_input,
            "map_freqs_rad_s": self.freqs.tolist(), "map": self.map.tolist(), "orders": list(self.orders),
            "order_amplitude": self.order_amplitude.tolist(), "line_labels": list(self.line_labels),
            "line_freqs_rad_s": self.line_freqs.tolist(), "line_amplitude_m": self.line_amplitude.tolist(),
            "line_erp_w": self.line_erp.tolist(), "erp_db": _finite(self.erp_db), "erp_a_db": _finite(self.erp_a_db),
            "basis_wmax_rad_s": self.wmax}
        if self.campbell is not None:
            out["crossings"] = list(self.campbell.crossings)
        return out


def _finite(x: np.ndarray) -> list:
    return [float(v) if np.isfinite(v) else None for v in x]


def write_results(res: Spectrum, path: str, scene: Scene) -> None:
    """An HDF5 results file (kind "spectrum", :mod:`cvtfem.io.results`) with the spectra as whole arrays."""
    from cvtfem.io.results import ResultsWriter

    with ResultsWriter(path, scene.to_toml(), "spectrum", ()) as w:
        w.set_stats({"node": res.node, "map_input": res.map_input, "basis_wmax_rad_s": res.wmax})
        w.add_array("spectrum/speeds", res.speeds, "rad/s", "Spin speeds.")
        w.add_array("spectrum/map_freqs", res.freqs, "rad/s", "Frequency lines of the order map.")
        w.add_array("spectrum/map", res.map, "m/N", f"|(u1, u2, u3)| at the node per unit {res.map_input}.")
        w.add_array("spectrum/orders", np.asarray(res.orders, dtype=float), "-", "Order lines drawn (w = k Omega).")
        w.add_array("spectrum/order_amplitude", res.order_amplitude, "m/N", "The map along each order line.")
        if res.line_labels:
            w.add_array("spectrum/line_freqs", res.line_freqs, "rad/s", "Excitation line frequencies, (speeds, lines).")
            w.add_array("spectrum/line_amplitude", res.line_amplitude, "m", "|(u1, u2, u3)| at the node per line.")
            w.add_array("spectrum/line_erp", res.line_erp, "W", "ERP of the sheave faces per line.")
            w.add_array("spectrum/erp_db", res.erp_db, "dB re 1 pW", "Total ERP of the sheave faces.")
            w.add_array("spectrum/erp_a_db", res.erp_a_db, "dB(A) re 1 pW", "A-weighted total ERP.")
        w.add_array("spectrum/campbell_wd", res.campbell.wd, "rad/s", "Tracked damped natural frequencies.")


def _node(model: RotorModel, node: int, where: str) -> int:
    if not 0 <= node < model.n_shaft_nodes:
        raise InputError(where, node, f"must be a shaft node 0..{model.n_shaft_nodes - 1}")
    return node


def _body_node(model: RotorModel, node: int) -> int:
    """The model node carrying the disk seated on shaft node ``node`` (its own node if elastic), else ``node``."""
    on = np.flatnonzero(np.asarray(model.seats) == node)
    return int(model.disks.nodes[on[0]]) if len(on) else node


def sheaves(scene: Scene) -> list[int]:
    """Indices of the scene's disks with a sheave geometry (they carry the chain and radiate)."""
    return [i for i, d in enumerate(scene.disk) if d.geometry == "sheave"]


def pin_entry_force(scene: Scene, model: RotorModel, pin: PinEntry) -> np.ndarray:
    """Generalised force (N, N m per N s of impulse rate) of one pin entry on every sheave of the scene:
    ``-(sin(alpha) e_r + facing cos(alpha) e3)`` at the point ``radius e_r(angle)`` of each sheave (alpha its cone
    angle; facing +1 for '+z'), i.e. the force and its moment ``p x F`` about the sheave's centre."""
    idx = sheaves(scene)
    if not idx:
        raise InputError("--chain", scene.source, "needs a scene with sheaves (disks with geometry = 'sheave')")
    f = np.zeros(model.n_dof)
    c, s = np.cos(pin.angle), np.sin(pin.angle)
    for i in idx:
        d = scene.disk[i]
        if not d.hub_diameter / 2 <= pin.radius <= d.outer_diameter / 2:
            raise InputError("--chain radius", pin.radius, f"must lie on the sheave face ({d.hub_diameter / 2:g} .. "
                             f"{d.outer_diameter / 2:g} m)")
        sigma = 1.0 if d.facing == "+z" else -1.0
        fr, fa = -np.sin(d.cone_angle), -sigma * np.cos(d.cone_angle)
        q = 6 * int(model.disks.nodes[i])
        f[q: q + 5] += [fr * c, fr * s, fa, pin.radius * s * fa, -pin.radius * c * fa]
    return f


def sheave_faces(scene: Scene, model: RotorModel) -> Face:
    """Both faces of every sheave as annuli from the hub to the outer radius (projected on the radial plane): the
    rigid disc's motion, plus a flexible sheave's own modes (:attr:`RotorModel.sheave_faces`)."""
    faces = []
    for i in sheaves(scene):
        d = scene.disk[i]
        q = 6 * int(model.disks.nodes[i])
        face = rigid_annulus(model.n_dof, (q + 2, q + 3, q + 4), d.hub_diameter / 2, d.outer_diameter / 2)
        own = [f for f in model.sheave_faces if f.disk == i]
        if own:
            r, a, _ = annulus_panels(d.hub_diameter / 2, d.outer_diameter / 2)
            face = Face(face.area, (face.N + sum(f.rows(model.n_dof, r, a) for f in own)).tocsr())
        faces += [face, face]
    if not faces:
        raise InputError("SCENE", scene.source, "needs sheaves (disks with geometry = 'sheave') for the ERP")
    return Face(np.concatenate([f.area for f in faces]), sp.vstack([f.N for f in faces]).tocsr())


def read_user_lines(path: str) -> list[UserLine]:
    """User lines from a CSV file with the header ``node,dof,order,freq_hz,amplitude,phase_deg``."""
    want = ["node", "dof", "order", "freq_hz", "amplitude", "phase_deg"]
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except OSError as err:
        raise InputError("--lines", path, f"must be a readable CSV file ({err.strerror})") from None
    if not rows or [h.strip() for h in rows[0]] != want:
        raise InputError("--lines", path, f"must start with the header {','.join(want)}")
    lines = []
    for k, row in enumerate(rows[1:], start=2):
        try:
            node, dof, order, fhz, amp, ph = (v.strip() for v in row)
            line = UserLine(int(node), dof, float(order), float(fhz), float(amp), np.radians(float(ph)))
        except ValueError:
            raise InputError(f"--lines row {k}", row, "must hold node,dof,order,freq_hz,amplitude,phase_deg") from None
        if dof not in DOF_NAMES:
            raise InputError(f"--lines row {k} dof", dof, f"must be one of {', '.join(DOF_NAMES)}")
        if not all(np.isfinite([line.order, line.freq_hz, line.amplitude, line.phase])) or line.order < 0 \
                or line.freq_hz < 0 or line.order + line.freq_hz <= 0:
            raise InputError(f"--lines row {k}", row, "must hold finite order, freq_hz >= 0, not both 0")
        lines.append(line)
    if not lines:
        raise InputError("--lines", path, "must hold at least one line after the header")
    return lines


def excitation(scene: Scene, model: RotorModel, pin: PinEntry | None, ripples: list[Ripple],
               user: list[UserLine]) -> list[Lines]:
    """The scene's excitation sources as line sets, each with its force distribution."""
    out = []
    if pin is not None:
        k, orders, amp = pin_entry_lines(pin.link_lengths, pin.radius, pin.impulse, pin.n_link_harmonics)
        out.append(Lines("pin entry", orders, np.zeros(len(k)), amp, "speed",
                         pin_entry_force(scene, model, pin)))
    for r in ripples:
        _node(model, r.node, "--ripple")
        if not (r.order > 0 and np.isfinite(r.order) and np.isfinite(r.torque)):
            raise InputError("--ripple", (r.node, r.order, r.torque), "needs an order > 0 and a finite torque")
        f = np.zeros(model.n_dof)
        f[6 * _body_node(model, r.node) + 5] = 1.0
        out.append(Lines(f"ripple {r.order:g}x node {r.node}", np.array([r.order]), np.zeros(1),
                         np.array([r.torque], dtype=complex), "const", f))
    for u in user:
        _node(model, u.node, "--lines node")
        f = np.zeros(model.n_dof)
        f[6 * _body_node(model, u.node) + DOF_NAMES.index(u.dof)] = 1.0
        out.append(Lines(f"{u.dof} node {u.node} {u.order:g}x+{u.freq_hz:g}Hz", np.array([u.order]),
                         np.array([2 * np.pi * u.freq_hz]), np.array([u.amplitude * np.exp(1j * u.phase)]), "const",
                         f))
    return out


def scene_spectrum(scene: Scene, speeds: np.ndarray, node: int, orders: tuple[float, ...] = (),
                   pin: PinEntry | None = None, ripples: list[Ripple] | None = None,
                   user: list[UserLine] | None = None, force_node: int | None = None, n_freqs: int = 200,
                   fmax: float | None = None, n_modes: int = 12) -> Spectrum:
    """Order map, line responses and ERP of a rotor scene over ``speeds``.

    Parameters
    ----------
    speeds : array (s,), rad/s, increasing, >= 0
    node : int
        Shaft node whose ``|(u1, u2, u3)|`` is reported (map, order and line responses).
    orders : tuple of float
        Extra order lines drawn on the map (the sources' orders are drawn too).
    pin, ripples, user : excitation sources (:class:`PinEntry`, :class:`Ripple`, :class:`UserLine`).
    force_node : int
        Without pin entry the map is driven by a unit x force at this node (default: ``node``).
    n_freqs, fmax : map lines from 0 to ``fmax`` rad/s (default: the highest drawn order line at the top speed).
    n_modes : int
        Modes of the superposition (right and left at the ends and the middle of the sweep) and of the Campbell
        diagram.
    """
    model = rotor_of(scene)
    speeds = np.asarray(speeds, dtype=float)
    if len(speeds) < 2 or np.any(speeds < 0) or np.any(np.diff(speeds) <= 0):
        raise InputError("--speeds", speeds.tolist()[:5], "must be two or more increasing speeds >= 0")
    node = _node(model, node, "--node")
    k = np.asarray(orders, dtype=float)
    if np.any(k <= 0) or not np.all(np.isfinite(k)):
        raise InputError("--orders", list(orders), "must be positive numbers (lines k x speed)")
    sources = excitation(scene, model, pin, list(ripples or ()), list(user or ()))
    n = model.n_dof
    if pin is not None:
        f_map, map_input = sources[0].force, "pin-entry impulse rate (N s/s) on the sheaves"
        link = 2 * np.pi * pin.radius * len(pin.link_lengths) / float(np.sum(pin.link_lengths))
        drawn = list(k) + [j * link for j in range(1, pin.n_link_harmonics + 1)]
    else:
        fn = node if force_node is None else _node(model, force_node, "--force-node")
        f_map = np.zeros(n)
        f_map[6 * _body_node(model, fn)] = 1.0
        map_input, drawn = f"x force (N) at node {fn}", list(k)
    drawn += [float(r.order) for r in ripples or ()] + [u.order for u in user or () if u.order > 0]
    if not drawn and not sources:
        raise InputError("--orders", list(orders), "needs at least one order line or an excitation source")
    drawn = tuple(sorted(set(drawn)))
    fixed = [2 * np.pi * u.freq_hz for u in user or ()]
    if max(drawn, default=0.0) > FMAX / speeds[-1]:
        raise InputError("--orders", [float(d) for d in drawn],
                         f"must keep the lines below {FMAX / 2 / np.pi:g} Hz at the top speed")
    top = max([k * speeds[-1] for k in drawn] + fixed) if fmax is None else float(fmax)
    if not 0 < top <= FMAX:
        raise InputError("--fmax", fmax, f"must be > 0 and <= {FMAX / 2 / np.pi:g} Hz (and the speeds not all 0)")
    F = np.column_stack([f_map] + [s.force for s in sources])
    basis = ModalBasis(model.M, model.K, model.C, model.G, F, n_modes, modes="sweep",
                       basis_speeds=(speeds[0], (speeds[0] + speeds[-1]) / 2, speeds[-1]))
    out = displacement([6 * node, 6 * node + 1, 6 * node + 2], n, ("u1", "u2", "u3"))
    freqs = np.linspace(top / n_freqs, top, n_freqs)  # no 0 Hz line: a static load on a free body has no response
    ko = np.asarray(drawn)
    grid, amp = np.zeros((len(speeds), n_freqs)), np.zeros((len(speeds), len(ko)))
    for i, s in enumerate(speeds):
        grid[i] = np.linalg.norm(basis.frf(out, freqs, s, columns=[0])[..., 0], axis=1)
        if s > 0:
            amp[i] = np.linalg.norm(basis.frf(out, ko * s, s, columns=[0])[..., 0], axis=1)
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind)
    diagram = campbell(problem, speeds, n_modes, shaft_orders(drawn))
    res = Spectrum(speeds, node, map_input, freqs, grid, drawn, amp, campbell=diagram, wmax=basis.wmax())
    if not sources:
        return res
    return _lines(res, scene, model, basis, out, sources)


def _lines(res: Spectrum, scene: Scene, model: RotorModel, basis: ModalBasis, out: OutputMap,
           sources: list[Lines]) -> Spectrum:
    """The sources' lines: response at the node and ERP of the sheave faces, per speed."""
    face = sheave_faces(scene, model) if sheaves(scene) else None
    both = OutputMap(sp.vstack([out.D] + ([face.N] if face else [])).tocsr(),
                     sp.csr_matrix((out.D.shape[0] + (face.N.shape[0] if face else 0), model.n_dof)), out.names)
    labels = tuple(f"{s.label} {o:.4g}x" if s.freqs[j] == 0 else f"{s.label}" for s in sources
                   for j, o in enumerate(s.orders))
    S, nl = len(res.speeds), len(labels)
    wl, al, el = np.zeros((S, nl)), np.zeros((S, nl)), np.zeros((S, nl))
    for i, s in enumerate(res.speeds):
        col = 0
        for j, src in enumerate(sources, start=1):
            w = src.frequencies(s)
            y = np.zeros((len(w), both.D.shape[0]), dtype=complex)  # a line at 0 Hz is a static load: no vibration
            y[w > 0] = basis.frf(both, w[w > 0], s, columns=[j])[..., 0] * src.amplitudes(s)[w > 0, None]
            sl = slice(col, col + len(w))
            wl[i, sl], al[i, sl] = w, np.linalg.norm(y[:, :3], axis=1)
            if face is not None:
                el[i, sl] = _erp_of(face, y[:, 3:], w)
            col += len(w)
    weights = 10 ** (a_weighting_db(wl / (2 * np.pi)) / 10)
    return Spectrum(res.speeds, res.node, res.map_input, res.freqs, res.map, res.orders, res.order_amplitude,
                    labels, wl, al, el, power_db(el.sum(axis=1)), power_db((el * weights).sum(axis=1)), res.campbell,
                    res.wmax)


def _erp_of(face: Face, w_normal: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """ERP (W) per line from the panels' complex normal displacements ``w_normal`` (lines, panels)."""
    return erp(Face(face.area, sp.identity(len(face.area), format="csr")), w_normal.T, omega)
