"""The one step loop (spec §6, §11): :class:`Stepping` drives any method one accepted step at a time.

``solve()``, :class:`~cvtfem.integrate.CvtfemSolver` and ``cvtfem run`` all step through it, so
error control, the growth guard, the local-error monitor, event location on the step's dense
output with the discrete-state ``switch``, Zeno/max-events detection, the stall guard and the
export of the full memory (:meth:`Stepping.state`) are the same for every method. A method is
run by an engine: :class:`NativeEngine` (a :class:`~cvtfem.integrate.base.Stepper` with the
step-size controller: attempt -> error norm -> accept/reject, step-size underflow) or
:class:`~cvtfem.integrate.scipy_bridge.ScipyEngine` (a ``scipy.integrate.OdeSolver``, which
brings its own step acceptance).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from cvtfem.errors import InputError, NumericalError
from cvtfem.integrate.base import Attempt, StepFailure, hermite
from cvtfem.integrate.controller import CONTROLLER_MEMORY, FixedStep, error_norm, make_controller, step_floor
from cvtfem.integrate.events import EVENT_SAMPLES, EventLocator
from cvtfem.integrate.guards import ErrorMonitor, GrowthGuard
from cvtfem.integrate.methods import METHODS, SCIPY_METHODS, check_options
from cvtfem.integrate.stats import COUNTERS, Stats
from cvtfem.integrate.system import OdeSystem, as_system

__all__ = ["Stepping", "NativeEngine", "Candidate", "make_engine", "initial_step", "state_fields", "GROWTH_LIMIT",
           "ZENO_GAP", "ZENO_GAP_H", "ZENO_COUNT"]

ZENO_GAP = 1e-9     # events closer than this fraction of the span ...
ZENO_GAP_H = 1e-6   # ... or of the step count towards Zeno accumulation
ZENO_COUNT = 3      # that many in a row stop the run
GROWTH_LIMIT = 1e8  # default growth guard (see :mod:`cvtfem.integrate.guards`)
#: Exceptions of a right-hand side at a state it cannot evaluate (a blown-up state reaching a linear solve, or a
#: model's own NumericalError, e.g. a pin end on a shaft axis): a failed attempt with the reason, not a
#: traceback; an adaptive method retries with a smaller step, a fixed-step one stops there.
MODEL_FAILURES = (np.linalg.LinAlgError, FloatingPointError, ZeroDivisionError, OverflowError, NumericalError)


@dataclass
class Candidate:
    """A step ``t0 -> t1 = t0 + h`` accepted by the method's error control, before the guards and
    events; ``dense(t)`` evaluates its interpolant at one time ``t``, s; ``precise(t)``, when set, the
    method's own solution there (:meth:`~cvtfem.integrate.base.Stepper.solution_at`, for event refinement)."""

    t0: float
    x0: np.ndarray
    h: float
    t1: float
    x1: np.ndarray
    f0: np.ndarray | None
    dense: Callable[[float], np.ndarray]
    raw: object = field(default=None, repr=False)
    precise: Callable[[float], np.ndarray] | None = field(default=None, repr=False)


def initial_step(stepper, t0, y0, rtol, atol, span):
    """Hairer's starting step guess, one extra RHS call (as scipy's ``select_initial_step``)."""
    f0 = stepper.f(t0, y0)
    scale = atol + rtol * np.abs(y0)
    d0, d1 = np.sqrt(np.mean(np.abs(y0 / scale) ** 2)), np.sqrt(np.mean(np.abs(f0 / scale) ** 2))
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, span)
    f1 = stepper.f(t0 + h0, y0 + h0 * f0)
    d2 = np.sqrt(np.mean(np.abs((f1 - f0) / scale) ** 2)) / h0
    q = stepper.error_order or stepper.order
    h1 = max(1e-6, h0 * 1e-3) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** (1 / (q + 1))
    return min(100 * h0, h1, span)


