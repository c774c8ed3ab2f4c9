"""Time-run driver: scene -> model -> integrate -> results file (HDF5) -> summary.

``run_scene`` builds the closed loop of a band-model CVT scene and steps through the one step loop
(:class:`~cvtfem.integrate.stepping.Stepping`, built by :func:`make_stepper`; the same object as
``solve()``'s, so the series are bitwise ``solve()``'s): outputs are sampled from each step's dense
output, written incrementally with checkpoints of the loop's full memory, the scene's events
(``[[solver.event]]``) end or mark the run, and the ``solver.on_failure`` policy retries.
"""
from __future__ import annotations

import logging
import math
import re
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from cvtfem.analysis.steppers import check_method_options, make_stepper
from cvtfem.analysis.summary import EFFICIENCY_WINDOW, RunSummary, summarise
from cvtfem.blas import single_thread_blas
from cvtfem.errors import InputError, NumericalError
from cvtfem.outputs import OutputSpec

#: Stall guard: a run fails when STALL_STEPS consecutive accepted steps each advance time by less than
#: STALL_FRACTION * t_end (1e-10 s for a 0.1 s run; the band models' fastest time scales are ~1e-5 s).
STALL_STEPS = 50
#: Most output samples (rows of the results file) and checkpoints one run may ask for.
MAX_SAMPLES = 10_000_000
MAX_CHECKPOINTS = 100_000
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
    if not (math.isfinite(t_end) and t_end > 0):
        raise InputError("--until", t_end, "must be a positive, finite number of simulated seconds")
    run = _Run(scene, t_end)
    with single_thread_blas():   # the same bits on every machine (cvtfem.blas)
        x0, report = run.loop.start(**(start or {}))
    run.x_start = x0
    run.start_note = report.get("warning", report["kind"] if "residual" not in report else
                                f"steady (relative Newton correction {report['residual']:.1e})")
    run.check_events(x0)
    writer = None
    if results is not None:
        from cvtfem.io.results import ResultsWriter

        writer = ResultsWriter(results, scene.to_toml(), "run", run.specs, scene.output.flush_interval, overwrite,
                               checkpoint=run.layout() if run.interval > 0 else None)
    with single_thread_blas():
        return run.drive_with_policy(writer, 0.0, x0, None, show_progress, on_checkpoint)


