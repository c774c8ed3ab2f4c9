"""Time-run driver: scene -> model -> integrate -> results file (HDF5) -> summary.

``run_scene`` builds the closed loop of a band-model CVT scene, integrates it with one small
solver factory (:func:`make_stepper`: scipy's ``OdeSolver`` classes step by step, so outputs are
sampled from the dense output, written incrementally and the progress bar advances), checks
every accepted state for NaN/inf and returns a :class:`RunSummary`.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cvtfem.errors import InputError, NumericalError

SCIPY_STEPPERS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")
EFFICIENCY_WINDOW = 0.05  # s, moving average of the efficiency (section 6.1)


def make_stepper(method: str, fun, t0: float, y0, t_end: float, rtol: float, atol: float, h: float = 0.0,
                 jac=None):
    """A step-by-step ODE solver with ``step()``, ``t``, ``y``, ``dense_output()`` and counters.

    The single place that picks the integrator: scipy's ``OdeSolver`` classes for now.
    """
    if method not in SCIPY_STEPPERS:
        raise InputError("solver.method", method, "must be one of " + ", ".join(SCIPY_STEPPERS) + " for `cvtfem run`",
                         "the cvtfem.integrate methods are not wired into the run driver yet")
    import scipy.integrate as si

    options: dict[str, Any] = {"rtol": rtol, "atol": atol}
    if h > 0:
        options["first_step"] = h
    if jac is not None and method in ("Radau", "BDF", "LSODA"):
        options["jac"] = jac
    return getattr(si, method)(fun, t0, np.asarray(y0, float), t_end, **options)


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
    efficiency: float
    efficiency_kinetic: float
    slip_speed_m_s: list[float]
    clamping_force_N: list[float]
    status: str
    solver: dict[str, Any] = field(default_factory=dict)
    results: str = ""

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def sample_outputs(loop, t: float, x) -> dict[str, Any]:
    """Named outputs (see ``cvtfem describe``) of closed-loop state ``x`` at time ``t``."""
    _, info = loop.evaluate(t, x)
    q, v, _, W = loop.split(x)
    N = np.asarray(info["N"])
    w, M, F = info["w"], info["M"], info["F"]
    P = np.array([M[0] * w[0], -M[1] * w[1], info["dissipation"], info["clamp_power"]])
    out = {"band.span_angle": q[0], "band.slip_speed": info["slip"], "band.slip_max": info["slip_max"],
           "band.mean_normal_force": N.mean(axis=-1) if N.ndim == 2 else N,
           "driving.speed": w[0], "driving.torque": M[0], "driving.clamping_force": F[0],
           "driven.speed": w[1], "driven.torque": M[1], "driven.clamping_force": F[1],
           "control.ratio_estimate": info["ratio_estimate"], "control.resistance": info["resistance"],
           "efficiency": P[1] / P[0] if P[0] else math.nan, "ratio": w[0] / w[1] if w[1] else math.nan,
           "power": P, "work": W, "energy": loop.energy(x)}
    if N.ndim == 2:
        out["band.normal_force"] = N.ravel()
    return out


def run_scene(scene, until: float | None = None, results: str | Path | None = None, show_progress: bool = True,
              overwrite: bool = False, start: dict[str, float] | None = None) -> RunSummary:
    """Integrate a band-model CVT scene and summarise it.

    Parameters
    ----------
    scene : Scene
        A ``cvt`` scene whose ``cvt.model`` is a dynamic band model.
    until : float, optional, s
        Simulated end time (default ``solver.t_end``).
    results : path, optional
        HDF5 results file written incrementally (``None``: no file).
    start : dict, optional
        ``ratio`` and/or ``speed_factor`` to start away from the targets
        (:meth:`~cvtfem.control.closed_loop.ClosedLoop.initial_state`).
    """
    from cvtfem.io.progress import progress
    from cvtfem.machines import layout
    from cvtfem.machines.cvt import closed_loop

    if scene.kind != "cvt":
        raise InputError("SCENE", scene.source, f"must describe a CVT for `cvtfem run`, not a `{scene.kind}` machine")
    t_end = scene.solver.t_end if until is None else until
    if not t_end > 0:
        raise InputError("--until", t_end, "must be positive (simulated seconds)")
    loop = closed_loop(scene)
    specs = [o for part in layout(scene) for o in part.outputs]
    x0 = loop.initial_state(**(start or {}))
    names = {s.name for s in specs}
    missing = names - set(sample_outputs(loop, 0.0, x0))
    specs = [s for s in specs if s.name not in missing]
    sol = scene.solver
    stepper = make_stepper(sol.method, loop.rhs, 0.0, x0, t_end, sol.rtol, sol.atol, sol.h, loop.jac)
    dt = scene.output.step
    t_out = np.arange(0.0, t_end + 0.5 * dt, dt)
    t_out = t_out[t_out <= t_end * (1 + 1e-12)]
    writer = None
    if results is not None:
        from cvtfem.io.results import ResultsWriter

        writer = ResultsWriter(results, scene.to_toml(), "run", specs, scene.output.flush_interval, overwrite)
    wall0 = time.perf_counter()
    bar = progress(t_end, "s", f"run {scene.cvt.model}") if show_progress else None
    history: list[tuple[float, np.ndarray]] = []
    k, steps, status, message = 0, 0, "finished", ""
    try:
        while k < len(t_out) and t_out[k] <= stepper.t:  # t = 0
            _emit(writer, loop, t_out[k], stepper.y, history)
            k += 1
        while stepper.status == "running":
            t_prev = stepper.t
            msg = stepper.step()
            steps += 1
            if stepper.status == "failed" or not np.all(np.isfinite(stepper.y)):
                raise NumericalError(f"{sol.method} failed: {msg or 'state became non-finite'}", t=stepper.t,
                                     component=f"band model {scene.cvt.model}")
            if steps > sol.max_steps:
                raise NumericalError(f"step budget `solver.max_steps` = {sol.max_steps} exhausted", t=stepper.t)
            if k < len(t_out) and t_out[k] <= stepper.t:
                dense = stepper.dense_output()
                while k < len(t_out) and t_out[k] <= stepper.t:
                    _emit(writer, loop, t_out[k], dense(t_out[k]), history)
                    k += 1
            if bar is not None:
                bar.update(stepper.t - t_prev)
    except BaseException as err:
        status, message = "failed", str(err)
        if writer is not None:
            writer.close("failed", message)
        raise
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - wall0
    stats = {"name": sol.method, "steps": steps, "nfev": int(stepper.nfev), "njev": int(getattr(stepper, "njev", 0)),
             "nlu": int(getattr(stepper, "nlu", 0)), "rtol": sol.rtol, "atol": sol.atol}
    summary = _summarise(scene, loop, history, t_end, wall, stats, status)
    if writer is not None:
        writer.set_stats({**{f"solver_{k}": v for k, v in stats.items()}, "wall_time_s": wall})
        writer.add_array("band.node_xi", loop.model.arc_nodes(0.0)[0] / (math.pi / 2), "-",
                         "Quadrature nodes xi = theta / theta* of band.normal_force (same on both arcs).")
        writer.close(status, message)
        summary.results = str(results)
    return summary


def _emit(writer, loop, t: float, x, history: list) -> None:
    if not np.all(np.isfinite(x)):
        raise NumericalError("state became non-finite", t=t, component="band model")
    history.append((float(t), np.array(x)))
    if writer is not None:
        writer.append(t, sample_outputs(loop, t, x))


def _summarise(scene, loop, history, t_end, wall, stats, status) -> RunSummary:
    """Final ratio and speeds (raw, at t_end), efficiency over the last window from the work integrals."""
    t = np.array([h[0] for h in history])
    X = np.array([h[1] for h in history])
    x = X[-1]
    _, info = loop.evaluate(t[-1], x)
    w1d, _, i_d = info["targets"]
    j = int(np.searchsorted(t, t[-1] - EFFICIENCY_WINDOW))
    if j >= len(t) - 1:  # run shorter than one output step past the window: use the whole run
        j = 0
    W0, W1 = loop.split(X[j])[3], loop.split(x)[3]
    dW = W1 - W0
    dE = loop.energy(x) - loop.energy(X[j])
    eff = dW[1] / dW[0] if dW[0] > 0 else math.nan
    eff_kin = 1 - (dW[0] - dW[1] - dE) / dW[0] if dW[0] > 0 else math.nan
    rpm = 30 / math.pi
    w = info["w"]
    return RunSummary(scene=scene.source, model=scene.cvt.model, n_coordinates=loop.model.n2,
                      simulated_time_s=float(t[-1]), wall_time_s=wall, ratio=float(w[0] / w[1]), target_ratio=i_d,
                      input_speed_rpm=float(w[0] * rpm), output_speed_rpm=float(w[1] * rpm),
                      target_output_speed_rpm=float(w1d / i_d * rpm), efficiency=float(eff),
                      efficiency_kinetic=float(eff_kin), slip_speed_m_s=[float(s) for s in info["slip"]],
                      clamping_force_N=[float(f) for f in info["F"]], status=status, solver=stats)