class NativeEngine:
    """A playground stepper with fixed steps (``h``) or error control (``h`` None or first step).

    Holds the step-size controller, the local-error monitor of fixed steps (``error_check``) and
    the proposal ``h`` for the next step; ``stats`` are the stepper's counters.
    """

    def __init__(self, method: str, system: OdeSystem, t0: float, y0, t_end: float, rtol: float, atol,
                 h: float | None = None, adaptive: bool | None = None, error_check: int = 0,
                 first_step: float | None = None, options: dict | None = None, controller: str | None = None) -> None:
        cls = METHODS[method]
        self.name, self.system, self.stats = method, system, Stats()
        self.stepper = cls(system, self.stats, **check_options(method, cls.OPTIONS, options or {}))
        self.adaptive = h is None if adaptive is None else bool(adaptive)
        if self.adaptive and self.stepper.error_order is None:
            raise InputError("method", method, "has no error estimate, so it needs a fixed step `h`")
        if not self.adaptive and h is None:
            raise InputError("h", h, "must be given for a fixed-step run")
        self.stepper.need_error = self.adaptive
        ratio = self.stepper.tolerance_ratio(rtol) if self.adaptive else 1.0   # internal tolerances
        self.rtol, self.atol = rtol * ratio, atol * ratio
        self.stepper.tolerances = (self.rtol, self.atol) if self.adaptive else None
        controller = controller or self.stepper.controller
        self.ctrl = (make_controller(controller, getattr(self.stepper, "STEP_QUANTUM", 1.0)) if self.adaptive
                     else FixedStep(h))
        if not (isinstance(error_check, (int, np.integer)) and error_check >= 0):
            raise InputError("error_check", error_check, "must be a whole number of steps >= 0 (0: off)")
        self.monitor = ErrorMonitor(self.stepper, rtol, atol, 0 if self.adaptive else error_check)
        if first_step and self.adaptive:
            self.h = float(first_step)
        elif self.adaptive and h is None:
            self.h = initial_step(self.stepper, t0, np.asarray(y0), rtol, atol, t_end - t0)
        else:
            self.h = float(h)

    def advance(self, t: float, x: np.ndarray, tf: float) -> tuple[Candidate | None, str | None]:
        """Attempts from ``(t, x)`` until one is accepted: ``(candidate, None)`` or ``(None, why)``."""
        stepper, adaptive = self.stepper, self.adaptive
        while True:
            h = self.h
            h_try = min(h, tf - t, stepper.max_step()) if adaptive else min(h, tf - t)
            if tf - (t + h_try) < 1e-9 * h_try:   # absorb round-off: land on tf
                h_try = tf - t
            elif adaptive and h_try < step_floor(t):   # shrunk by accepted steps or a method's cap
                return None, self._underflow(t, h_try, "the step size shrank on accepted steps or to the "
                                             "method's largest stable step")
            self.monitor.before()
            try:
                with np.errstate(over="ignore", invalid="ignore"):   # detected here, reported
                    att = stepper.attempt(t, x, h_try)
                failure = None if np.all(np.isfinite(att.x1)) else "non-finite state"
            except StepFailure as err:
                att, failure = None, str(err)
            except MODEL_FAILURES as err:   # the right-hand side met a state it cannot evaluate
                att, failure = None, f"the right-hand side failed ({type(err).__name__}: {err})"
            if not adaptive:
                if failure is not None:
                    nonfin = [] if att is None else np.flatnonzero(~np.isfinite(att.x1))
                    bad = f" in component {int(nonfin[0])}" if len(nonfin) else ""
                    return None, f"{failure}{bad} at t = {t + h_try:.6g} s with fixed step h = {h:.3g} s"
                return self._candidate(att), None
            if failure is None:
                err = error_norm(att.err, x, att.x1, self.rtol, self.atol)
                accept, h_new = self.ctrl.propose(h_try, err, stepper.error_order, stepper.max_step())
            else:
                accept, h_new = False, 0.25 * h_try
                self.ctrl.rejected = True
            self.h = h_new
            if accept:
                return self._candidate(att), None
            self.stats.counts["nreject"] += 1
            if h_new < step_floor(t):
                return None, self._underflow(t, h_new, failure or f"the error estimate stayed above tolerance "
                                                                  f"(last error norm {err:.3g})")

    @staticmethod
    def _underflow(t: float, h: float, why: str) -> str:
        """The message of a step-size underflow at ``t`` with step ``h``, s, after ``why``."""
        return (f"step size underflow (h = {h:.3g} s) at t = {t:.6g} s: below the floor {step_floor(t):.3g} s "
                f"(16 spacings of doubles at t) after {why}; likely causes: a singularity or discontinuity of "
                f"the right-hand side near t, a tolerance below what double precision resolves there, or a "
                f"method that does not damp stiff components")

    def _candidate(self, att: Attempt) -> Candidate:
        stepper = self.stepper
        if att.interp is not None:
            return Candidate(att.t0, att.x0, att.h, att.t0 + att.h, att.x1, att.f0, att.interp, att)

        def dense(tq):
            if att.f1 is None:        # kept: accept() caches it as the next step's F0
                att.f1 = stepper.f(att.t0 + att.h, att.x1)
            if att.f0 is None:
                att.f0 = stepper.f(att.t0, att.x0)
            return hermite(att, att.f1, tq)

        def precise(tq):
            return stepper.solution_at(att, tq)
        exact = precise if stepper.substep_dense and self.adaptive else None
        return Candidate(att.t0, att.x0, att.h, att.t0 + att.h, att.x1, att.f0, dense, att, exact)

    def commit(self, cand: Candidate) -> None:
        self.stepper.accept(cand.raw)
        self.monitor.after(cand.raw)

    def restart(self, t: float, x: np.ndarray) -> None:
        """After an event: forget the history (the state or ``phi`` may have changed)."""
        self.stepper.reset()
        self.monitor.reset()

    def counts(self) -> dict[str, int]:
        """The counters (``stats.counts``)."""
        return self.stats.counts

    def set_counts(self, counts: dict[str, int]) -> None:
        self.stats.counts.update(counts)

    def memory_fields(self) -> tuple[tuple[str, int], ...]:
        """The method's memory and the step-size controller's."""
        return self.stepper.memory_fields() + (("controller", len(CONTROLLER_MEMORY)),)

    def state(self, t: float, x: np.ndarray) -> dict[str, np.ndarray]:
        return {**self.stepper.state(t, x), "controller": self.ctrl.memory()}

    def restore(self, state: dict[str, np.ndarray], t: float, x: np.ndarray) -> None:
        self.stepper.restore(state, t, x)
        if "controller" in state:   # absent in checkpoints written before it was kept
            self.ctrl.restore(state["controller"])

    def report(self) -> dict:
        """Extra stats (the local-error monitor of fixed steps, when active)."""
        return self.monitor.stats() if self.monitor.active else {}

    def warning(self) -> str | None:
        return self.monitor.warning() if self.monitor.active else None


