"""Time-run driver: scene -> model -> integrate -> results file (HDF5) -> summary.

``run_scene`` builds the closed loop of a band-model CVT scene, integrates it with one small
solver factory (:func:`make_stepper`: scipy's ``OdeSolver`` classes step by step, so outputs are
sampled from the dense output, written incrementally and the progress bar advances), checks
every accepted state for NaN/inf and returns a :class:`RunSummary`.
"""
from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from cvtfem.analysis.steppers import SCIPY_STEPPERS, make_stepper
from cvtfem.analysis.summary import EFFICIENCY_WINDOW, RunSummary, summarise
from cvtfem.errors import InputError, NumericalError

#: Stall guard: a run fails when STALL_STEPS consecutive accepted steps each advance time by less than
#: STALL_FRACTION * t_end (1e-10 s for a 0.1 s run; the band models' fastest time scales are ~1e-5 s).
STALL_STEPS = 50
STALL_FRACTION = 1e-9
log = logging.getLogger(__name__)


def run_scene(scene, until: float | None = None, results: str | Path | None = None, show_progress: bool = True,
              overwrite: bool = False, start: dict[str, float] | None = None,
              on_checkpoint: Callable[[float, int], None] | None = None) -> RunSummary:
    """Integrate a band-model CVT scene and summarise it.

    Parameters
    ----------
    scene : Scene
        A ``cvt`` scene whose ``cvt.model`` is a dynamic band model.
    until : float, optional, s
        Simulated end time (default ``solver.t_end``).
    results : path, optional
        HDF5 results file written incrementally (``None``: no file).  With
        ``output.checkpoint_interval > 0`` it also receives the checkpoints (:func:`resume_run`).
    start : dict, optional
        ``ratio`` and/or ``speed_factor`` to start away from the targets
        (:meth:`~cvtfem.machines.band_cvt.BandCVT.initial_state`).
    on_checkpoint : callable, optional
        ``on_checkpoint(t, seq)`` after each checkpoint is on disk.
    """
    if scene.kind != "cvt":
        raise InputError("SCENE", scene.source, f"must describe a CVT for `cvtfem run`, not a `{scene.kind}` machine")
    t_end = scene.solver.t_end if until is None else until
    if not t_end > 0:
        raise InputError("--until", t_end, "must be positive (simulated seconds)")
    run = _Run(scene, t_end)
    x0 = run.x_start = run.loop.initial_state(**(start or {}))
    writer = None
    if results is not None:
        from cvtfem.io.results import ResultsWriter

        writer = ResultsWriter(results, scene.to_toml(), "run", run.specs, scene.output.flush_interval, overwrite,
                               checkpoint=run.layout() if run.interval > 0 else None)
    return run.drive_with_policy(writer, 0.0, x0, None, show_progress, on_checkpoint)


def resume_run(results: str | Path, show_progress: bool = True,
               on_checkpoint: Callable[[float, int], None] | None = None) -> RunSummary:
    """Continue a killed run from the newest checkpoint of its results file, appending to that file.

    The scene (TOML stored in the file), end time and solver come from the file; rows after the
    checkpoint are dropped and recomputed.  Methods without step-to-step memory (explicit Runge-Kutta,
    fixed or adaptive: the step size is restored) and those whose memory the checkpoint holds
    (:mod:`cvtfem.io.solver_state`: trapezoidal/theta, scipy Radau and BDF, with dense Jacobians) give
    bitwise the series of an uninterrupted run; others (W-methods, LSODA) restart their memory, so their
    results agree within the solver tolerance.  A finished run or a file without checkpoint is refused
    with :class:`InputError`.
    """
    from cvtfem.io.results import ResultsWriter
    from cvtfem.scene.loader import _parse, scene_from_dict

    writer, seq, values = ResultsWriter.resume(results)
    try:
        scene = scene_from_dict(_parse(writer.scene_toml, str(results)), source=f"{results} (resumed)")
        run = _Run(scene, float(values["t_end"][0]))
        layout = run.layout()
        if dict(writer.checkpoint_layout) != {**dict(layout.fields), "rows": 1}:
            raise InputError("--resume", str(results), "must hold a checkpoint of this cvtfem version's run driver "
                             f"(state layout {writer.checkpoint_layout} differs)")
        run.specs = writer.specs
        writer.flush_interval = scene.output.flush_interval
    except BaseException as err:
        writer.close("failed", f"resume: {err}")
        raise
    run.retry, run.x_start = int(values["retry"][0]), run.loop.initial_state()
    return run.drive_with_policy(writer, float(values["t"][0]), values["x"], (seq, values), show_progress,
                                 on_checkpoint)


