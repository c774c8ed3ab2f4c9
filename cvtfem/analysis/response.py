"""Forced response of a rotor scene: unbalance response over speed, order response and order map.

Numerics in :mod:`cvtfem.modal.forced`; this module builds the rotor model, the loads and the outputs.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cvtfem.errors import InputError
from cvtfem.machines.rotor import RotorModel, build_model
from cvtfem.modal import ModalProblem, campbell, shaft_orders
from cvtfem.modal.campbell import Campbell
from cvtfem.modal.forced import ModalBasis, displacement, orbit, unbalance_response
from cvtfem.scene.loader import Scene

#: Machine kinds this analysis supports.
SUPPORTED = ("rotor",)


@dataclass(frozen=True)
class Unbalance:
    """Unbalance ``me`` (kg m) at angle ``phase`` (rad) on the disk seated at shaft node ``node``."""

    node: int
    me: float
    phase: float


@dataclass(frozen=True)
class Response:
    """Unbalance response at a node over speed and, with orders, the order response and map.

    Attributes
    ----------
    speeds : array (s,), rad/s
    node : int
    x, y : complex arrays (s,)
        Amplitudes of u1, u2 at the node, m (motion ``Re(x e^{i Omega t})``).
    major, minor : arrays (s,)
        Orbit semi-axes, m; minor < 0 for a backward orbit.
    orders : tuple of float
    order_amplitude : array (s, orders)
        ``|(u1, u2)|`` at the node per unit force (m/N) along ``w = k Omega``, force in x at ``force_node``.
    freqs : array (w,), rad/s
    map : array (s, w)
        ``|(u1, u2)|`` per unit force (m/N) over speed and frequency.
    campbell : Campbell or None
        Natural frequencies over the speeds with the order lines and their crossings.
    """

    speeds: np.ndarray
    node: int
    x: np.ndarray
    y: np.ndarray
    major: np.ndarray
    minor: np.ndarray
    orders: tuple[float, ...] = ()
    force_node: int = -1
    order_amplitude: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    freqs: np.ndarray = field(default_factory=lambda: np.zeros(0))
    map: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    campbell: Campbell | None = None

    def to_dict(self) -> dict[str, object]:
        """JSON-ready data (amplitudes in m, phases in deg)."""
        out: dict[str, object] = {
            "speeds_rad_s": self.speeds.tolist(), "node": self.node,
            "amplitude_x_m": np.abs(self.x).tolist(), "phase_x_deg": np.degrees(np.angle(self.x)).tolist(),
            "amplitude_y_m": np.abs(self.y).tolist(), "phase_y_deg": np.degrees(np.angle(self.y)).tolist(),
            "major_m": self.major.tolist(), "minor_m": self.minor.tolist()}
        if self.orders:
            out.update({"orders": list(self.orders), "force_node": self.force_node,
                        "order_amplitude_m_per_N": self.order_amplitude.tolist(),
                        "map_freqs_rad_s": self.freqs.tolist(), "map_m_per_N": self.map.tolist()})
        if self.campbell is not None:
            out["crossings"] = list(self.campbell.crossings)
        return out

    def csv_rows(self) -> list[list[str]]:
        """Header and one row per speed: speed, |x|, phase x, |y|, phase y, major, minor."""
        rows = [["speed_rad_s", "amplitude_x_m", "phase_x_deg", "amplitude_y_m", "phase_y_deg", "major_m",
                 "minor_m"]]
        for i, s in enumerate(self.speeds):
            rows.append([f"{s:.9g}", f"{abs(self.x[i]):.9g}", f"{np.degrees(np.angle(self.x[i])):.6g}",
                         f"{abs(self.y[i]):.9g}", f"{np.degrees(np.angle(self.y[i])):.6g}",
                         f"{self.major[i]:.9g}", f"{self.minor[i]:.9g}"])
        return rows


def write_results(res: Response, path: str, scene: Scene) -> None:
    """An HDF5 results file (kind "response", :mod:`cvtfem.io.results`) with the response as whole arrays."""
    from cvtfem.io.results import ResultsWriter

    with ResultsWriter(path, scene.to_toml(), "response", ()) as w:
        w.set_stats({"node": res.node, "force_node": res.force_node})
        w.add_array("response/speeds", res.speeds, "rad/s", "Spin speeds.")
        w.add_array("response/x", res.x, "m", "Complex amplitude of u1 at the node: u1 = Re(x e^{i Omega t}).")
        w.add_array("response/y", res.y, "m", "Complex amplitude of u2 at the node.")
        w.add_array("response/major", res.major, "m", "Orbit major semi-axis.")
        w.add_array("response/minor", res.minor, "m", "Orbit minor semi-axis, < 0 backward.")
        if res.orders:
            w.add_array("response/orders", np.asarray(res.orders), "-", "Excitation orders k (w = k Omega).")
            w.add_array("response/order_amplitude", res.order_amplitude, "m/N",
                        "|(u1, u2)| per unit x force along each order line, (speeds, orders).")
            w.add_array("response/map_freqs", res.freqs, "rad/s", "Frequency lines of the order map.")
            w.add_array("response/map", res.map, "m/N", "|(u1, u2)| per unit x force, (speeds, freqs).")
            w.add_array("response/campbell_wd", res.campbell.wd, "rad/s", "Tracked damped natural frequencies.")


def rotor_of(scene: Scene) -> RotorModel:
    """The rotor model of a scene; InputError naming the supported kinds otherwise."""
    if scene.kind not in SUPPORTED:
        raise InputError("SCENE", scene.source, f"must be a rotor scene ([[shaft]] tables) for the forced "
                         f"response (supported: {', '.join(SUPPORTED)}), this one is {scene.kind!r}")
    return build_model(scene)


def _node(model: RotorModel, node: int, where: str) -> int:
    if not 0 <= node < model.n_shaft_nodes:
        raise InputError(where, node, f"must be a shaft node 0..{model.n_shaft_nodes - 1}")
    return node


def scene_response(scene: Scene, unbalances: list[Unbalance], speeds: np.ndarray, node: int,
                   orders: tuple[float, ...] = (), force_node: int | None = None, n_freqs: int = 200,
                   n_modes: int = 12) -> Response:
    """Unbalance response at ``node`` and, with ``orders``, the order response and map of a rotor scene.

    Parameters
    ----------
    unbalances : list of Unbalance
    speeds : array (s,), rad/s, increasing, >= 0
    node : int
        Shaft node whose x, y motion is reported.
    orders : tuple of float
        Excitation orders k (lines ``w = k Omega``) of a unit force fixed in x at ``force_node``
        (default: the first unbalance's node); e.g. the link-passing order ``2 pi r / l_link``.
    n_freqs : int
        Frequency lines of the order map, from 0 to the highest order line.
    n_modes : int
        Modes of the modal superposition (order response and map) and of the Campbell overlay.
    """
    model = rotor_of(scene)
    speeds = np.asarray(speeds, dtype=float)
    if len(speeds) < 2 or np.any(speeds < 0) or np.any(np.diff(speeds) <= 0):
        raise InputError("--speeds", speeds.tolist()[:5], "must be two or more increasing speeds >= 0")
    if not unbalances:
        raise InputError("--unbalance", [], "needs at least one unbalance NODE:ME:PHASE")
    node = _node(model, node, "--node")
    for u in unbalances:
        _node(model, u.node, "--unbalance")
    n = model.n_dof
    load = sum(model.unbalance_load(u.node, u.me, u.phase) for u in unbalances)
    out = displacement([6 * node, 6 * node + 1], n, ("u1", "u2"))
    xy = unbalance_response(model.M, model.K, model.C, model.G, load, out, speeds, speed_terms=model.speed_terms)
    major, minor = orbit(xy[:, 0], xy[:, 1])
    if not orders:
        return Response(speeds, node, xy[:, 0], xy[:, 1], major, minor)
    fnode = _node(model, unbalances[0].node if force_node is None else force_node, "--force-node")
    f = np.abs(model.unbalance_load(fnode, 1.0, 0.0).real)  # unit force in x at the disk (or shaft) node
    k = np.asarray(orders, dtype=float)
    if np.any(k <= 0) or not np.all(np.isfinite(k)):
        raise InputError("--orders", list(orders), "must be positive numbers (lines k x speed)")
    basis = ModalBasis(model.M, model.K, model.C, model.G, f, n_modes, modes="sweep",
                       basis_speeds=(speeds[0], (speeds[0] + speeds[-1]) / 2, speeds[-1]))
    freqs = np.linspace(0.0, k.max() * speeds[-1], n_freqs)
    amp, grid = np.zeros((len(speeds), len(k))), np.zeros((len(speeds), n_freqs))
    for i, s in enumerate(speeds):  # |(u1, u2)| per unit force; one modal basis for the sweep
        amp[i] = np.linalg.norm(basis.frf(out, k * s, s)[..., 0], axis=1)
        grid[i] = np.linalg.norm(basis.frf(out, freqs, s)[..., 0], axis=1)
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, speed_terms=model.speed_terms)
    diagram = campbell(problem, speeds, n_modes, shaft_orders(tuple(orders)))
    return Response(speeds, node, xy[:, 0], xy[:, 1], major, minor, tuple(orders), fnode, amp, freqs, grid,
                    diagram)