def make_engine(method: str, system: OdeSystem, t0: float, y0, t_end: float, rtol: float, atol,
                h: float | None = None, adaptive: bool | None = None, error_check: int = 0,
                first_step: float | None = None, options: dict | None = None, controller: str | None = None):
    """The engine of ``method`` (a native or a scipy name, :mod:`cvtfem.integrate.methods`); ``controller``
    (``"i"``, ``"pi"``, ``"predictive"``, :mod:`cvtfem.integrate.controller`; None: the method's default)
    steers native adaptive runs."""
    if method in SCIPY_METHODS:
        from cvtfem.integrate.scipy_bridge import ScipyEngine

        return ScipyEngine(method, system, t0, y0, t_end, rtol, atol, first_step or h, options or {})
    if method not in METHODS:
        raise InputError("method", method, f"must be one of {sorted(METHODS) + sorted(SCIPY_METHODS)}")
    return NativeEngine(method, system, t0, y0, t_end, rtol, atol, h, adaptive, error_check, first_step, options,
                        controller)


class Stepping:
    """Step ``engine`` from ``(t0, x0)`` to ``t_end``, one accepted (possibly event-truncated) step
    per :meth:`step`.

    ``status`` is ``"running"``, ``"finished"`` (``t == t_end``), ``"event"`` (a terminal event
    fired; ``t`` is its time) or ``"failed"`` (``message`` says why; ``failure`` is ``"stall"``
    for the stall guard, else ``"numerical"``). After each step ``last`` is the step taken
    (``dense(t)`` its interpolant; truncated at an event), ``fired`` the mask of the event
    indicators that fired at its end (or None), ``t_events``/``y_events`` all events so far.

    The stall guard (``stall_steps`` > 0) fails a run after that many consecutive steps each
    shorter than ``stall_h``, s.
    """

    def __init__(self, engine, t0: float, x0, t_end: float, *, growth_limit: float | None = GROWTH_LIMIT,
                 event_location: str = "dense", event_samples: int = EVENT_SAMPLES,
                 max_steps: int = 10_000_000, max_events: int = 100_000, stall_steps: int = 0,
                 stall_h: float = 0.0) -> None:
        if growth_limit is not None and not growth_limit > 1:
            raise InputError("growth_limit", growth_limit, "must be a number > 1 or None")
        self.engine, self.system = engine, engine.system
        self.t, self.x, self.t0, self.t_end = float(t0), np.array(x0), float(t0), float(t_end)
        self.guard = GrowthGuard(growth_limit, self.x, engine.atol, engine.name, engine.adaptive)
        self.locator = (EventLocator(self.system, engine.stats, event_location, event_samples)
                        if self.system.n_events else None)
        if self.locator is not None:
            self.locator.start(self.t, self.x)
        self.max_steps, self.max_events = max_steps, max_events
        self.stall_steps, self.stall_h, self.tiny = stall_steps, stall_h, 0
        self.last_event, self.zeno = -np.inf, 0
        self.t_events = [[] for _ in range(self.system.n_events)]
        self.y_events = [[] for _ in range(self.system.n_events)]
        self.status, self.message, self.failure = "running", "", None
        self.t_fail = float("nan")   # where a failure was detected (a blown-up step's end), s
        self.monitor = getattr(engine, "monitor", None)   # local-error monitor of fixed steps
        self.last: Candidate | None = None
        self.fired: np.ndarray | None = None

    @property
    def counts(self) -> dict[str, int]:
        return self.engine.counts()

    @property
    def h(self) -> float:
        """Proposed size of the next step, s."""
        return self.engine.h

    def _fail(self, message: str, failure: str = "numerical", t: float | None = None) -> bool:
        self.status, self.message, self.failure = "failed", message, failure
        self.t_fail = self.t if t is None else t
        return False

    def step(self) -> bool:
        """One accepted step: True when a step was taken (``last``; ``status`` may say the run stops
        after it), False when none was (``status`` "failed", or the run was over)."""
        if self.status != "running":
            return False
        counts = self.engine.counts()
        if counts["nsteps"] >= self.max_steps:
            return self._fail(f"`max_steps` = {self.max_steps} reached at t = {self.t:.6g} s")
        t, x = self.t, self.x
        cand, why = self.engine.advance(t, x, self.t_end)
        if cand is None:
            return self._fail(why)
        blow_up = self.guard.check(x, cand.x1, cand.h, cand.f0)
        if blow_up is not None:
            kind = "adaptive" if self.engine.adaptive else "fixed"
            return self._fail(f"{blow_up} at t = {cand.t1:.6g} s with {kind} step h = {cand.h:.3g} s"
                              f"{self.guard.hint()}", t=cand.t1)
        counts = self.engine.counts()
        counts["nsteps"] += 1
        t1, x1 = cand.t1, cand.x1
        hit = None if self.locator is None else self.locator.locate(t, x, t1, x1, cand.dense, cand.precise)
        self.fired = None
        if hit is not None:
            t1, x1, self.fired, _ = hit
            counts["nevents"] += 1
            counts["ntruncated"] += 1
            cand.t1, cand.x1 = t1, x1
        self.engine.commit(cand)
        self.last = cand
        self.t, self.x = t1, x1
        self.guard.update(x1)
        if self.stall_steps:
            self.tiny = self.tiny + 1 if t1 - t < self.stall_h else 0
            if self.tiny >= self.stall_steps:
                self._fail("step size stalled", "stall")
                return True
        if hit is not None:
            return self._event(cand.h)
        if self.t >= self.t_end:
            self.status = "finished"
        return True

    def _event(self, h_step: float) -> bool:
        t, fired, system = self.t, self.fired, self.system
        for k in np.flatnonzero(fired):
            self.t_events[k].append(t)
            self.y_events[k].append(self.x.copy())
        if system.switch is not None:
            new = system.switch(t, self.x.copy(), fired)
            if new is not None:
                self.x = np.array(new, dtype=self.x.dtype)
                self.guard.update(self.x)
        self.engine.restart(t, self.x)
        self.locator.start(t, self.x, fired)
        if np.any(fired & system.event_terminal):
            self.status, self.message = "event", "A termination event occurred."
            return True
        gap = max(ZENO_GAP * (self.t_end - self.t0), ZENO_GAP_H * h_step)
        self.zeno = self.zeno + 1 if t - self.last_event < gap else 0
        self.last_event = t
        if self.zeno >= ZENO_COUNT:
            self._fail(f"{ZENO_COUNT + 1} events less than {gap:.3g} s apart "
                       f"accumulate at t = {t:.12g} s (Zeno behaviour)")
        elif self.engine.counts()["nevents"] >= self.max_events:
            self._fail(f"`max_events` = {self.max_events} reached at t = {t:.6g} s (Zeno?)")
        elif self.t >= self.t_end:
            self.status = "finished"
        return True

    def dense(self, t: float) -> np.ndarray:
        """The last step's interpolant at one time ``t`` in ``[last.t0, t]``, s.

        :class:`NumericalError` when the interpolant needs the right-hand side at a state it cannot evaluate
        (a diverging fixed-step run: the step's end is finite, its slope is not).
        """
        try:
            return self.last.dense(t)
        except MODEL_FAILURES as err:
            raise NumericalError(f"{self.engine.name}: the right-hand side failed at the end of the last step "
                                 f"({type(err).__name__}: {err}); the run is diverging", t=self.last.t1,
                                 component="dense output") from None

    # --- memory -------------------------------------------------------------------------------

    def fields(self) -> tuple[tuple[str, int], ...]:
        """``((name, size), ...)`` of :meth:`state`: the loop's own memory, then the method's."""
        return loop_fields(len(self.x), self.system.n_events) + self.engine.memory_fields()

    def state(self) -> dict[str, np.ndarray]:
        """The full memory at the current point as named float arrays (sizes: :meth:`fields`)."""
        loc, m = self.locator, self.system.n_events
        counts = self.engine.counts()

        def ev(a):
            return np.full(m, np.nan) if a is None else np.asarray(a, dtype=float)

        return {"t": np.array([self.t]), "x": np.array(self.x, dtype=float), "h": np.array([self.engine.h]),
                "counts": np.array([counts[c] for c in COUNTERS], dtype=float),
                "largest": np.array([self.guard.largest]), "tiny": np.array([float(self.tiny)]),
                "zeno": np.array([float(self.zeno)]), "last_event": np.array([self.last_event]),
                "monitor": self.monitor.snapshot() if self.monitor is not None else np.zeros(5),
                "events_g0": ev(None if loc is None else loc.g0), "events_side": ev(None if loc is None else loc.side),
                "events_ga": ev(None if loc is None else loc._ga), **self.engine.state(self.t, self.x)}

    def restore(self, state: dict[str, np.ndarray], memory: bool = True) -> None:
        """Continue from :meth:`state` in a ``Stepping`` built at its ``t, x`` (with ``h`` as first step).
        ``memory`` False keeps the method's fresh memory (a retry with other settings)."""
        self.guard.largest = max(self.guard.largest, float(state["largest"][0]))
        self.tiny, self.zeno = int(state["tiny"][0]), int(state["zeno"][0])
        self.last_event = float(state["last_event"][0])
        if self.locator is not None and not np.all(np.isnan(state["events_g0"])):
            self.locator.g0 = np.array(state["events_g0"])
            self.locator.side = np.array(state["events_side"])
            ga = state["events_ga"]
            self.locator._ga = None if np.all(np.isnan(ga)) else np.array(ga)
        if self.monitor is not None:
            self.monitor.restore(state["monitor"])
        if memory:
            self.engine.restore(state, self.t, self.x)
        self.engine.set_counts({c: int(v) for c, v in zip(COUNTERS, state["counts"])})