def resume_run(results: str | Path, show_progress: bool = True,
               on_checkpoint: Callable[[float, int], None] | None = None, scene=None,
               changed: bool = False, until: float | None = None) -> RunSummary:
    """Continue a killed run from the newest checkpoint of its results file, appending to that file.

    The scene (TOML stored in the file), end time and solver come from the file; rows after the
    checkpoint are dropped and recomputed.  Methods without step-to-step memory (explicit Runge-Kutta,
    fixed or adaptive: the step size is restored) and those that export their memory (trapezoidal/theta,
    scipy Radau and BDF; sparse Jacobians stored compressed) give bitwise the series of an uninterrupted
    run; others (W-methods, stabilized methods, LSODA) restart their memory, so their results agree within
    the solver tolerance.  A file without checkpoint is refused with :class:`InputError`, and so is a
    finished run unless ``until`` is given.

    ``until`` (s) continues the run, killed or finished, to that end time instead of the stored one: it
    must lie after the checkpoint.  The series then equal those of one run to ``until`` (bitwise for the
    methods above); the summary's efficiency window starts at the checkpoint when the last
    :data:`~cvtfem.analysis.summary.EFFICIENCY_WINDOW` before ``until`` began before it.  Everything is
    checked before the file is touched.

    ``scene`` (a :class:`~cvtfem.scene.loader.Scene`, optional) must equal the stored one but for its
    ``title`` and ``description``: a difference is an :class:`InputError` naming the first differing key,
    unless ``changed``: then the run continues with ``scene``'s values from the checkpoint (which must have
    its state layout), and the file stores ``scene`` and the changes (``/stats`` ``scene_changed``).

    On elastic shafts the faces' reference positions ``z_ref`` come from the file (the series
    ``*.face_reference``, since session 17), not from the rigid start solved again: a resume costs no start, and
    with ``changed`` the faces stay where the run had them (a changed regime would otherwise move them).
    """
    from cvtfem.io.results import ResultsWriter, read_checkpoint, read_first_row, read_scene_toml
    from cvtfem.machines.chain_cvt_elastic import FACE_REFERENCE, with_face_reference
    from cvtfem.scene.loader import _parse, scene_from_dict

    text = read_scene_toml(results, "--resume")
    faces = read_first_row(results, FACE_REFERENCE, "--resume")     # elastic shafts: the faces stay where they were
    diff = []
    if scene is not None:
        stored = scene_from_dict(_parse(text, str(results)), source=str(results))
        diff = scene_differences(stored, scene)
        if diff and not changed:
            raise InputError("SCENE", scene.source, f"must equal the scene stored in {results} to resume it: "
                             f"{diff[0]}" + (f" (and {len(diff) - 1} more)" if len(diff) > 1 else ""),
                             "pass --resume-changed to continue the run with the new values")
        if diff and _Run.prepared(scene).layout() != _Run.prepared(stored).layout():
            raise InputError("SCENE", scene.source, f"must give the state layout of the run in {results} to "
                             "continue it: its model, solver method or events change what a checkpoint holds")
    run = None
    if until is not None:    # checked, and the run built, before the file is rewritten
        latest = read_checkpoint(results)
        t_ck = float(latest["t"][0]) if latest is not None else 0.0
        if not (math.isfinite(until) and until > t_ck):
            raise InputError("--until", until, f"must be a finite end time after the newest checkpoint of {results} "
                             f"(t = {t_ck:.6g} s), which the run continues from")
        text = scene.to_toml() if diff else text
        run = _Run.prepared(scene_from_dict(_parse(text, str(results)), source=f"{results} (resumed)"), until)
    writer, seq, values = ResultsWriter.resume(results, scene_toml=scene.to_toml() if diff else None,
                                               extend=until is not None)
    try:
        stored = scene_from_dict(_parse(writer.scene_toml, str(results)), source=f"{results} (resumed)")
        if diff:
            writer.set_stats({"scene_changed": "; ".join(diff)})
        if run is None:
            run = _Run.prepared(stored, float(values["t_end"][0]))
        elif until != float(values["t_end"][0]):   # a new end: its window starts at the checkpoint at the earliest
            run.j_window = max(run.j_window, int(values["k"][0]))
        if dict(writer.checkpoint_layout) != {**dict(run.layout().fields), "rows": 1}:
            raise InputError("--resume", str(results), "must hold a checkpoint of this cvtfem version's run driver "
                             f"(state layout {writer.checkpoint_layout} differs)")
        run.specs = writer.specs
        run.loop = with_face_reference(run.loop, faces)
        writer.flush_interval = stored.output.flush_interval
    except BaseException as err:
        writer.close("failed", f"resume: {err}")
        raise
    run.retry = int(values["retry"][0])
    with single_thread_blas():
        return run.drive_with_policy(writer, float(values["t"][0]), values["x"], (seq, values), show_progress,
                                     on_checkpoint)


#: Scene keys a resume may change without ``--resume-changed`` (free text without effect on the run).
FREE_TEXT_KEYS = ("title", "description")


def scene_differences(stored, new) -> list[str]:
    """``"`KEY` is A in the results file, B in SCENE"`` for every key (dotted path, schema order) whose value
    differs between two scenes, but :data:`FREE_TEXT_KEYS`."""
    from cvtfem.scene.node import thaw

    out: list[str] = []

    def walk(a, b, path: str) -> None:
        if isinstance(a, dict) and isinstance(b, dict):
            for key in dict.fromkeys([*a, *b]):
                walk(a.get(key), b.get(key), f"{path}.{key}" if path else key)
        elif a != b and path not in FREE_TEXT_KEYS:
            out.append(f"`{path}` is {a!r} in the results file, {b!r} in SCENE")

    walk(thaw(stored.data), thaw(new.data), "")
    return out


