"""What accuracy costs on a running chain transmission: the source's chapter-2 protocol (issue 16).

Spec ``numerics-and-periodic.md`` section 9.  On a chain-CVT scene started in its quasi-static state:

* the spectrum of the Jacobian at a state of the run, and the same spectrum with the friction saturation
  speed ``v0`` divided by 10 (section 9.2: which eigenvalues friction makes);
* test 2 (section 9.5): the global error ``E = max |P - P*| / max |P*|`` over a window ``[t1, t2]`` of the
  axial force ``P`` of the pin that enters a sheave in the window (A:(2.9)), for each method and step or
  tolerance, with its cost (wall time, RHS calls, Jacobians, LU factorisations);
* the reference ``P*`` computed two independent ways whose mutual ``E`` is reported (it must be far below the
  acceptance 0.05 for the study to mean anything).

Test 1 (local error and effective order) reuses :func:`cvtfem.integrate.study.local_errors` on
:meth:`PinForceProblem` from a state of the run.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cvtfem.errors import InputError
from cvtfem.problems.base import Problem

__all__ = ["PinForceProblem", "pin_force_problem", "window_error", "jacobian_spectrum", "spectrum_with_v0",
           "ACCEPT_E"]

#: The source's acceptance of test 2.
ACCEPT_E = 0.05
#: Output of the chain families whose global error test 2 measures.
PIN_FORCE = "chain.pin_axial_force"


def window_error(p, p_ref) -> float:
    """``E = max |p - p_ref| / max |p_ref|`` over the samples given (A:(2.9)); ``inf`` for non-finite ``p``."""
    p, p_ref = np.asarray(p, float), np.asarray(p_ref, float)
    if p.shape != p_ref.shape or not np.all(np.isfinite(p)):
        return float("inf")
    return float(np.max(np.abs(p - p_ref)) / np.max(np.abs(p_ref)))


@dataclass(frozen=True)
class PinForceProblem(Problem):
    """A chain transmission from its start state over ``[0, t2]``; the error of a run is :func:`window_error`
    of the axial force of pin ``pin`` at the samples ``t_eval`` of the window ``[t1, t2]``."""

    loop: object = None
    pin: int = 0
    t_eval: np.ndarray = field(default_factory=lambda: np.zeros(0))
    p_ref: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def pin_forces(self, y) -> np.ndarray:
        """Axial force of every pin (N), (samples, n_pins), at the states ``y`` (n, samples): the chain family's
        output alone (the contacts and loops of the full output set are not needed for it)."""
        fam = self.loop.family
        out = []
        for yi in np.asarray(y).T:
            q, v = self.loop.split(yi)[:2]
            out.append(fam.outputs(q[:fam.size], v[:fam.size])[PIN_FORCE])
        return np.array(out)

    def error(self, res) -> float:
        if not res.success or len(res.t) != len(self.t_eval):
            return float("inf")
        return window_error(self.pin_forces(res.y)[:, self.pin], self.p_ref)


def pin_force_problem(scene, window: tuple[float, float] = (1e-3, 5e-3), sample: float = 1e-5,
                      reference: tuple[str, float] = ("Radau", 1e-8),
                      check: tuple[str, float] = ("rodas5p", 1e-8)) -> tuple[PinForceProblem, dict]:
    """Test 2 of the protocol on a chain-CVT scene: the problem, and a report of its reference.

    The pin is the one whose axial force varies most over the window in the reference run (a pin entering or
    leaving an arc: the sharply varying output of A:(2.9)).  ``reference`` and ``check`` are two methods with
    their rtol (``atol = 1e-3 rtol``, analytic sparse Jacobian); the report holds the ``E`` between them.
    """
    from cvtfem.integrate import solve
    from cvtfem.machines.cvt import closed_loop

    t1, t2 = (float(v) for v in window)
    if not (0 <= t1 < t2 and np.isfinite(t2)):
        raise InputError("--window", window, "must be two simulated times 0 <= t1 < t2, s")
    if not (0 < sample <= (t2 - t1) / 4):
        raise InputError("--sample", sample, f"must be positive and give at least 4 samples in {t2 - t1:g} s")
    if not scene.cvt.model.startswith("chain"):
        raise InputError("cvt.model", scene.cvt.model, "must be a discrete chain (the protocol measures a pin's "
                         "axial force)")
    loop = closed_loop(scene)
    x0, start = loop.start()
    t_eval = np.arange(t1, t2 + 0.5 * sample, sample)
    t_eval = t_eval[t_eval <= t2]
    base = PinForceProblem("chain", loop.rhs, x0, (0.0, t2), n2=loop.n2, jac=loop.jac,
                           jac_sparsity=loop.jac_sparsity, loop=loop, t_eval=t_eval)
    forces = {}
    for method, rtol in (reference, check):
        res = solve(**base.solve_kwargs(), method=method, rtol=rtol, atol=1e-3 * rtol, t_eval=t_eval)
        if not res.success:
            raise InputError("reference", method, f"must complete the reference run: {res.message}")
        forces[method] = base.pin_forces(res.y)
    p_all = forces[reference[0]]
    pin = int(np.argmax(np.ptp(p_all, axis=0)))
    problem = PinForceProblem("chain", loop.rhs, x0, (0.0, t2), n2=loop.n2, jac=loop.jac,
                              jac_sparsity=loop.jac_sparsity, loop=loop, pin=pin, t_eval=t_eval,
                              p_ref=p_all[:, pin], info={"n": len(x0), "n2": loop.n2})
    report = {"start": start["kind"], "pin": pin, "samples": len(t_eval), "window": (t1, t2),
              "reference": f"{reference[0]} rtol {reference[1]:g}", "check": f"{check[0]} rtol {check[1]:g}",
              "reference_E": window_error(forces[check[0]][:, pin], p_all[:, pin]),
              "force_range_N": (float(p_all[:, pin].min()), float(p_all[:, pin].max()))}
    return problem, report


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


def measure(problem: PinForceProblem, fixed, steps, adaptive, rtols, repeats: int = 3) -> list[dict]:
    """Test 2 for every fixed-step method at every step ``h`` (s) and every adaptive method at every rtol
    (``atol = 1e-3 rtol``): rows of :func:`~cvtfem.integrate.study.work_precision` (error = ``E``, wall time =
    median of ``repeats``, RHS calls, Jacobians, LU factorisations) with a ``setting`` label."""
    from cvtfem.integrate.study import work_precision

    runs = [(label, method, {**opts, "h": h, "adaptive": False, "t_eval": problem.t_eval})
            for label, method, opts in fixed for h in steps]
    runs += [(label, method, {**opts, "rtol": r, "atol": 1e-3 * r, "t_eval": problem.t_eval})
             for label, method, opts in adaptive for r in rtols]
    rows = work_precision(problem, runs, repeats=repeats, error=problem.error)
    for row in rows:
        row["setting"] = f"h={row['h']:g}" if "h" in row else f"rtol={row['rtol']:g}"
    return rows


def speedups(rows: list[dict], baseline: dict | None, accept: float = ACCEPT_E) -> list[dict]:
    """Per method, its cheapest run with ``E <= accept`` and its speed-up (wall time) over ``baseline`` (the
    source's Table 2.4: RK4 at h = 5e-8 s); a method with no accepted run gets ``None``."""
    out = []
    for label in dict.fromkeys(r["label"] for r in rows):
        ok = [r for r in rows if r["label"] == label and r["error"] <= accept]
        best = min(ok, key=lambda r: r["time"]) if ok else None
        out.append({"label": label, "setting": best["setting"] if best else None,
                    "error": best["error"] if best else None, "time": best["time"] if best else None,
                    "nfev": best["nfev"] if best else None,
                    "speedup": baseline["time"] / best["time"] if best and baseline else None})
    return out