def loop_fields(n: int, n_events: int) -> tuple[tuple[str, int], ...]:
    """The loop's own part of :meth:`Stepping.fields` (state, step size, counters, guards, events)."""
    m = n_events
    return (("t", 1), ("x", n), ("h", 1), ("counts", len(COUNTERS)), ("largest", 1), ("tiny", 1),
            ("zeno", 1), ("last_event", 1), ("monitor", 5), ("events_g0", m), ("events_side", m), ("events_ga", m))


def state_fields(method: str, n: int, n2: int = 0, n_events: int = 0, jac_sparsity=None):
    """:meth:`Stepping.fields` of a run of ``method`` without building it (checkpoint layouts)."""
    return loop_fields(n, n_events) + memory_fields(method, n, n2, jac_sparsity)


def memory_fields(method: str, n: int, n2: int = 0, jac_sparsity=None, options: dict | None = None,
                  split=None) -> tuple[tuple[str, int], ...]:
    """The method part of :meth:`Stepping.fields` for ``n`` states, without building a run (``options`` and the
    model's stiff ``split`` as the run's: ``strang-friction``'s memory is its explicit method's)."""
    if method in SCIPY_METHODS:
        from cvtfem.integrate.scipy_bridge import scipy_fields

        return scipy_fields(method, n, jac_sparsity)
    system = as_system(lambda t, x: x, np.zeros(n), n2=n2, jac_sparsity=jac_sparsity, split=split)
    stepper = METHODS[method](system, Stats(), **(options or {}))
    return stepper.memory_fields() + (("controller", len(CONTROLLER_MEMORY)),)