class _Run:
    """One run of a scene: loop, output grid, checkpoint payload and the stepping loop."""

    def __init__(self, scene, t_end: float) -> None:
        from cvtfem.machines.cvt import closed_loop

        self.scene, self.t_end = scene, t_end
        self.loop = closed_loop(scene)
        self.specs = list(self.loop.output_specs)
        if scene.output.state:
            self.specs.append(OutputSpec("state", "SI", "Full state vector x (the model's layout).", self.loop.size))
        dt = scene.output.step
        rows = t_end / dt + 1
        if rows > MAX_SAMPLES:
            width = sum(s.size for s in self.specs) + 1
            raise InputError("output.step", dt, f"must give at most {MAX_SAMPLES:.0e} output samples over "
                             f"{t_end:g} s: {rows:.3g} samples would take {rows * width * 8 / 1e9:.3g} GB",
                             "raise `output.step` or shorten the run")
        self.interval = float(scene.output.checkpoint_interval)
        if self.interval > 0 and t_end / self.interval > MAX_CHECKPOINTS:
            raise InputError("output.checkpoint_interval", self.interval, f"must give at most {MAX_CHECKPOINTS:.0e} "
                             f"checkpoints over {t_end:g} s ({t_end / self.interval:.3g} asked for)",
                             "checkpoints cost a full-state write each: one every few seconds of wall time is plenty")
        t_out = np.arange(0.0, t_end + 0.5 * dt, dt)
        # a sample within round-off past t_end (arange's 3 * 1e-4 = 3.0000000000000003e-4) is t_end: the stepper
        # lands on t_end exactly, so a sample a hair beyond it would never be emitted
        self.t_out = np.minimum(t_out[t_out <= t_end * (1 + 1e-12)], t_end)
        # the start of the efficiency window among the samples
        j = int(np.searchsorted(self.t_out, self.t_out[-1] - EFFICIENCY_WINDOW))
        self.j_window = 0 if j >= len(self.t_out) - 1 else j  # run shorter than one output step past the window
        from cvtfem.integrate.methods import parse_options

        sol = scene.solver
        self.options = check_method_options(sol.method, parse_options(sol.options, "solver.options",
                                                                      "scheme=imex-rk4"))
        if sol.on_failure == "retry":  # the fallback runs adaptive: refuse one without error estimate now
            try:
                make_stepper(sol.fallback, lambda t, y: -y, 0.0, [1.0], 1.0, sol.rtol, sol.atol)
            except InputError:
                raise InputError("solver.fallback", sol.fallback, "must be a method with an error estimate (it runs "
                                 "with adaptive steps), e.g. 'Radau', 'BDF', 'trapezoidal'") from None
        self.start_note = ""    # how the run started: "steady", "no-slip" or the warning of a start without slip
        self.x_start = None     # the start state (`start_state`: solved when first needed, not on a resume)
        self.retry = 0          # retries of `solver.on_failure = "retry"` so far
        self.retry_log: list[str] = []
        self._layout = None
        self.events = None      # (indicators, direction, terminal) of `[[solver.event]]`, set by `check_events`
        self.switch = None      # the model's discrete-state switch at its own events (`check_events`)
        self.event_names: list[str] = []

    def start_state(self) -> np.ndarray:
        """The model's start state (its ``initial_state``: for a chain the quasi-static solve, minutes on elastic
        shafts), solved once and only where needed (a resumed run starts from its checkpoint)."""
        if self.x_start is None:
            with single_thread_blas():
                self.x_start = self.loop.initial_state()
        return self.x_start

    @classmethod
    def prepared(cls, scene, t_end: float | None = None) -> _Run:
        """A run of ``scene`` to ``t_end`` (default ``solver.t_end``) with its events checked (as for a resume)."""
        run = cls(scene, scene.solver.t_end if t_end is None else t_end)
        run.check_events(None)
        return run

    def check_events(self, x0) -> None:
        """Event indicators ``output(t, x) - value`` of the scene's ``[[solver.event]]`` (scalar outputs only, checked
        at the state ``x0``, or at the model's start state when None and there are such events), then the model's own
        (its discrete state: :attr:`switch` applies them)."""
        declared = self.scene.solver.event
        if not declared:
            self.events = None
            self._model_events(0)
            return
        outputs = self.loop.outputs(0.0, self.start_state() if x0 is None else x0)
        for i, ev in enumerate(declared):
            if ev.output not in outputs:
                raise InputError(f"solver.event[{i}].output", ev.output,
                                 f"must be an output of this model: {', '.join(sorted(outputs))}")
            if np.size(outputs[ev.output]) != 1:
                raise InputError(f"solver.event[{i}].output", ev.output, "must be a scalar output (it has "
                                 f"{np.size(outputs[ev.output])} values)")
        loop, names = self.loop, [ev.output for ev in declared]
        values = np.array([ev.value for ev in declared])

        def indicators(t, x):
            out = loop.outputs(t, x)
            return np.array([float(out[name]) for name in names]) - values

        direction = np.array([{"rising": 1, "falling": -1, "either": 0}[ev.direction] for ev in declared])
        self.events = (indicators, direction, np.array([ev.terminal for ev in declared]))
        self.event_names = [ev.name or f"{ev.output} = {ev.value:g}" for ev in declared]
        self._model_events(len(declared))

    def _model_events(self, n_scene: int) -> None:
        """Append the model's event indicators (if it has any) after the ``n_scene`` of the scene and route their
        firing to the model's ``switch`` (an impact changes the state)."""
        loop = self.loop
        if getattr(loop, "events", None) is None:
            return
        scene_events, model_events = self.events, loop.events

        def indicators(t, x):
            own = np.asarray(model_events(t, x), float)
            return own if scene_events is None else np.concatenate([scene_events[0](t, x), own])

        def switch(t, x, fired):
            mine = fired[n_scene:]
            return loop.switch(t, x, mine) if mine.any() else None

        first = (np.zeros(0, int), np.zeros(0, bool)) if scene_events is None else scene_events[1:]
        self.events = (indicators, np.concatenate([first[0], loop.event_direction]),
                       np.concatenate([first[1], loop.event_terminal]))
        self.switch = switch

    def settings(self) -> tuple[str, float, float, float]:
        """``(method, h, rtol, atol)`` of the current attempt: the scene's, then per retry half the fixed step
        (adaptive: half the tolerances), the last retry with ``solver.fallback`` (adaptive)."""
        sol, r = self.scene.solver, self.retry
        if r == 0:
            return sol.method, sol.h, sol.rtol, sol.atol
        if r >= sol.max_retries:
            return sol.fallback, 0.0, sol.rtol, sol.atol
        if sol.h > 0 and _native(sol.method):
            return sol.method, sol.h / 2 ** r, sol.rtol, sol.atol
        return sol.method, sol.h, sol.rtol / 2 ** r, sol.atol / 2 ** r

    def methods(self) -> list[str]:
        """The methods a run of this scene may step with (the scene's, and the fallback of retries)."""
        sol = self.scene.solver
        return list(dict.fromkeys([sol.method] + ([sol.fallback] if sol.on_failure == "retry" else [])))

    def layout(self):
        """Checkpoint payload: the run's own position, the step loop's memory
        (:func:`~cvtfem.integrate.stepping.loop_fields`) and each method's (``<method>:<field>``)."""
        from cvtfem.integrate.stepping import loop_fields, memory_fields
        from cvtfem.io.checkpoint import Layout

        if self._layout is None:
            n, n2, m = self.loop.size, self.loop.n2, len(self.events[1]) if self.events else 0
            sparsity = getattr(self.loop, "jac_sparsity", None)
            fields = [("t_end", 1), ("k", 1), ("steps", 1), ("next_checkpoint", 1), ("t_last", 1), ("x_last", n),
                      ("x_window", n), ("wall", 1), ("retry", 1)] + list(loop_fields(n, m))
            split = getattr(self.loop, "stiff_split", None)
            for method in self.methods():
                options = self.options if method == self.scene.solver.method else None
                fields += [(f"{method}:{name}", size)
                           for name, size in memory_fields(method, n, n2, sparsity, options, split)]
            self._layout = Layout(tuple(fields))
        return self._layout

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
                what = f"h = {h:g} s" if h > 0 and _native(method) else f"rtol = {rtol:g}"
                note = f"retry {self.retry} of {sol.max_retries} with {method}, {what} after: {err}"
                if writer is not None and writer.checkpoint_layout:
                    try:
                        writer, seq, values = ResultsWriter.resume(writer.path)
                    except InputError:  # no checkpoint on disk yet: start again
                        writer = self._restart_file(writer)
                        start = (0.0, self.start_state(), None)
                    else:
                        start = (float(values["t"][0]), values["x"], (seq, values))
                        note += f", from the checkpoint at t = {start[0]:.6g} s"
                else:
                    writer = None if writer is None else self._restart_file(writer)
                    start = (0.0, self.start_state(), None)
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
        from cvtfem.io.progress import progress

        scene, loop, sol, t_end, t_out = self.scene, self.loop, self.scene.solver, self.t_end, self.t_out
        method, h_fixed, rtol, atol = self.settings()
        n, n2 = loop.size, loop.n2
        k, steps, seq, wall_before = 0, 0, 0, 0.0
        last, x_window = (math.nan, np.full(n, math.nan)), np.full(n, math.nan)
        next_ck = self.interval
        first_step, memory = 0.0, None
        if resumed is not None:
            seq, v = resumed
            k, steps = int(v["k"][0]), int(v["steps"][0])
            next_ck, wall_before = float(v["next_checkpoint"][0]), float(v["wall"][0])
            last, x_window = (float(v["t_last"][0]), v["x_last"]), v["x_window"]
            memory = {name.split(":", 1)[-1]: a for name, a in v.items()
                      if ":" not in name or name.startswith(f"{method}:")}
            first_step = float(memory["h"][0])
        try:
            run = make_stepper(method, loop.rhs, t0, x0, t_end, rtol, atol, h_fixed, loop.jac, n2,
                               first_step=0.0 if fresh_solver else first_step, error_check=sol.error_check,
                               events=self.events, switch=self.switch,
                               jac_sparsity=getattr(loop, "jac_sparsity", None),
                               stall_steps=STALL_STEPS, stall_h=STALL_FRACTION * t_end,
                               split=getattr(loop, "stiff_split", None),
                               options=self.options if method == sol.method else None)
        except BaseException as err:
            if writer is not None:
                writer.close("failed", str(err))
            raise
        if memory is not None:  # memory and counters continue from the checkpoint
            run.restore(memory, memory=not fresh_solver)

        def emit(t: float, x) -> None:
            nonlocal k, last, x_window
            if not np.all(np.isfinite(x)):
                bad = int(np.flatnonzero(~np.isfinite(x))[0])
                raise NumericalError(_labelled(loop, f"state became non-finite in component {bad}"), t=t,
                                     component=component)
            last = (float(t), np.array(x))
            if k == self.j_window:
                x_window = np.array(x)
            if writer is not None:
                writer.append(t, loop.outputs(t, x) | ({"state": x} if scene.output.state else {}))
            k += 1

        def save() -> None:
            nonlocal seq
            seq += 1
            state = run.state()
            payload = {name: np.full(size, np.nan) for name, size in self.layout().fields}
            payload.update({name if name in payload else f"{method}:{name}": a for name, a in state.items()})
            payload.update({"t_end": t_end, "k": k, "steps": steps,
                            "next_checkpoint": next_ck, "t_last": last[0], "x_last": last[1], "x_window": x_window,
                            "wall": wall_before + time.perf_counter() - wall0, "retry": self.retry})
            writer.checkpoint(seq, payload)
            if on_checkpoint is not None:
                on_checkpoint(float(run.t), seq)

        checkpoints = writer is not None and self.interval > 0
        wall0, cpu0 = time.perf_counter(), time.process_time()
        bar = progress(t_end, "s", f"run {scene.cvt.model}") if show_progress else None
        if bar is not None and t0 > 0:
            bar.update(t0)
        status, message = "finished", ""
        component = f"{'chain' if scene.cvt.model.startswith('chain') else 'band'} model {scene.cvt.model}"
        retry_stats = {"retries": self.retry, "retry_log": "\n".join(self.retry_log)} if self.retry_log else {}
        try:
            while k < len(t_out) and t_out[k] <= run.t:  # t = 0
                emit(t_out[k], run.x)
            while run.status == "running":
                t_prev = run.t
                taken = run.step()
                if run.failure == "stall":
                    raise NumericalError(_stall_message(loop, method, run.t, run.x, run.t - t_prev, run.stall_h)
                                         + _fastest(loop, run.t, run.x, rtol, atol), t=run.t, component=component)
                if not taken:
                    raise NumericalError(_failure(loop, method, run, rtol, atol), t=run.t_fail, component=component)
                steps += 1
                if steps > sol.max_steps:
                    raise NumericalError(f"step budget `solver.max_steps` = {sol.max_steps} exhausted", t=run.t)
                while k < len(t_out) and t_out[k] <= run.t:
                    emit(t_out[k], run.dense(t_out[k]))
                if run.status == "failed":
                    raise NumericalError(_failure(loop, method, run, rtol, atol), t=run.t_fail, component=component)
                if checkpoints and run.status == "running" and run.t >= next_ck:
                    while next_ck <= run.t:
                        next_ck += self.interval
                    save()
                if bar is not None:
                    bar.update(run.t - t_prev)
        except BaseException as err:
            status, message = "failed", str(err)
            if writer is not None:
                writer.set_stats(retry_stats)
                writer.close("failed", message)
            raise
        finally:
            if bar is not None:
                bar.close()
        if run.status == "event" and (k == 0 or last[0] < run.t):   # the run ends at the event: its last sample
            emit(run.t, run.x)
        wall = wall_before + time.perf_counter() - wall0
        counts = run.counts
        stats = {"name": method, "steps": steps, "nfev": int(counts["nfev"]), "njev": int(counts["njev"]),
                 "nlu": int(counts["nlu"]), "rtol": rtol, "atol": atol,
                 "kernel": getattr(getattr(loop, "model", loop), "backend", "numpy")}  # numba or numpy RHS
        stats.update(run.engine.report())
        warning = run.engine.warning()
        if warning is not None:
            stats["warning"] = warning
            log.warning("%s", warning)
        summary = summarise(scene, loop, last, (t_out[self.j_window], x_window), t_end, wall, stats, status)
        summary.process_cpu_time_s = time.process_time() - cpu0
        diverged = self._diverged(summary, method, h_fixed)
        if diverged:
            status, message = "failed", diverged
        if writer is not None:
            extra = {"checkpoints": seq} if checkpoints else {}
            if self.start_note:
                extra["start"] = self.start_note
            if resumed is not None:
                extra["resumed_from_t"] = float(resumed[1]["t"][0])
            if run.status == "event":
                fired = np.flatnonzero(run.fired & run.system.event_terminal)
                extra.update(event_t=float(run.t), event_name=", ".join(self.event_names[i] for i in fired))
            writer.set_stats({**{f"solver_{k}": v for k, v in stats.items()}, "wall_time_s": wall,
                              "process_cpu_time_s": summary.process_cpu_time_s, **extra,
                              **retry_stats})
            if self.events is not None:
                for i, name in enumerate(self.event_names):
                    writer.add_array(f"event.{i}.times", np.array(run.t_events[i], dtype=float), "s",
                                     f"Times of event {name!r}.")
            arc_nodes = getattr(getattr(loop, "model", None), "arc_nodes", None)   # band 6+2n models
            if arc_nodes is not None:
                writer.add_array("band.node_xi", arc_nodes(0.0)[0] / (math.pi / 2), "-",
                                 "Quadrature nodes xi = theta / theta* of band.normal_force (same on both arcs).")
            writer.close(status, message)
            summary.results = str(writer.path)
        if diverged:
            raise NumericalError(diverged, t=summary.simulated_time_s, component=component)
        return summary

    def _diverged(self, summary: RunSummary, method: str, h: float) -> str:
        """Why a run that stepped to its end has diverged (empty if it has not): a final speed ratio beyond
        half / twice the ratios the sheaves admit, or a driving shaft turning backwards."""
        from cvtfem.machines.cvt import check_ratio_range

        lo, hi = check_ratio_range(self.scene)
        if lo / 2 <= summary.ratio <= 2 * hi and summary.input_speed_rpm > 0:
            return ""
        how = f"{method} at h = {h:g} s" if h > 0 and _native(method) else method
        return (f"the run diverged: final ratio {summary.ratio:.3g} (admissible {lo:.3g}..{hi:.3g}), input speed "
                f"{summary.input_speed_rpm:.4g} rpm; {how} may be unstable for this model: try a smaller "
                "`solver.h` or an implicit method")


