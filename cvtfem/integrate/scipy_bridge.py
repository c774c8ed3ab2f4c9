"""scipy's ``OdeSolver`` methods (RK23, RK45, DOP853, Radau, BDF, LSODA) as engines of the one step loop.

scipy brings its own step acceptance; :class:`ScipyEngine` takes its accepted steps and hands them,
with their dense output, to :class:`~cvtfem.integrate.stepping.Stepping` (growth guard, events,
stall guard, memory export). Counters: ``nfev``, ``njev``, ``nlu`` are scipy's; ``solve`` reports
``nsolve``, ``nnewton``, ``nreject`` and ``nfev_jac`` (not counted by scipy) as -1.

Memory (:meth:`ScipyEngine.state`): the step size for every method (explicit pairs need nothing
else: their first slope is recomputed bitwise); Radau: Jacobian and whether it is current, the last
two step sizes and error norms (predictive controller), the collocation increments ``Z``,
``y_old``, ``t_old`` (dense output = Newton start of the next step), the finite-difference factors
and the factorised iteration matrices; BDF: the difference array ``D``, order, equal-step count,
Jacobian, factors and iteration matrix. LU factors are recomputed from the matrix that was
factorised (``A_real``, ``A_complex``, recorded as scipy factorises them): rebuilding them from the
current step is wrong, because scipy keeps a factorisation across steps whose sizes differ in the
last bits (Radau re-rounds ``h = (t + h) - t``; BDF keeps the LU after an error rejection; issue 11).
Sparse Jacobians (``jac_sparsity`` given) are stored compressed. LSODA keeps its history in
Fortran work arrays scipy does not let us write: it restarts with the saved step size.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.integrate.memory import MatrixSlot, opt_scalar, opt_vector, scalar, vector
from cvtfem.integrate.methods import SCIPY_METHODS
from cvtfem.integrate.stats import Stats
from cvtfem.integrate.stepping import MODEL_FAILURES, Candidate

__all__ = ["ScipyEngine", "scipy_fields", "SCIPY_OPTIONS"]

#: Options scipy's methods take besides rtol/atol/first_step/max_step.
SCIPY_OPTIONS = {"RK23": set(), "RK45": set(), "DOP853": set(), "LSODA": {"jac"},
                 "Radau": {"jac", "jac_sparsity"}, "BDF": {"jac", "jac_sparsity"}}
BDF_ROWS = 5 + 3  # scipy.integrate BDF: MAX_ORDER + 3 rows of D


def _kind(method: str) -> str:
    cls = SCIPY_METHODS[method]
    for base in cls.__mro__:
        if base.__name__ in ("Radau", "BDF"):
            return base.__name__
    return "other"


def scipy_fields(method: str, n: int, jac_sparsity=None) -> tuple[tuple[str, int], ...]:
    """Names and sizes of the memory of scipy ``method`` for ``n`` states."""
    kind = _kind(method)
    J = MatrixSlot.for_pattern("J", n, jac_sparsity).fields()
    A = MatrixSlot.for_pattern("A_real", n, jac_sparsity).fields()
    if kind == "Radau":
        return (("h_abs_old", 1), ("error_norm_old", 1)) + J + (
            ("current_jac", 1), ("lu_valid", 1), ("Z", 3 * n), ("y_old", n), ("t_old", 1), ("jac_factor", n)) + A + \
            MatrixSlot.for_pattern("A_complex", n, jac_sparsity, complex=True).fields()
    if kind == "BDF":
        return (("D", BDF_ROWS * n), ("order", 1), ("n_equal_steps", 1)) + J + (("lu_valid", 1), ("jac_factor", n)) + A
    return ()


class ScipyEngine:
    """A scipy ``OdeSolver`` of class ``SCIPY_METHODS[method]`` behind the engine interface of
    :class:`~cvtfem.integrate.stepping.Stepping`; ``first_step`` (s) or scipy's own guess."""

    adaptive = True

    def __init__(self, method: str, system, t0: float, y0, t_end: float, rtol: float, atol,
                 first_step: float | None = None, options: dict | None = None) -> None:
        self.name, self.system, self.rtol, self.atol = method, system, rtol, atol
        self.t_end, self.stats, self.kind = t_end, Stats(), _kind(method)
        self.options = {k: v for k, v in (options or {}).items() if k not in ("jac", "jac_sparsity")}
        self._base = {"nfev": 0, "njev": 0, "nlu": 0}
        self.solver = self._build(t0, np.asarray(y0, dtype=float), first_step)

    def _build(self, t0: float, y0, first_step):
        kw = dict(self.options, rtol=self.rtol, atol=self.atol)
        if first_step:
            kw["first_step"] = min(first_step, self.t_end - t0)
        if "jac" in SCIPY_OPTIONS.get(self.name, {"jac"}) and self.system.jac is not None:
            kw["jac"] = self.system.jac
        if "jac_sparsity" in SCIPY_OPTIONS.get(self.name, set()) and self.system.jac_sparsity is not None \
                and self.system.jac is None:
            kw["jac_sparsity"] = self.system.jac_sparsity
        solver = SCIPY_METHODS[self.name](self.system.fun, t0, y0, self.t_end, **kw)
        if self.kind in ("Radau", "BDF"):
            _remember_iteration_matrices(solver)
        return solver

    @property
    def h(self) -> float:
        s = self.solver
        return float(getattr(s, "h_abs", None) or s.step_size or 0.0)

    def counts(self) -> dict[str, int]:
        """The counters (``stats.counts``), scipy's ``nfev``, ``njev``, ``nlu`` brought up to date."""
        s, c = self.solver, self.stats.counts
        c["nfev"] = self._base["nfev"] + s.nfev
        c["njev"] = self._base["njev"] + s.njev
        c["nlu"] = self._base["nlu"] + s.nlu
        return c

    def set_counts(self, counts: dict[str, int]) -> None:
        self.stats.counts.update(counts)
        s = self.solver
        for k in self._base:
            self._base[k] = counts[k] - getattr(s, k)

    def advance(self, t: float, x: np.ndarray, tf: float) -> tuple[Candidate | None, str | None]:
        s = self.solver
        f0 = getattr(s, "f", None)
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                message = s.step()
        except MODEL_FAILURES as err:   # the right-hand side met a state it cannot evaluate
            return None, f"the right-hand side failed ({type(err).__name__}: {err})"
        if s.status == "failed":
            return None, str(message)
        if not np.all(np.isfinite(s.y)):
            return None, "non-finite state"
        dense = s.dense_output()
        return Candidate(t, x, s.t - t, s.t, s.y, f0, dense), None

    def commit(self, cand: Candidate) -> None:
        """scipy has moved on already; an event-truncated step restarts it (:meth:`restart`)."""

    def restart(self, t: float, x: np.ndarray) -> None:
        """A fresh solver at ``(t, x)`` (after an event), counters continued, with the current step size."""
        counts, h = dict(self.counts()), self.h
        self.solver = self._build(t, np.array(x), h)
        self.set_counts(counts)

    # --- memory -------------------------------------------------------------------------------

    def memory_fields(self) -> tuple[tuple[str, int], ...]:
        return scipy_fields(self.name, len(self.solver.y), self.system.jac_sparsity)

    def _slots(self, n):
        p = self.system.jac_sparsity
        return (MatrixSlot.for_pattern("J", n, p), MatrixSlot.for_pattern("A_real", n, p),
                MatrixSlot.for_pattern("A_complex", n, p, complex=True))

    def state(self, t: float, x: np.ndarray) -> dict[str, np.ndarray]:
        s, n = self.solver, len(self.solver.y)
        if self.kind == "other":
            return {}
        J, A_real, A_complex = self._slots(n)
        valid = getattr(s, "LU_real" if self.kind == "Radau" else "LU") is not None
        A = s.iteration_matrices if valid else {}
        v = {**J.pack(s.J), "lu_valid": scalar(valid), "jac_factor": vector(s.jac_factor, n),
             **A_real.pack(A.get("real"))}
        if self.kind == "Radau":
            v.update(h_abs_old=scalar(s.h_abs_old), error_norm_old=scalar(s.error_norm_old),
                     current_jac=scalar(s.current_jac), Z=vector(s.Z, 3 * n), y_old=vector(s.y_old, n),
                     t_old=scalar(s.t_old), **A_complex.pack(A.get("complex")))
        else:
            v.update(D=np.asarray(s.D[:BDF_ROWS], dtype=float).ravel(), order=scalar(s.order),
                     n_equal_steps=scalar(s.n_equal_steps))
        return v

    def restore(self, v: dict[str, np.ndarray], t: float, x: np.ndarray) -> None:
        """Into a solver built at the checkpoint's ``(t, x)`` with its step size as first step."""
        s, n = self.solver, len(self.solver.y)
        s.h_abs = float(v["h"][0])
        if self.kind == "other":
            return
        J_slot, A_real, A_complex = self._slots(n)
        fmt = s.J.format if sp.issparse(s.J) else None   # a dense slot holds a sparse matrix densified

        def like(M):
            return M if M is None or fmt is None or sp.issparse(M) else sp.csr_matrix(M).asformat(fmt)

        J = like(J_slot.unpack(v))
        if J is not None:
            s.J = J
        s.jac_factor = opt_vector(v["jac_factor"])
        Ar = like(A_real.unpack(v)) if v["lu_valid"][0] == 1.0 else None
        LU_real = None if Ar is None else s.lu(Ar)
        if self.kind == "Radau":
            s.h_abs_old, s.error_norm_old = opt_scalar(v["h_abs_old"]), opt_scalar(v["error_norm_old"])
            s.current_jac = bool(v["current_jac"][0])
            Z = opt_vector(v["Z"])
            if Z is not None:
                s.Z, s.y_old, s.t_old = Z.reshape(3, n), np.array(v["y_old"]), float(v["t_old"][0])
                s.sol = s._compute_dense_output()
            Ac = None if LU_real is None else like(A_complex.unpack(v))
            s.LU_real, s.LU_complex = LU_real, None if Ac is None else s.lu(Ac)
        else:
            s.D[:BDF_ROWS] = v["D"].reshape(BDF_ROWS, n)
            s.order, s.n_equal_steps = int(v["order"][0]), int(v["n_equal_steps"][0])
            s.LU = LU_real

    def report(self) -> dict:
        return {}

    def warning(self) -> str | None:
        return None


def _remember_iteration_matrices(solver) -> None:
    """Make scipy's Radau/BDF keep a copy of the matrices they factorise last (``iteration_matrices``:
    ``"real"``, and ``"complex"`` for Radau), so that a checkpoint can restore their LU factors exactly."""
    factorise = solver.lu
    solver.iteration_matrices = {}

    def lu(A):
        solver.iteration_matrices["complex" if np.iscomplexobj(A) else "real"] = A.copy()
        return factorise(A)

    solver.lu = lu
