"""What a time run reports at its end: :class:`RunSummary` (the samples are the model's ``outputs``)."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

EFFICIENCY_WINDOW = 0.05  # s, moving average of the efficiency (section 6.1)


@dataclass
class RunSummary:
    """What a run reports (also written as ``--summary-json``)."""

    scene: str
    model: str
    n_coordinates: int
    simulated_time_s: float
    wall_time_s: float
    ratio: float
    target_ratio: float
    input_speed_rpm: float
    output_speed_rpm: float
    target_output_speed_rpm: float
    efficiency: float | None  # None: undefined (no input work over the window), see efficiency_note
    efficiency_kinetic: float | None
    slip_speed_m_s: list[float]
    clamping_force_N: list[float]
    status: str
    solver: dict[str, Any] = field(default_factory=dict)
    results: str = ""
    efficiency_note: str = ""  # why efficiency is None, else empty
    off_face_fraction: list[float] | None = None  # refined contact: share of contacts off the pin end face at the end
    process_cpu_time_s: float = 0.0  # CPU time of this process's stepping (since its start or its resume), s

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def summarise(scene, loop, last, window, t_end, wall, stats, status) -> RunSummary:
    """Final ratio and speeds (raw, at the last sample ``last = (t, x)``), efficiency over the last window
    from the work integrals (``window = (t, x)``: the sample that starts it)."""
    t_last, x = last
    t_j, x_j = window
    _, info = loop.evaluate(t_last, x)
    w1d, _, i_d = info["targets"]
    W0, W1 = loop.split(x_j)[3], loop.split(x)[3]
    dW = W1 - W0
    dE = loop.energy(x) - loop.energy(x_j)
    eff: float | None = None
    eff_kin: float | None = None
    note = ""
    if dW[0] > 0:
        eff, eff_kin = float(dW[1] / dW[0]), float(1 - (dW[0] - dW[1] - dE) / dW[0])
    else:  # zero driving torque (or speed): output over input is 0/0
        note = (f"undefined: input work {dW[0]:.3g} J over the last {t_last - t_j:.3g} s (driving torque "
                f"{info['M'][0]:.3g} N m); efficiency needs positive input power")
    rpm = 30 / math.pi
    w = info["w"]
    off = off_face_fraction(scene, loop, t_last, x)
    return RunSummary(off_face_fraction=off, scene=scene.source, model=scene.cvt.model, n_coordinates=loop.n2,
                      simulated_time_s=float(t_last), wall_time_s=wall, ratio=float(w[0] / w[1]), target_ratio=i_d,
                      input_speed_rpm=float(w[0] * rpm), output_speed_rpm=float(w[1] * rpm),
                      target_output_speed_rpm=float(w1d / i_d * rpm), efficiency=eff,
                      efficiency_kinetic=eff_kin, efficiency_note=note, slip_speed_m_s=[float(s) for s in info["slip"]],
                      clamping_force_N=[float(f) for f in info["F"]], status=status, solver=stats)


def off_face_fraction(scene, loop, t: float, x) -> list[float] | None:
    """Share of the pin ends touching each shaft (driving, driven) whose refined (H2) contact point lies farther than
    the face half-height ``width_n / 2`` from the pin axis (``contact.face_offset``) at ``(t, x)``; None for a model
    without the output."""
    if "contact.face_offset" not in {o.name for o in getattr(loop, "output_specs", ())}:
        return None
    from cvtfem.machines.cvt import pin_section

    out = loop.outputs(t, x)
    x_off = np.asarray(out["contact.face_offset"]).reshape(-1, 2)
    on = np.asarray(out["contact.normal_force"]).reshape(-1, 2) > 0
    h = 0.5 * pin_section(scene).width_n
    return [float(((x_off[:, k] > h) & on[:, k]).sum() / max(on[:, k].sum(), 1)) for k in (0, 1)]
