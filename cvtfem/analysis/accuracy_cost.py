"""What accuracy costs on a running chain transmission: the source's chapter-2 protocol (issue 16).

Spec ``numerics-and-periodic.md`` section 9.  On a chain-CVT scene started in its quasi-static state:

* the spectrum of the Jacobian at a state of the run, and the same spectrum with the friction saturation
  speed ``v0`` divided by 10 (section 9.2: which eigenvalues friction makes);
* test 2 (section 9.5): the global error ``E = max |P - P*| / max |P*|`` over a window ``[t1, t2]`` of the
  axial force ``P`` of the pin that enters a sheave in the window (A:(2.9)), for each method and step or
  tolerance, with its cost (wall time, RHS calls, Jacobians, LU factorisations);
* the reference ``P*`` computed two independent ways whose mutual ``E`` is reported (it must be far below the
  acceptance 0.05 for the study to mean anything);
* test 1 (section 9.4): the local error of one step of size ``h`` from a state of the run, in a norm weighted
  per state block (positions, velocities, first-order states: section 9.7), and the effective order (A:(2.8)).

On a chain with independent pin halves (A5: variants (e) and (zh)) the output is the axial force of one pin half,
the source's quantity for (e); on a band model the sheave normal force (N/m) at the Gauss node whose force varies
most (the band has no pins); everything else is the same.  Where the start is far from a steady state (A5's
quasi-static solve can stall and leave the chain placed off balance), the study can start after a settling
interval, from the state the reference method reaches there.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.stabilized import rkc1_coefficients
from cvtfem.problems.base import Problem

__all__ = ["PinForceProblem", "chain_output", "energy_balance", "cvt_problem", "pin_force_problem", "output_of",
           "output_component", "window_error", "jacobian_spectrum", "spectrum_with_v0", "local_error_table", "block_scales", "baseline_time", "state_at",
           "StudyCache", "ACCEPT_E", "ACCEPT_ENERGY", "operation_costs", "rhs_equivalents", "distinct_labels"]

#: The source's acceptance of test 2.
ACCEPT_E = 0.05
#: Second acceptance (ours): |energy balance residual| over the run, relative to the input work.  A tenth of the 1 %
#: to which issue 14 asks a run's balance to close, and a fifth of the smallest loss (0.5 % of the input at 99.5 %
#: efficiency): a run that chatters in stick (RK4 beyond its stability limit, rock4 at rtol 1e-2 on variant (e))
#: dissipates work that E hardly shows (docs/accuracy-cost.md, sessions 9-10).
ACCEPT_ENERGY = 1e-3
#: Output of the chain families whose global error test 2 measures.
PIN_FORCE = "chain.pin_axial_force"
#: Output of the chains with independent pin halves (A5): axial force of each half, N (half -, then half +).
HALF_FORCE = "chain.pin_half_axial_force"
#: Output of the band models measured instead (they have no pins): sheave normal force per Gauss node, N/m.
BAND_FORCE = "band.normal_force"


def window_error(p, p_ref) -> float:
    """``E = max |p - p_ref| / max |p_ref|`` over the samples given (A:(2.9)); ``inf`` for non-finite ``p``."""
    p, p_ref = np.asarray(p, float), np.asarray(p_ref, float)
    if p.shape != p_ref.shape or not np.all(np.isfinite(p)):
        return float("inf")
    return float(np.max(np.abs(p - p_ref)) / np.max(np.abs(p_ref)))


@dataclass(frozen=True)
class PinForceProblem(Problem):
    """A CVT from its start state over ``[0, t2]``; the error of a run is :func:`window_error` of component
    ``pin`` of the output ``output`` (a pin's axial force, or a band model's normal force at a Gauss node) at the
    samples ``t_eval`` of the window ``[t1, t2]``."""

    loop: object = None
    pin: int = 0
    t_eval: np.ndarray = field(default_factory=lambda: np.zeros(0))
    p_ref: np.ndarray = field(default_factory=lambda: np.zeros(0))
    output: str = PIN_FORCE

    def solve_kwargs(self) -> dict:
        """:class:`Problem`'s, with the loop's stiff split (A5's halves' friction) where it has one."""
        split = getattr(self.loop, "stiff_split", None)
        return {**super().solve_kwargs(), **({"split": split} if split is not None else {})}

    def pin_forces(self, y, t=None) -> np.ndarray:
        """The output (samples, components) at the states ``y`` (n, samples) and times ``t`` (default
        ``t_eval``): a chain's pin axial forces (N) from the chain family's output alone (the contacts and loops
        of the full output set are not needed for it), a band's normal forces (N/m) from the loop's outputs."""
        t = self.t_eval if t is None else t
        if self.output == BAND_FORCE:
            return np.array([self.loop.outputs(ti, yi)[BAND_FORCE] for ti, yi in zip(t, np.asarray(y).T)])
        return chain_output(self.loop, y, self.output)

    def warm_up(self) -> None:
        """One right-hand side, one Jacobian where the loop has one, each stiff split's explicit part and friction
        solve (over 1 ns) and its friction rate where it has one, and the output at the start state: the one-off costs
        of a process (loading or compiling the kernels) then stay out of the first timed run (session 13: a first imex
        row took 53 s CPU of which ~45 s were the friction kernels' compilation)."""
        kw = Problem.solve_kwargs(self)
        t0, y0 = kw["t_span"][0], kw["y0"]
        kw["fun"](t0, y0)
        if kw.get("jac") is not None:
            kw["jac"](t0, y0)
        split = getattr(self.loop, "stiff_split", None)
        if split is not None:
            n2 = self.loop.n2
            for explicit, solve, *rest in (split[:3], *(split[3] or {}).values()):
                explicit(t0, y0)
                solve(t0, y0, 1e-9)
                if len(rest) > 2 and rest[2] is not None:                   # multirate-rk4's friction rate
                    rate = rest[2](y0)
                    rate.bound(None, 1)
                    rate.advance(y0[n2:2 * n2], y0[n2:2 * n2], 1e-9, rkc1_coefficients(2))
        self.pin_forces(np.asarray(self.y0)[:, None], [t0])

    def error(self, res) -> float:
        if not res.success or len(res.t) != len(self.t_eval):
            return float("inf")
        return window_error(self.pin_forces(res.y, res.t)[:, self.pin], self.p_ref)

    def energy_balance(self, res) -> dict:
        """The run's energy balance from its start state ``y0`` to its last sample: ``energy_residual`` = (input
        work - output work - dissipated work + clamping work - change of the stored energy) / input work (the work
        integrals are states the method integrates, so a method that chatters in stick, or loses energy, shows
        here) and ``dissipated`` (friction and damping, J); empty where the loop has no work integrals."""
        loop = self.loop
        if not res.success or not (hasattr(loop, "energy") and hasattr(loop, "split")):
            return {}
        return energy_balance(loop, self.y0, res.y[:, -1])


def chain_output(loop, y, name: str) -> np.ndarray:
    """The chain family's output ``name`` (samples, components) at the states ``y`` (n, samples) of the transmission
    ``loop``, from the family's own outputs (the contacts and loops of the full output set are not needed)."""
    fam, out = loop.family, []
    for yi in np.asarray(y).T:
        q, v = loop.split(yi)[:2]
        out.append(fam.outputs(q[:fam.size], v[:fam.size])[name])
    return np.array(out)


def energy_balance(loop, x0, x1) -> dict:
    """``energy_residual`` = (input work - output work - dissipated work + clamping work - change of the stored
    energy) / input work from state ``x0`` to ``x1`` of the transmission ``loop``, and ``dissipated`` (friction and
    damping, J); empty where the loop has no four work integrals or no input work."""
    x0, x1 = np.asarray(x0, float), np.asarray(x1, float)
    dW = np.asarray(loop.split(x1)[3]) - np.asarray(loop.split(x0)[3])
    if len(dW) != 4 or not dW[0] > 0:
        return {}
    residual = dW[0] - dW[1] - dW[2] + dW[3] - (loop.energy(x1) - loop.energy(x0))
    return {"energy_residual": float(residual / dW[0]), "dissipated": float(dW[2])}


#: Packages whose code decides a run's result: the model (its start state and the references) ...
MODEL_CODE = ("elements", "assembly", "machines", "control", "problems", "scene")
#: ... and, for the rows of test 2, also the integrators.
RUN_CODE = MODEL_CODE + ("integrate",)


def code_stamp(dirs: tuple[str, ...]) -> str:
    """A short digest (hex) of the cvtfem sources under ``dirs``: what a cached result was computed with."""
    from cvtfem.io.sources import sources_digest

    return sources_digest(str(Path(__file__).resolve().parents[1]), dirs).hex()[:16]


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:                      # another user's process
        return True
    return True


class StudyCache:
    """Runs of one study kept in a directory, so that a long study can be resumed or split over processes: the
    reference runs' outputs (``reference-METHOD-RTOL.npy``, every component at every sample) and the rows of test 2
    (``runs.json``, wall and CPU times as measured when they ran).  ``key`` names the study (scene, window, samples,
    start); a directory holding another study's runs is refused.  Every result carries the :func:`code_stamp` of the
    sources it was computed with; one computed with other code (or with no stamp) is run again, not reused."""

    def __init__(self, path, key: str):
        self.model_code, self.run_code = code_stamp(MODEL_CODE), code_stamp(RUN_CODE)
        self.path = Path(path)
        self.path.mkdir(parents=True, exist_ok=True)
        stamp = self.path / "key.txt"
        if stamp.exists() and stamp.read_text(encoding="utf-8") != key:
            raise InputError("--cache", str(path), f"must hold runs of this study ({key}), not of "
                                                   f"{stamp.read_text(encoding='utf-8')}: use another directory")
        stamp.write_text(key, encoding="utf-8")
        runs = self.path / "runs.json"
        self.rows: dict = json.loads(runs.read_text(encoding="utf-8")) if runs.exists() else {}

    @classmethod
    def existing(cls, path) -> StudyCache:
        """The cache a study left at ``path``, opened under its own key (to read its references and start)."""
        stamp = Path(path) / "key.txt"
        if not stamp.exists():
            raise InputError("cache", str(path), "must be a directory a study wrote with --cache (it has key.txt)")
        return cls(path, stamp.read_text(encoding="utf-8"))

    def _file(self, method: str, rtol: float, suffix: str) -> Path:
        return self.path / f"reference-{method}-{rtol:g}.{suffix}"

    def reference(self, method: str, rtol: float, wait: bool = False):
        """The cached output (samples, components) of a reference run, or ``None``; ``wait``: for the run another
        process has marked running (polls every 10 s)."""
        while wait and not self._file(method, rtol, "npy").exists() and self.running(method, rtol):
            time.sleep(10)
        f = self._file(method, rtol, "npy")
        return np.load(f) if f.exists() and self._current(self._file(method, rtol, "code")) else None

    def _current(self, stamp: Path) -> bool:
        """Whether the result stamped in ``stamp`` was computed with today's model code."""
        return stamp.exists() and stamp.read_text(encoding="utf-8") == self.model_code

    def stale_rows(self) -> list[str]:
        """Keys of the kept rows of test 2 computed with other code than today's (or before rows were stamped)."""
        return [key for key, row in self.rows.items() if row.get("code") != self.run_code]

    def row(self, key: str) -> dict | None:
        """The kept row ``key`` if it was computed with today's code, else ``None``."""
        row = self.rows.get(key)
        return row if row is not None and row.get("code") == self.run_code else None

    def running(self, method: str, rtol: float) -> bool:
        """True while a process computes this reference run: its mark (the process id) is removed when the run is
        kept; a mark whose process is gone (killed before it could remove it) is removed here, so no study waits for
        it.  The processes sharing a cache run on one machine."""
        mark = self._file(method, rtol, "running")
        try:
            pid = int(mark.read_text(encoding="utf-8"))
        except (FileNotFoundError, ValueError):
            pid = None
        if pid is not None and _alive(pid):
            return True
        mark.unlink(missing_ok=True)
        return False

    def mark_running(self, method: str, rtol: float) -> None:
        tmp = self._file(method, rtol, f"running.{os.getpid()}")
        tmp.write_text(str(os.getpid()), encoding="utf-8")
        tmp.replace(self._file(method, rtol, "running"))           # complete before it appears

    def clear_running(self, method: str, rtol: float) -> None:
        self._file(method, rtol, "running").unlink(missing_ok=True)

    def keep_reference(self, method: str, rtol: float, p) -> None:
        np.save(self._file(method, rtol, "tmp.npy"), np.asarray(p))      # complete before it appears
        self._file(method, rtol, "tmp.npy").replace(self._file(method, rtol, "npy"))
        self._file(method, rtol, "code").write_text(self.model_code, encoding="utf-8")

    def start(self):
        """The kept start state ``(x0, description)`` of the study's runs, or ``None``."""
        f = self.path / "start.npy"
        if not f.exists() or not self._current(self.path / "start.code"):
            return None
        return np.load(f), (self.path / "start.txt").read_text(encoding="utf-8")

    def keep_start(self, x0, kind: str) -> None:
        """Keep the start state (the quasi-static solve of an A5 chain costs about a minute of CPU per process)."""
        (self.path / "start.txt").write_text(kind, encoding="utf-8")
        np.save(self.path / "start.tmp.npy", np.asarray(x0, float))
        (self.path / "start.tmp.npy").replace(self.path / "start.npy")
        (self.path / "start.code").write_text(self.model_code, encoding="utf-8")

    def face_ref(self) -> np.ndarray | None:
        """The kept sheave faces' reference positions (2, 2) m of a chain on elastic shafts, or ``None``."""
        f = self.path / "face_ref.npy"
        return np.load(f) if f.exists() and self._current(self.path / "face_ref.code") else None

    def keep_face_ref(self, z_ref) -> None:
        """Keep the faces' reference positions (the rigid start that sets them costs about a minute of CPU per process
        on (e) at the chapter-2 regime, again in every process that builds the model)."""
        np.save(self.path / "face_ref.tmp.npy", np.asarray(z_ref, float))
        (self.path / "face_ref.tmp.npy").replace(self.path / "face_ref.npy")
        (self.path / "face_ref.code").write_text(self.model_code, encoding="utf-8")

    def keep_row(self, key: str, row: dict) -> None:
        """Keep a row of test 2 (re-reading the file first: another process may have added rows)."""
        runs = self.path / "runs.json"
        self.rows = json.loads(runs.read_text(encoding="utf-8")) if runs.exists() else {}
        self.rows[key] = {k: (float(v) if isinstance(v, (np.floating, float)) else v) for k, v in row.items()}
        self.rows[key]["code"] = self.run_code
        runs.write_text(json.dumps(self.rows, indent=0), encoding="utf-8")


def output_of(scene, loop) -> str:
    """The output test 2 measures on the scene's ``loop``: a pin half's axial force on A5, a pin's on the other
    chains, the sheave normal force on a band model."""
    if not scene.cvt.model.startswith("chain"):
        return BAND_FORCE
    names = {s.name for s in loop.family.output_specs}
    return HALF_FORCE if HALF_FORCE in names else PIN_FORCE


def output_component(report: dict) -> str:
    """What component ``report["pin"]`` of the report's output is: ``"pin 40"``, ``"pin 12, half +"`` (A5's halves:
    half ``-`` of every pin, then half ``+``), ``"Gauss node 3"``."""
    k = report["pin"]
    if report["output"] == HALF_FORCE:
        return f"pin {k % report['pins']}, half {'-+'[k // report['pins']]}"
    return f"Gauss node {k}" if report["output"] == BAND_FORCE else f"pin {k}"


def cvt_problem(scene, t_end: float, settle: float = 0.0, settle_by: tuple[str, float] = ("Radau", 1e-8),
                placed: bool = False, cache: StudyCache | None = None) -> tuple[PinForceProblem, dict]:
    """The scene's closed loop from its start state (``loop.start()``: quasi-static, or placed off balance where
    that solve stalls) over ``[0, t_end]``, or, with ``settle > 0`` (s), from the state that ``settle_by`` (method,
    rtol; ``atol = 1e-3 rtol``) reaches at ``settle``, over ``[settle, t_end]``; and a report of the start.
    ``placed``: start from the chain placed on the sheaves (``placed_state``, A5 only) without trying the
    quasi-static solve (which stalls at the chapter-2 regime after about 150 evaluations: docs/accuracy-cost.md).
    ``cache``: take the start state from there where it holds one (before any settling), else keep it there."""
    from cvtfem.machines.cvt import closed_loop

    if not (0 <= settle < t_end and np.isfinite(t_end)):
        raise InputError("--settle", settle, f"must be a time in 0..{t_end:g} s (before the run's end)")
    loop = closed_loop(scene)
    if placed and not hasattr(loop, "placed_state"):
        raise InputError("--placed", scene.cvt.model, "must be a chain with independent pin halves (chain-A5): only "
                         "they have a placed start state")
    kept = cache.start() if cache is not None else None
    elastic = hasattr(type(loop), "face_ref")      # a chain on elastic shafts (the class: no solve to ask)
    z_ref = cache.face_ref() if cache is not None and elastic else None
    if z_ref is not None:                 # the rigid start that sets the faces' positions, not solved again
        loop = replace(loop, z_ref=z_ref)
    if kept is not None:
        x0, start = kept[0], {"kind": kept[1]}
    elif placed:
        w1, _, ratio = loop.regime.targets(0.0)
        x0, start = loop.placed_state(ratio, w1), {"kind": "placed on the sheaves, off balance (no quasi-static solve)"}
    else:
        x0, start = loop.start()
    if cache is not None and kept is None:
        cache.keep_start(x0, start["kind"])
    if cache is not None and z_ref is None and elastic:
        cache.keep_face_ref(loop.face_ref)
    sparsity = loop.jac_sparsity() if callable(loop.jac_sparsity) else loop.jac_sparsity
    problem = PinForceProblem(scene.cvt.model, loop.rhs, x0, (0.0, t_end), n2=loop.n2, jac=loop.jac,
                              jac_sparsity=sparsity, loop=loop, output=output_of(scene, loop),
                              info={"n": len(x0), "n2": loop.n2})
    if settle > 0:
        problem = replace(problem, y0=state_at(problem, settle, *settle_by), t_span=(settle, t_end))
    report = {"start": start["kind"], "settle": settle,
              "settled_by": f"{settle_by[0]} rtol {settle_by[1]:g}" if settle > 0 else None}
    return problem, report


def pin_force_problem(scene, window: tuple[float, float] = (1e-3, 5e-3), sample: float = 1e-5,
                      reference: tuple[str, float] = ("Radau", 1e-8),
                      check: tuple[str, float] = ("rodas5p", 1e-8), settle: float = 0.0,
                      placed: bool = False, cache: StudyCache | None = None) -> tuple[PinForceProblem, dict]:
    """Test 2 of the protocol on a CVT scene: the problem, and a report of its reference.

    The pin (or pin half, on A5) is the one whose axial force varies most over the window in the reference run (a
    pin entering or leaving an arc: the sharply varying output of A:(2.9)); on a band model the Gauss node whose
    normal force varies most.  ``reference`` and ``check`` are two methods with their rtol (``atol = 1e-3 rtol``,
    analytic sparse Jacobian); the report holds the ``E`` between them.  The run starts as :func:`cvt_problem`
    (``settle``: by the reference method; ``placed``), so both references share the start state.  ``cache``: take
    the reference outputs from there where it holds them, and keep those computed.
    """
    t1, t2 = (float(v) for v in window)
    if not (0 <= t1 < t2 and np.isfinite(t2)):
        raise InputError("--window", window, "must be two simulated times 0 <= t1 < t2, s")
    if not (0 < sample <= (t2 - t1) / 4):
        raise InputError("--sample", sample, f"must be positive and give at least 4 samples in {t2 - t1:g} s")
    if not 0 <= settle <= t1:
        raise InputError("--settle", settle, f"must be a time in 0..{t1:g} s (T1 of --window)")
    base, start = cvt_problem(scene, t2, settle, reference, placed, cache)
    t_eval = np.arange(t1, t2 + 0.5 * sample, sample)
    t_eval = t_eval[t_eval <= t2]
    base = replace(base, t_eval=t_eval)
    forces = {}
    for method, rtol in sorted((reference, check), key=lambda mr: cache is not None and cache.running(*mr)):
        forces[method] = cache.reference(method, rtol, wait=False) if cache is not None else None
        if forces[method] is None and cache is not None and cache.running(method, rtol):
            forces[method] = cache.reference(method, rtol, wait=True)      # another process computes it
        if forces[method] is None:
            forces[method] = _reference_run(base, method, rtol, cache)
    p_all = forces[reference[0]]
    pin = int(np.argmax(np.ptp(p_all, axis=0)))
    problem = replace(base, pin=pin, p_ref=p_all[:, pin])
    report = {**start, "output": base.output, "pin": pin, "pins": getattr(base.loop.family, "n", 0),
              "samples": len(t_eval), "window": (t1, t2),
              "reference": f"{reference[0]} rtol {reference[1]:g}", "check": f"{check[0]} rtol {check[1]:g}",
              "reference_E": window_error(forces[check[0]][:, pin], p_all[:, pin]),
              "force_range": (float(p_all[:, pin].min()), float(p_all[:, pin].max()))}
    return problem, report


def _reference_run(base: PinForceProblem, method: str, rtol: float, cache: StudyCache | None) -> np.ndarray:
    """The output (samples, components) of ``base`` run by ``method`` at ``rtol``, kept in ``cache``."""
    from cvtfem.integrate import solve

    if cache is not None:
        cache.mark_running(method, rtol)
    try:
        res = solve(**base.solve_kwargs(), method=method, rtol=rtol, atol=1e-3 * rtol, t_eval=base.t_eval)
        if not res.success:
            raise InputError("reference", method, f"must complete the reference run: {res.message}")
        p = base.pin_forces(res.y)
        if cache is not None:
            cache.keep_reference(method, rtol, p)
    finally:
        if cache is not None:
            cache.clear_running(method, rtol)
    return p


def jacobian_spectrum(loop, x, t: float = 0.0) -> np.ndarray:
    """Eigenvalues (1/s) of the Jacobian of ``loop`` at ``(t, x)``, dense (n up to a few thousand)."""
    J = loop.jac(t, x)
    J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
    return np.linalg.eigvals(J)


def spectrum_with_v0(scene, x, factor: float = 0.1, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Spectra of the scene's loop at ``(t, x)`` with the friction saturation speed ``v0`` as given and times
    ``factor`` (section 9.2's attribution: eigenvalues that move by ``1/factor`` come from friction)."""
    from cvtfem.machines.cvt import closed_loop

    v0 = scene.cvt.friction.v0
    changed = scene.replace({"cvt": {"friction": {"v0": v0 * factor}}})
    return jacobian_spectrum(closed_loop(scene), x, t), jacobian_spectrum(closed_loop(changed), x, t)


def operation_costs(problem: Problem, h: float = 2e-6, repeats: int = 7) -> dict:
    """CPU time (s, median of ``repeats``; of 10 times as many for the RHS call, whose sub-millisecond CPU time the
    load scatters most) of one RHS call, one Jacobian, one LU of the reduced ``I - h gamma J``
    (building the matrix and factoring it; ``gamma = 1 - 1/sqrt(2)``, SW24's) and one full solve with it, at the
    problem's start state, and the last three in RHS-equivalents (``*_rhs``): the weights of
    :func:`rhs_equivalents`.  Empty without a Jacobian."""
    from cvtfem.integrate.linsolve import LU, reduced_matrix
    from cvtfem.integrate.stats import Stats

    if problem.jac is None:
        return {}
    t0, x0, n2 = problem.t_span[0], np.asarray(problem.y0, float), problem.n2
    g = h * (1.0 - 1.0 / np.sqrt(2.0))

    def cpu(fn, k=repeats):
        times, out = [], None
        for _ in range(k):
            c = time.process_time()
            out = fn()
            times.append(time.process_time() - c)
        return float(np.median(times)), out

    t_rhs, f0 = cpu(lambda: problem.fun(t0, x0), 10 * repeats)
    t_jac, J = cpu(lambda: problem.jac(t0, x0))
    J = J.tocsr() if hasattr(J, "tocsr") else np.asarray(J)
    t_lu, lu = cpu(lambda: LU(Stats(), reduced_matrix(J, n2, g), n2, g, J[n2:, :n2]))
    t_solve, _ = cpu(lambda: lu.solve_full(f0))
    out = {"rhs": t_rhs, "jac": t_jac, "lu": t_lu, "solve": t_solve, "h": h}
    out.update({f"{k}_rhs": out[k] / t_rhs for k in ("jac", "lu", "solve")})
    return out


#: Methods whose LU count is not of the full system (``strang-friction``: the friction solves' Newton iterations on
#: the slip matrix), so their runs have no RHS-equivalents: their cost is their CPU time.
UNPRICED = frozenset({"strang-friction"})


def rhs_equivalents(row: dict, costs: dict) -> float | None:
    """A run's cost in RHS calls: its RHS calls plus its Jacobians, LUs and solves weighted by ``costs`` (from
    :func:`operation_costs`; counters a method does not report, -1 or absent, count 0); None for the methods of
    :data:`UNPRICED` (pricing their friction iterations as full LUs understated them 2.5x in session 13)."""
    if row.get("method") in UNPRICED:
        return None
    total = float(row["nfev"])
    for count, weight in (("njev", "jac_rhs"), ("nlu", "lu_rhs"), ("nsolve", "solve_rhs")):
        total += max(row.get(count) or 0, 0) * costs.get(weight, 0.0)
    return total


def measure(problem: PinForceProblem, fixed, steps, adaptive, rtols, repeats: int = 3,
            cache: StudyCache | None = None) -> list[dict]:
    """Test 2 for every fixed-step method at every step ``h`` (s) and every adaptive method at every rtol
    (``atol = 1e-3 rtol``): rows of :func:`~cvtfem.integrate.study.work_precision` (error = ``E``, wall time =
    median of ``repeats``, RHS calls, Jacobians, LU factorisations) with a ``setting`` label and ``cpu``, the CPU
    time per run (s, with the error's evaluation); a method run both ways is labelled ``"NAME adaptive"`` in its
    adaptive runs.  ``cache``: rows found there (computed with today's code) are not run again, rows run are kept
    there."""
    from cvtfem.integrate.study import work_precision

    both = {label for label, _, _ in fixed} & {label for label, _, _ in adaptive}
    runs = [(label, method, {**opts, "h": h, "adaptive": False, "t_eval": problem.t_eval})
            for label, method, opts in fixed for h in steps]
    runs += [(label + " adaptive" if label in both else label, method,
              {**opts, "rtol": r, "atol": 1e-3 * r, "t_eval": problem.t_eval})
             for label, method, opts in adaptive for r in rtols]
    rows, warm = [], False
    for label, method, opts in runs:
        setting = f"h={opts['h']:g}" if "h" in opts else f"rtol={opts['rtol']:g}"
        key = f"{label} {method} {setting}"
        kept = cache.row(key) if cache is not None else None
        if kept is not None:
            rows.append(kept)
            continue
        if not warm:                     # the process's one-off costs out of the first timed run
            problem.warm_up()
            warm = True
        balance = {}

        def error(res):
            balance.update(problem.energy_balance(res))
            return problem.error(res)

        cpu = time.process_time()
        (row,) = work_precision(problem, [(label, method, opts)], repeats=repeats, error=error)
        row.update(setting=setting, cpu=(time.process_time() - cpu) / repeats, **balance)
        if cache is not None:
            cache.keep_row(key, row)
        rows.append(row)
    return rows


def distinct_labels(rows: list[dict]) -> list[dict]:
    """The rows with the adaptive runs of a method that also has fixed-step runs labelled ``"NAME adaptive"``
    (:func:`measure` does so within one call; rows gathered from a cache filled by several calls need it here)."""
    fixed = {r["label"] for r in rows if not str(r.get("setting", "")).startswith("rtol")}
    out = []
    for r in rows:
        adaptive = str(r.get("setting", "")).startswith("rtol")
        out.append({**r, "label": r["label"] + " adaptive"} if adaptive and r["label"] in fixed else r)
    return out


def accepted(row: dict, accept: float = ACCEPT_E, accept_energy: float | None = ACCEPT_ENERGY) -> bool:
    """``E <= accept`` and, where the row has it and ``accept_energy`` is set, ``|energy residual| <=
    accept_energy``."""
    if not row["error"] <= accept:
        return False
    residual = row.get("energy_residual")
    return accept_energy is None or residual is None or abs(residual) <= accept_energy


def speedups(rows: list[dict], baseline: dict | None, accept: float = ACCEPT_E, costs: dict | None = None,
             accept_energy: float | None = ACCEPT_ENERGY) -> list[dict]:
    """Per method, its cheapest accepted run (:func:`accepted`: ``E <= accept`` and the energy balance; cheapest by
    CPU time where every candidate has one, else by wall time) and its speed-up over ``baseline`` (the source's
    Table 2.4: RK4 at h = 5e-8 s): by wall time (``speedup``), by CPU time (``speedup_cpu``, where both have it) and
    by RHS-equivalents (``speedup_rhs``: the baseline's RHS calls over :func:`rhs_equivalents` of the run, with
    ``costs`` from :func:`operation_costs`); a method with no accepted run gets ``None``.  The energy balance's
    residual and the dissipated work of the run (:meth:`PinForceProblem.energy_balance`) come along where measured.
    """
    out = []
    for label in dict.fromkeys(r["label"] for r in rows):
        ok = [r for r in rows if r["label"] == label and accepted(r, accept, accept_energy)]
        by = "cpu" if ok and all(r.get("cpu") for r in ok) else "time"
        best = min(ok, key=lambda r: r[by]) if ok else None
        entry = {"label": label, "setting": best["setting"] if best else None,
                 **{k: best.get(k) if best else None for k in ("error", "time", "cpu", "nfev", "njev", "nlu",
                                                              "nsolve", "nsteps", "energy_residual", "dissipated")},
                 "speedup": baseline["time"] / best["time"] if best and baseline else None,
                 "speedup_cpu": None, "rhs_equivalents": None, "speedup_rhs": None}
        if best and baseline and baseline.get("cpu") and best.get("cpu"):
            entry["speedup_cpu"] = baseline["cpu"] / best["cpu"]
        if best and costs is not None:
            entry["rhs_equivalents"] = rhs_equivalents(best, costs)
            if baseline and entry["rhs_equivalents"] is not None:
                entry["speedup_rhs"] = baseline["nfev"] / entry["rhs_equivalents"]
        out.append(entry)
    return out


def baseline_time(rows: list[dict], h: float, span: float) -> dict | None:
    """The baseline of the speed-up table, RK4 at step ``h`` (s) over a run of ``span`` s: its run if the study
    made it and it completed, else its wall time estimated from the study's RK4 runs (a fixed-step RK4 run costs 4
    RHS calls per step and nothing else, so its wall time is ``4 span / h`` times the median wall time per RHS call
    of those runs; ``estimated`` says which, ``failed`` that the study ran it and it did not complete: unstable at
    that step).  ``None`` without RK4 runs."""
    rk4 = [r for r in rows if r["method"] == "rk4" and "h" in r and np.isfinite(r["time"]) and r["nfev"] > 0]
    exact = [r for r in rk4 if abs(r["h"] - h) <= 1e-9 * h]
    if exact and np.isfinite(exact[0]["error"]):
        return {"time": exact[0]["time"], "nfev": exact[0]["nfev"], "estimated": False, "failed": False,
                **({"cpu": exact[0]["cpu"]} if exact[0].get("cpu") else {})}
    if not rk4:
        return None
    nfev = 4 * int(round(span / h))
    return {"time": nfev * float(np.median([r["time"] / r["nfev"] for r in rk4])), "nfev": nfev, "estimated": True,
            "failed": bool(exact)}


def block_scales(x0, n2: int) -> np.ndarray:
    """Per-component scales of the weighted norm of test 1 (section 9.7: positions, velocities and first-order
    states differ in units): each block's largest ``|x0|`` (1 for a block of zeros)."""
    x0 = np.abs(np.asarray(x0, float))
    scales = np.empty_like(x0)
    for sl in (slice(0, n2), slice(n2, 2 * n2), slice(2 * n2, len(x0))):
        block = x0[sl]
        scales[sl] = block.max() if block.size and block.max() > 0 else 1.0
    return scales


def local_error_table(problem: Problem, methods, hs, reference_rtol: float = 1e-13) -> list[dict]:
    """Test 1 (section 9.4) from ``problem.y0`` at ``problem.t_span[0]``: for every ``(label, method, options)``
    and step ``h`` (s), the local error ``e = max_i |x_1 - x(t0 + h)|_i / s_i`` of one step (``s`` from
    :func:`block_scales`) and the effective order ``p~ = d ln e / d ln h - 1`` (A:(2.8)) between neighbouring
    steps (NaN at the first).  ``x(t0 + h)`` is DOP853 at ``reference_rtol`` with ``atol = reference_rtol s``
    (one run per ``h``, ending exactly there).  Rows: label, method, h, error, p_eff, nominal order."""
    from cvtfem.integrate import solve
    from cvtfem.integrate.methods import METHODS
    from cvtfem.integrate.study import effective_order
    from cvtfem.integrate.system import as_system

    hs = np.asarray(sorted(float(h) for h in hs))
    kw = problem.solve_kwargs()
    t0, x0 = problem.t_span[0], problem.y0
    scales = block_scales(x0, problem.n2)
    exact = []
    for h in hs:
        ref = solve(kw["fun"], (t0, t0 + h), x0, "DOP853", n2=problem.n2, rtol=reference_rtol,
                    atol=reference_rtol * scales)
        if not ref.success:
            raise InputError("--hs", h, f"must allow the reference run (DOP853 at rtol {reference_rtol:g}): "
                             f"{ref.message}")
        exact.append(ref.y[:, -1])
    system = as_system(kw["fun"], x0, n2=problem.n2, jac=kw.get("jac"), jac_sparsity=kw.get("jac_sparsity"),
                       split=kw.get("split"))
    rows = []
    for label, method, opts in methods:
        nominal = METHODS[method](system, None, **opts).order
        errs = []
        for h, x_ref in zip(hs, exact):
            res = solve(**{**kw, "t_span": (t0, t0 + h)}, method=method, h=h, adaptive=False, **opts)
            ok = res.success and np.all(np.isfinite(res.y[:, -1]))
            errs.append(float(np.max(np.abs(res.y[:, -1] - x_ref) / scales)) if ok else np.inf)
        p_eff = [np.nan, *effective_order(hs, np.where(np.isfinite(errs), errs, np.nan))]
        rows += [{"label": label, "method": method, "h": float(h), "error": e, "p_eff": float(q), "nominal": nominal}
                 for h, e, q in zip(hs, errs, p_eff)]
    return rows


def state_at(problem: Problem, t: float, method: str = "Radau", rtol: float = 1e-8) -> np.ndarray:
    """The state of ``problem`` at time ``t`` (s) by ``method`` at ``rtol`` (``atol = 1e-3 rtol``): the start of
    test 1 inside the run (its start state is the quasi-static one, where the pins on the arcs stick)."""
    from cvtfem.integrate import solve

    if t <= problem.t_span[0]:
        return np.asarray(problem.y0, float)
    res = solve(**{**problem.solve_kwargs(), "t_span": (problem.t_span[0], t)}, method=method, rtol=rtol,
                atol=1e-3 * rtol)
    if not res.success:
        raise InputError("--local-at", t, f"must be reached by {method} at rtol {rtol:g}: {res.message}")
    return res.y[:, -1]