def _native(method: str) -> bool:
    """True for a playground method (``solver.h`` is its fixed step), False for scipy's."""
    from cvtfem.integrate import METHODS

    return method in METHODS


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


def _labelled(loop, message: str) -> str:
    """``message`` with each ``component K`` followed by what state ``K`` is (``loop.state_label``, e.g.
    ``component 212 (pin 44, u3)``), for models that label their states."""
    label = getattr(loop, "state_label", None)
    if label is None:
        return message
    return re.sub(r"component (\d+)", lambda m: f"component {m[1]} ({label(int(m[1]))})", message)


def _fastest(loop, t: float, x, rtol: float, atol: float) -> str:
    """``"; fastest state: component K (pin 17, du3/dt) ..."``: the coordinate or velocity whose rate is largest
    against its tolerance at ``(t, x)`` (the one that holds the step size down or blows up; the first-order
    states, loops and work integrals, only follow), for models that label their states."""
    if getattr(loop, "state_label", None) is None or not np.all(np.isfinite(x)):
        return ""
    n = 2 * loop.n2
    with np.errstate(all="ignore"):
        rate = np.abs(loop.rhs(t, x)[:n]) / (atol + rtol * np.abs(x[:n]))
    if not np.all(np.isfinite(rate)):
        return ""
    k = int(np.argmax(rate))
    return _labelled(loop, f"; fastest state: component {k}, |dx/dt| / (atol + rtol |x|) = {rate[k]:.3g} 1/s")


def _failure(loop, method: str, run, rtol: float, atol: float) -> str:
    """The failure text of a stepper with the failing component named: the component its message names, and
    unless that is a pin coordinate (a work integral grows fastest in a blow-up) the fastest state at the last
    accepted step."""
    message = f"{method} failed: {run.message}"
    named = re.search(r"component (\d+)", message)
    label = getattr(loop, "state_label", None)
    if named and label is not None and label(int(named[1])).startswith("pin "):
        return _labelled(loop, message)
    return _labelled(loop, message) + _fastest(loop, run.t, run.x, rtol, atol)