class _Run:
    """One run of a scene: loop, output grid, checkpoint payload and the stepping loop."""

    def __init__(self, scene, t_end: float) -> None:
        from cvtfem.machines.cvt import closed_loop

        self.scene, self.t_end = scene, t_end
        self.loop = closed_loop(scene)
        self.specs = list(self.loop.output_specs)
        dt = scene.output.step
        t_out = np.arange(0.0, t_end + 0.5 * dt, dt)
        self.t_out = t_out[t_out <= t_end * (1 + 1e-12)]
        # the samples a finished run emits (the stepper lands on t_end) and the start of the efficiency window
        final = self.t_out[self.t_out <= t_end]
        j = int(np.searchsorted(final, final[-1] - EFFICIENCY_WINDOW))
        self.j_window = 0 if j >= len(final) - 1 else j  # run shorter than one output step past the window
        self.interval = float(scene.output.checkpoint_interval)
        sol = scene.solver
        if sol.on_failure == "retry":  # the fallback runs adaptive: refuse one without error estimate now
            try:
                make_stepper(sol.fallback, lambda t, y: -y, 0.0, [1.0], 1.0, sol.rtol, sol.atol)
            except InputError:
                raise InputError("solver.fallback", sol.fallback, "must be a method with an error estimate (it runs "
                                 "with adaptive steps), e.g. 'Radau', 'BDF', 'trapezoidal'") from None
        self.retry = 0          # retries of `solver.on_failure = "retry"` so far
        self.retry_log: list[str] = []

    def settings(self) -> tuple[str, float, float, float]:
        """``(method, h, rtol, atol)`` of the current attempt: the scene's, then per retry half the fixed step
        (adaptive: half the tolerances), the last retry with ``solver.fallback`` (adaptive)."""
        sol, r = self.scene.solver, self.retry
        if r == 0:
            return sol.method, sol.h, sol.rtol, sol.atol
        if r >= sol.max_retries:
            return sol.fallback, 0.0, sol.rtol, sol.atol
        if sol.h > 0 and sol.method not in SCIPY_STEPPERS:
            return sol.method, sol.h / 2 ** r, sol.rtol, sol.atol
        return sol.method, sol.h, sol.rtol / 2 ** r, sol.atol / 2 ** r

    def state_size(self) -> int:
        from cvtfem.io.solver_state import state_size

        sol, n, n2 = self.scene.solver, self.loop.size, self.loop.model.n2
        methods = [sol.method] + ([sol.fallback] if sol.on_failure == "retry" else [])
        return max(state_size(m, n, n2) for m in methods)

    def layout(self):
        from cvtfem.integrate.stats import COUNTERS
        from cvtfem.io.checkpoint import Layout

        n = self.loop.size
        return Layout((("t", 1), ("t_end", 1), ("x", n), ("h", 1), ("k", 1), ("steps", 1), ("tiny", 1),
                       ("next_checkpoint", 1), ("counts", len(COUNTERS)), ("t_last", 1), ("x_last", n),
                       ("x_window", n), ("wall", 1), ("largest", 1), ("monitor", 5), ("retry", 1),
                       ("solver_state", self.state_size())))

    def drive_with_policy(self, writer, t0: float, x0, resumed, show_progress: bool, on_checkpoint) -> RunSummary:
        """:meth:`drive`, and on a :class:`NumericalError` the scene's ``solver.on_failure`` policy: "stop"
        re-raises (the results file is closed "failed" with the message, its rows stay readable); "retry"
        restarts from the newest checkpoint (or from the start without one) with :meth:`settings` of the next
        retry, at most ``solver.max_retries`` times, each logged in the results file (``/stats`` retries and
        retry_log) and by the logger."""
        from cvtfem.io.results import ResultsWriter

        sol = self.scene.solver
        start = (t0, np.array(x0), resumed)
        while True:
            try:
                return self.drive(writer, *start, show_progress, on_checkpoint, fresh_solver=bool(self.retry_log))
            except NumericalError as err:
                if sol.on_failure != "retry" or self.retry >= sol.max_retries:
                    raise
                self.retry += 1
                method, h, rtol, _ = self.settings()
                what = f"h = {h:g} s" if h > 0 and method not in SCIPY_STEPPERS else f"rtol = {rtol:g}"
                note = f"retry {self.retry} of {sol.max_retries} with {method}, {what} after: {err}"
                if writer is not None and writer.checkpoint_layout:
                    try:
                        writer, seq, values = ResultsWriter.resume(writer.path)
                    except InputError:  # no checkpoint on disk yet: start again
                        writer = self._restart_file(writer)
                        start = (0.0, self.x_start, None)
                    else:
                        start = (float(values["t"][0]), values["x"], (seq, values))
                        note += f", from the checkpoint at t = {start[0]:.6g} s"
                else:
                    writer = None if writer is None else self._restart_file(writer)
                    start = (0.0, self.x_start, None)
                self.retry_log.append(note)
                log.warning("%s", note)

    def _restart_file(self, writer):
        """A fresh results file in place of ``writer``'s (a retry from the start)."""
        from cvtfem.io.results import ResultsWriter

        writer.close("failed", "retried from the start")
        return ResultsWriter(writer.path, writer.scene_toml, "run", writer.specs, self.scene.output.flush_interval,
                             True, checkpoint=self.layout() if self.interval > 0 else None)

    def drive(self, writer, t0: float, x0, resumed, show_progress: bool, on_checkpoint,
              fresh_solver: bool = False) -> RunSummary:
        """Step from ``(t0, x0)`` to ``t_end``; ``resumed = (seq, checkpoint payload)`` continues a run, with the
        integrator memory restored unless ``fresh_solver`` (a retry with other settings)."""
        from cvtfem.integrate import CvtfemSolver
        from cvtfem.integrate.driver import GROWTH_LIMIT
        from cvtfem.integrate.guards import GrowthGuard
        from cvtfem.integrate.stats import COUNTERS
        from cvtfem.io.progress import progress
        from cvtfem.io.solver_state import export_state, import_state

        scene, loop, sol, t_end, t_out = self.scene, self.loop, self.scene.solver, self.t_end, self.t_out
        method, h_fixed, rtol, atol = self.settings()
        n, n2 = loop.size, loop.model.n2
        k, steps, tiny, seq, wall_before = 0, 0, 0, 0, 0.0
        last, x_window = (math.nan, np.full(n, math.nan)), np.full(n, math.nan)
        next_ck = self.interval
        first_step = 0.0
        if resumed is not None:
            seq, v = resumed
            k, steps, tiny = int(v["k"][0]), int(v["steps"][0]), int(v["tiny"][0])
            next_ck, wall_before, first_step = float(v["next_checkpoint"][0]), float(v["wall"][0]), float(v["h"][0])
            last, x_window = (float(v["t_last"][0]), v["x_last"]), v["x_window"]
        try:
            stepper = make_stepper(method, loop.rhs, t0, x0, t_end, rtol, atol, h_fixed, loop.jac, n2,
                                   first_step=0.0 if fresh_solver else first_step, error_check=sol.error_check)
        except BaseException as err:
            if writer is not None:
                writer.close("failed", str(err))
            raise
        cvtfem_solver = isinstance(stepper, CvtfemSolver)
        guard = stepper.guard if cvtfem_solver else GrowthGuard(GROWTH_LIMIT, x0, atol, method, adaptive=True)
        monitor = stepper.monitor if cvtfem_solver else None
        if resumed is not None:  # memory and counters continue from the checkpoint
            v = resumed[1]
            guard.largest = max(guard.largest, float(v["largest"][0]))
            if monitor is not None:
                monitor.restore(v["monitor"])
            if not fresh_solver:
                import_state(method, stepper, v["solver_state"], n, n2)
            counts = v["counts"]
            if cvtfem_solver:
                stepper.stats.counts.update({c: int(counts[i]) for i, c in enumerate(COUNTERS)})
                stepper._sync()
            else:
                stepper.nfev, stepper.njev, stepper.nlu = (int(c) for c in counts[:3])

        def emit(t: float, x) -> None:
            nonlocal k, last, x_window
            if not np.all(np.isfinite(x)):
                raise NumericalError("state became non-finite", t=t, component="band model")
            last = (float(t), np.array(x))
            if k == self.j_window:
                x_window = np.array(x)
            if writer is not None:
                writer.append(t, loop.outputs(t, x))
            k += 1

        def save() -> None:
            nonlocal seq
            seq += 1
            if cvtfem_solver:
                counts = [stepper.stats.counts[c] for c in COUNTERS]
                h = stepper.h_next
            else:
                counts = [stepper.nfev, getattr(stepper, "njev", 0), getattr(stepper, "nlu", 0)]
                counts += [0] * (len(COUNTERS) - 3)
                h = getattr(stepper, "h_abs", None) or stepper.step_size or 0.0
            state = np.full(self.state_size(), np.nan)
            mem = export_state(method, stepper, n, n2)
            state[:mem.size] = mem
            writer.checkpoint(seq, {"t": stepper.t, "t_end": t_end, "x": stepper.y, "h": h, "k": k, "steps": steps,
                                    "tiny": tiny, "next_checkpoint": next_ck, "counts": counts, "t_last": last[0],
                                    "x_last": last[1], "x_window": x_window,
                                    "wall": wall_before + time.perf_counter() - wall0, "largest": guard.largest,
                                    "monitor": monitor.snapshot() if monitor is not None else np.zeros(5),
                                    "retry": self.retry, "solver_state": state})
            if on_checkpoint is not None:
                on_checkpoint(float(stepper.t), seq)

        checkpoints = writer is not None and self.interval > 0
        wall0 = time.perf_counter()
        bar = progress(t_end, "s", f"run {scene.cvt.model}") if show_progress else None
        if bar is not None and t0 > 0:
            bar.update(t0)
        status, message = "finished", ""
        h_stall = STALL_FRACTION * t_end
        component = f"band model {scene.cvt.model}"
        retry_stats = {"retries": self.retry, "retry_log": "\n".join(self.retry_log)} if self.retry_log else {}
        try:
            while k < len(t_out) and t_out[k] <= stepper.t:  # t = 0
                emit(t_out[k], stepper.y)
            while stepper.status == "running":
                t_prev, y_prev, f_prev = stepper.t, stepper.y, getattr(stepper, "f", None)
                msg = stepper.step()
                steps += 1
                if stepper.status == "failed" or not np.all(np.isfinite(stepper.y)):
                    raise NumericalError(f"{method} failed: {msg or 'state became non-finite'}", t=stepper.t,
                                         component=component)
                if not cvtfem_solver:  # scipy steppers: the growth guard of cvtfem's adaptive runs
                    why = guard.check(y_prev, stepper.y, stepper.t - t_prev, f_prev)
                    if why is not None:
                        raise NumericalError(f"{method} failed: {why} at t = {stepper.t:.6g} s with adaptive step "
                                             f"h = {stepper.t - t_prev:.3g} s{guard.hint()}", t=stepper.t,
                                             component=component)
                    guard.update(stepper.y)
                if steps > sol.max_steps:
                    raise NumericalError(f"step budget `solver.max_steps` = {sol.max_steps} exhausted", t=stepper.t)
                tiny = tiny + 1 if stepper.t - t_prev < h_stall else 0
                if tiny >= STALL_STEPS:
                    raise NumericalError(_stall_message(loop, method, stepper.t, stepper.y, stepper.t - t_prev,
                                                        h_stall), t=stepper.t, component=component)
                if k < len(t_out) and t_out[k] <= stepper.t:
                    dense = stepper.dense_output()
                    while k < len(t_out) and t_out[k] <= stepper.t:
                        emit(t_out[k], dense(t_out[k]))
                if checkpoints and stepper.status == "running" and stepper.t >= next_ck:
                    while next_ck <= stepper.t:
                        next_ck += self.interval
                    save()
                if bar is not None:
                    bar.update(stepper.t - t_prev)
        except BaseException as err:
            status, message = "failed", str(err)
            if writer is not None:
                writer.set_stats(retry_stats)
                writer.close("failed", message)
            raise
        finally:
            if bar is not None:
                bar.close()
        wall = wall_before + time.perf_counter() - wall0
        stats = {"name": method, "steps": steps, "nfev": int(stepper.nfev), "njev": int(getattr(stepper, "njev", 0)),
                 "nlu": int(getattr(stepper, "nlu", 0)), "rtol": rtol, "atol": atol,
                 "kernel": getattr(loop.model, "backend", "numpy")}  # compiled (numba) or numpy right-hand side
        if monitor is not None and monitor.active:
            stats.update(monitor.stats())
            warning = monitor.warning()
            if warning is not None:
                stats["warning"] = warning
                log.warning("%s", warning)
        summary = summarise(scene, loop, last, (t_out[self.j_window], x_window), t_end, wall, stats, status)
        if writer is not None:
            extra = {"checkpoints": seq} if checkpoints else {}
            if resumed is not None:
                extra["resumed_from_t"] = float(resumed[1]["t"][0])
            writer.set_stats({**{f"solver_{k}": v for k, v in stats.items()}, "wall_time_s": wall, **extra,
                              **retry_stats})
            writer.add_array("band.node_xi", loop.model.arc_nodes(0.0)[0] / (math.pi / 2), "-",
                             "Quadrature nodes xi = theta / theta* of band.normal_force (same on both arcs).")
            writer.close(status, message)
            summary.results = str(writer.path)
        return summary


def _stall_message(loop, method: str, t: float, x, h: float, h_stall: float) -> str:
    """Why the step size collapsed, with the clamping forces and slips that usually explain it."""
    _, info = loop.evaluate(t, x)
    F, slip = np.asarray(info["F"]), np.asarray(info["slip"])
    return (f"step size stalled: {STALL_STEPS} consecutive {method} steps each advanced time by less than "
            f"{h_stall:.3g} s (STALL_FRACTION = {STALL_FRACTION:g} x t_end), last h = {h:.3g} s at t = {t:.6g} s; "
            f"clamping forces {F[0]:.3g} / {F[1]:.3g} N, slip speeds {slip[0]:.3g} / {slip[1]:.3g} m/s. "
            "Likely cause: a non-smooth right-hand side the solver cannot step over (anti-windup switching of the "
            "control loops, gross slip under a vanishing clamping force at near-zero torque); raise the torque "
            "or the clamping safety factor, or try another `solver.method`")
