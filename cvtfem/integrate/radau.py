"""Radau IIA of order 5 (3 stages) with the Jacobian and LU reuse of Hairer's RADAU5.

The collocation method at ``c = (4 - sqrt6)/10, (4 + sqrt6)/10, 1`` (Hairer-Wanner II §IV.8) in the
stage increments ``Z_i = X_i - x0``; simplified Newton on the transformed unknowns ``W = T^-1 Z``, which
splits the ``3n`` system into one real system ``(mu_r/h) I - J`` and one complex system
``(mu_c/h) I - J`` (two LUs per step size and Jacobian; with second-order structure ``x = [u, v, z]`` and more than
``DENSE_MAX`` states both are reduced to the ``[v, z]`` block as in the other implicit methods,
:mod:`cvtfem.integrate.linsolve`; below, the full dense LU costs less than the reduction's bookkeeping). Strategies, as RADAU5:

* Newton stops on the contraction rate in the error norm (tolerance ``max(10 eps/rtol, min(0.03,
  sqrt(rtol)))``) and gives up when the predicted error after the remaining iterations stays too large;
  it starts from the previous step's collocation polynomial.
* The Jacobian is kept across steps and recomputed only after a solve that needed more than 2
  iterations with a rate above 1e-3, after a rejected step, or after a failed solve with an old Jacobian
  (then the same ``h`` is retried); LUs are kept while ``J`` and ``h`` are unchanged (the controller keeps ``h`` unless it
  wants to grow it by 1.2 or more).
* Error estimate of order 3, filtered by the real LU (``err = ((mu_r/h) I - J)^-1 (F0 + sum e_i Z_i/h)``),
  and refined once through ``F`` when it exceeds the tolerance on the first attempt or after a rejection
  (Shampine's device for very stiff problems).
* Dense output: the collocation polynomial (order 3 inside the step, exact at its end).
* Tolerance map of RADAU5: the order-3 estimate is controlled against ``rtol_int = 0.1 rtol^(2/3)``,
  ``atol_int = atol rtol_int / rtol``, so the order-5 solution's error tracks rtol (without it the error
  is 1e-3 x rtol at rtol 1e-8 on the limit cycle); ``proportional=False`` controls against rtol itself.

The constants are published figures (the transformation ``T`` and its inverse, the eigenvalues ``mu`` of
the inverse Radau IIA(5) matrix, the estimate's weights ``e``).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper, StepFailure
from cvtfem.integrate.jacobian import JacobianProvider
from cvtfem.integrate.linsolve import DENSE_MAX, LU, reduced_matrix
from cvtfem.integrate.memory import MatrixSlot, opt_scalar, scalar, vector

__all__ = ["Radau5"]

S6 = 6.0 ** 0.5
C = np.array([(4 - S6) / 10, (4 + S6) / 10, 1.0])
E = np.array([-13 - 7 * S6, -13 + 7 * S6, -1.0]) / 3
MU_REAL = 3 + 3 ** (2 / 3) - 3 ** (1 / 3)
MU_COMPLEX = 3 + 0.5 * (3 ** (1 / 3) - 3 ** (2 / 3)) - 0.5j * (3 ** (5 / 6) + 3 ** (7 / 6))
T = np.array([[0.09443876248897524, -0.14125529502095421, 0.03002919410514742],
              [0.25021312296533332, 0.20412935229379994, -0.38294211275726192],
              [1.0, 1.0, 0.0]])
TI = np.array([[4.17871859155190428, 0.32768282076106237, 0.52337644549944951],
               [-4.17871859155190428, -0.32768282076106237, 0.47662355450055044],
               [0.50287263494578682, -2.57192694985560522, 0.59603920482822492]])
TI_REAL, TI_COMPLEX = TI[0], TI[1] + 1j * TI[2]
#: collocation polynomial: ``x(t0 + s h) = x0 + Z^T P [s, s^2, s^3]``
P = np.array([[13 / 3 + 7 * S6 / 3, -23 / 3 - 22 * S6 / 3, 10 / 3 + 5 * S6],
              [13 / 3 - 7 * S6 / 3, -23 / 3 + 22 * S6 / 3, 10 / 3 - 5 * S6],
              [1 / 3, -8 / 3, 10 / 3]])
NEWTON_MAXITER = 6
#: Newton's (rtol, atol) and iteration limit in fixed-step runs (no retry with a smaller step there)
FIXED_STEP_TOL, FIXED_STEP_MAXITER = (1e-12, 1e-12), 30
#: a converged solve slower than this (rate) with more than 2 iterations asks for a new Jacobian
JAC_RATE = 1e-3


# The small stage transforms (3 x 3 against 3 x n) and the norms go through np.einsum, not BLAS: OpenBLAS
# kernels (Sandybridge) round such products differently with the operands' memory alignment, so a run restored from
# its memory drifted from the original in the last bits (test_radau5.py::test_memory_restores_bit_for_bit).


def rms(a: np.ndarray) -> float:
    """Root mean square of the entries of ``a``."""
    a = a.ravel()
    return math.sqrt(float(np.einsum("i,i->", a, a)) / a.size)


def solve(lu: LU, r: np.ndarray) -> np.ndarray:
    """``k`` with ``((mu/h) I - J) k = r``, from the LU of ``I - gamma J``, ``gamma = h/mu``."""
    return lu.solve_full(lu.gamma * r)


class Radau5(Stepper):
    """Radau IIA(5): 3-stage implicit Runge-Kutta method of order 5, L-stable, stiffly accurate."""

    name, order, error_order, stages = "radau5", 5, 3, 3
    controller = "predictive"   # Gustafsson's, as RADAU5
    STEP_QUANTUM = 1.2          # keep h (and the LUs) unless the controller wants 1.2x or more

    OPTIONS = frozenset({"proportional"})

    def __init__(self, system, stats=None, proportional: bool = True) -> None:
        super().__init__(system, stats)
        if not isinstance(proportional, (bool, np.bool_)):
            raise InputError("proportional", proportional, "must be true or false")
        self.proportional = bool(proportional)
        self.jac = JacobianProvider(self)
        self.J = None
        self._current = False     # J was evaluated at the current step's start
        self._stale = True        # recompute J at the next attempt
        self._lu: tuple[float, LU, LU] | None = None
        self._poly = None         # (t0, h, x0, Q) of the last accepted step: Newton's starting guess
        self._retry = True        # first attempt, or after a rejection: refine the estimate, refresh an old J
        self._pending = False     # the last attempt's Newton solve was slow: new J after accepting it

    def tolerance_ratio(self, rtol: float) -> float:
        """``rtol_int / rtol = 0.1 rtol^(-1/3)`` (RADAU5's map, module docstring) or 1."""
        return 0.1 * rtol ** (-1.0 / 3.0) if self.proportional else 1.0

    # --- linear algebra ---------------------------------------------------------------------------

    def _new_jacobian(self, t: float, x: np.ndarray) -> None:
        self.J = self.jac(t, x)
        self._current, self._stale, self._lu = True, False, None

    def _factors(self, h: float) -> tuple[LU, LU]:
        """LUs of ``I - gamma J`` for ``gamma = h/mu_r`` and ``h/mu_c`` (:func:`solve` turns them into solves with
        ``(mu/h) I - J``), with the second-order structure eliminated (``n2``); kept while ``J`` and ``h`` are."""
        if self._lu is not None and self._lu[0] == h:
            return self._lu[1], self._lu[2]
        J, n2 = self.J, (self.system.n2 if self.system.n > DENSE_MAX else 0)   # small: the full LU is cheaper
        lus = tuple(LU(self.stats, reduced_matrix(J, n2, g), n2, g, J[n2:, :n2])
                    for g in (h / MU_REAL, h / MU_COMPLEX))
        self._lu = (h, *lus)
        return lus

    # --- one step ---------------------------------------------------------------------------------

    def _guess(self, t: float, h: float, x: np.ndarray) -> np.ndarray:
        """Stage increments ``Z`` (3, n) from the previous step's collocation polynomial (zero without)."""
        if self._poly is None or self._poly[0] + self._poly[1] != t:
            return np.zeros((3, len(x)))
        t0, h0, x0, Q = self._poly
        s = (t + h * C - t0) / h0
        return np.einsum("ij,jk->ki", Q, np.vstack([s, s * s, s ** 3])) + (x0 - x)

    def _newton(self, t, x, h, Z, scale, tol, lr, lc):
        """Simplified Newton on ``W = T^-1 Z``: ``(Z, iterations, last contraction rate or None)``, or None when it
        diverges or would not converge within the iteration limit."""
        W = np.einsum("ij,jk->ik", TI, Z)
        mr, mc = MU_REAL / h, MU_COMPLEX / h
        norm_old, rate = None, None
        maxiter = NEWTON_MAXITER if self.tolerances else FIXED_STEP_MAXITER
        for k in range(maxiter):
            F = np.array([self.f(t + ci * h, x + zi) for ci, zi in zip(C, Z)])
            if not np.all(np.isfinite(F)):
                return None
            dr = solve(lr, np.einsum("ji,j->i", F, TI_REAL) - mr * W[0])
            dc = solve(lc, np.einsum("ji,j->i", F, TI_COMPLEX) - mc * (W[1] + 1j * W[2]))
            dW = np.array([dr, dc.real, dc.imag])
            norm = rms(dW / scale)
            if norm_old is not None:
                rate = norm / norm_old
                if rate >= 1 or rate ** (maxiter - k) / (1 - rate) * norm > tol:
                    return None
            W += dW
            Z = np.einsum("ij,jk->ik", T, W)
            self.stats.counts["nnewton"] += 1
            if norm == 0 or (rate is not None and rate / (1 - rate) * norm < tol):
                return Z, k + 1, rate
            norm_old = norm
        return None

    def attempt(self, t, x, h):
        rtol, atol = self.tolerances or FIXED_STEP_TOL   # fixed steps: Newton to round-off
        if self.J is None or self._stale or (self._retry and not self._current):   # as RADAU5 after a rejection
            self._new_jacobian(t, x)
        f0 = self.f0(t, x)
        scale = atol + rtol * np.abs(x)
        tol = max(10 * np.finfo(float).eps / rtol, min(0.03, rtol ** 0.5))
        Z0 = self._guess(t, h, x)
        while True:
            lr, lc = self._factors(h)
            solved = self._newton(t, x, h, Z0, scale, tol, lr, lc)
            if solved is not None:
                break
            self.stats.counts["nnewton_fail"] += 1
            if self._current:
                raise StepFailure(f"Newton iteration of the Radau stages did not converge (h = {h:.3g} s)")
            self._new_jacobian(t, x)
            self.stats.counts["njac_refresh"] += 1
        Z, iters, rate = solved
        x1 = x + Z[2]
        err = None
        if self.need_error:
            ZE = np.einsum("i,ik->k", E, Z) / h
            err = solve(lr, f0 + ZE)
            if self._retry:
                sc = atol + rtol * np.maximum(np.abs(x), np.abs(x1))
                if rms(err / sc) > 1:
                    err = solve(lr, self.f(t, x + err) + ZE)
        self._retry = True   # the next attempt without accept() follows a rejection
        self._pending = iters > 2 and rate is not None and rate > JAC_RATE
        Q = np.einsum("ji,jk->ik", Z, P)

        def interp(tq):
            s = (np.asarray(tq, dtype=float) - t) / h
            if np.ndim(s) == 0:
                return x + np.einsum("ij,j->i", Q, np.array([s, s * s, s ** 3]))
            return x[:, None] + np.einsum("ij,jk->ik", Q, np.vstack([s, s * s, s ** 3]))

        interp.Q = Q
        return Attempt(t, x, h, x1, err, f0, interp=interp)

    def accept(self, att: Attempt) -> None:
        super().accept(att)
        self._poly = (att.t0, att.h, att.x0, att.interp.Q)
        self._stale, self._current, self._retry = self._pending, False, False

    def reset(self) -> None:
        self._poly, self._retry, self._stale = None, True, True

    # --- memory -----------------------------------------------------------------------------------

    def _slot(self) -> MatrixSlot:
        return MatrixSlot.for_pattern("J", self.system.n, self.system.jac_sparsity)

    def memory_fields(self):
        """The Jacobian, the step size of its LUs, the flags (J stale / evaluated at this point / refine the next
        estimate), the last step's collocation polynomial (``t0, h``, ``x0``, ``Q``) and ``F`` here."""
        n = self.system.n
        return self._slot().fields() + (("lu_h", 1), ("flags", 3), ("poly_th", 2), ("poly_x0", n),
                                         ("poly_q", 3 * n)) + super().memory_fields()

    def state(self, t, x):
        n, poly = self.system.n, self._poly
        return {**self._slot().pack(self.J), "lu_h": scalar(None if self._lu is None else self._lu[0]),
                "flags": np.array([self._stale, self._current, self._retry], dtype=float),
                "poly_th": np.array(poly[:2] if poly else [np.nan, np.nan]),
                "poly_x0": vector(poly[2] if poly else None, n),
                "poly_q": vector(poly[3].ravel() if poly else None, 3 * n), **super().state(t, x)}

    def restore(self, state, t, x):
        """The LUs are recomputed from the saved Jacobian and ``h`` (the same factors for the same matrix)."""
        J = self._slot().unpack(state)
        if J is not None:   # in the form JacobianProvider returns
            self.J = sp.csr_matrix(J) if self.system.n > DENSE_MAX else (J.toarray() if sp.issparse(J) else J)
        self._stale, self._current, self._retry = (bool(v) for v in state["flags"])
        self._lu = None
        lu_h = opt_scalar(state["lu_h"])
        if lu_h is not None and self.J is not None:
            self._factors(lu_h)
        th = state["poly_th"]
        self._poly = None if np.isnan(th[0]) else (float(th[0]), float(th[1]), np.array(state["poly_x0"]),
                                                   np.array(state["poly_q"]).reshape(len(x), 3))
        super().restore(state, t, x)
