"""Theta-method with a velocity-only Newton system (spec §4.2, eqs. (2.15)-(2.17), (4.2)).

``x1 = x0 + h[(1-alpha) F(t0, x0) + alpha F(t1, x1)]``: alpha = 0 explicit Euler, 1/2
trapezoidal rule, 1 implicit Euler. With ``n2`` second-order pairs the coordinates are
eliminated, ``u1 = u0 + h[(1-alpha) v0 + alpha v1]``, and Newton solves for ``y = [v, z]``
only, with ``dG/dy = I - h alpha J_yy - (h alpha)^2 J_yu P_v`` (reduced matrix).
Predictor (option ``predictor``): ``euler`` (explicit Euler, the source's choice; default at
fixed steps), ``constant`` (the step's start value) or ``linear`` (default in adaptive runs: the
linearised step ``y0 + M^-1 (h F_y0 + gamma h J_yu v0)`` with the current iteration matrix ``M``,
no RHS call; Euler-accurate on smooth components, damped by ``1/(h lambda)`` on stiff ones). On
band-4dof at rtol 1e-3 the Euler predictor, off by ``h lambda ~ 500`` in the stiff components,
made 161 of 358 Newton solves fail; the constant one none, but it needs more iterations at tight
tolerance. Adaptive runs stop Newton by its contraction
rate in the error norm (``newton_stop="auto"``, :mod:`cvtfem.integrate.newton`), with tolerance
``kappa = max(10 eps / rtol, 1e-3)`` (option ``newton_kappa``): tighter than Radau's 0.03 because
the trapezoidal rule does not damp stiff components (R(-inf) = -1), so a Newton error left there
rings on (band-6+2n 1 s, rtol 1e-3, Euler predictor: kappa 0.03 gave 2483 steps, 1e-3 389); fixed-step runs and
``newton_stop="source"`` use the source's line search and stopping rule (2.21)-(2.23).

Error estimate (ours): the trapezoidal rule's local error ``h^3 x'''/12`` with ``x'''`` from the third
divided difference of the states at the last four points ``t_{n-2} ... t_{n+1}`` (the step before: from the
divided difference of ``F`` over two steps; the first step: first order). Not from ``F``: the rule is not
L-stable, so a stiff component's deviation from its slow manifold alternates in sign undamped, and ``F`` of
the components coupled to it carries that alternation (Robertson: ``1e4 y2`` in ``y1'``), which the rule
itself cancels in ``(F_n + F_{n+1})/2`` but an estimate from ``F`` does not (h/t fell to 1e-3 on Robertson).
Other alpha use ``|alpha - 1/2| h (F1 - F0)``; all are filtered by the LU of ``I - h alpha J`` (Shampine).

Tolerance proportionality (adaptive trapezoidal rule, option ``proportional``, default on): with the
local error held at the tolerance an order-2 method's global error falls only like ``tol^(2/3)``
(HIRES: 73 ... 3678 x rtol over rtol 1e-3 ... 1e-8). As RADAU5 does for its order, the step is
controlled against internal tolerances ``rtol_int = 0.5 rtol^(3/2)``,
``atol_int = atol rtol_int / rtol`` (Hairer-Wanner II, IV.8), so ``h ~ rtol^(1/2)`` and the global
error ``~ h^2 ~ rtol`` (:func:`~cvtfem.integrate.base.proportional_ratio`, constant measured in
docs/integrators.md). Newton's tolerance follows the internal tolerances.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper, proportional_ratio
from cvtfem.integrate.jacobian import JacobianProvider
from cvtfem.integrate.linsolve import DENSE_MAX, LU, reduced_matrix
from cvtfem.integrate.memory import MatrixSlot, opt_scalar, scalar, vector
from cvtfem.integrate.newton import NewtonOptions, NewtonSolver

__all__ = ["Theta", "Trapezoidal", "ImplicitEuler"]

NEWTON_KAPPA = 0.01   # stop="source", adaptive: Newton residual below 1 % of the error tolerance
PREDICTORS = ("auto", "euler", "constant", "linear")   # auto: euler at fixed steps, linear adaptive
RATE_KAPPA = 1e-3     # stop="rate": Newton tolerance in the error norm (see module docstring)


class Theta(Stepper):
    """The theta family; ``alpha`` in [0, 1] (option), Newton variant via ``newton``."""

    name = "theta"
    OPTIONS = frozenset({"alpha", "newton", "newton_tol", "newton_max_iter", "trim_threshold",
                         "newton_stop", "newton_kappa", "predictor", "proportional"})
    STEP_QUANTUM = 1.3   # keep h (and the LU) unless the controller wants >= 1.3x
    default_alpha = 0.5

    def __init__(self, system, stats=None, alpha: float | None = None, newton: str = "const",
                 newton_tol: tuple[float, float] = (1e-10, 1e-8), newton_max_iter: int = 12,
                 trim_threshold: float = 1e-3, newton_stop: str = "auto",
                 newton_kappa: float | None = None, predictor: str = "auto",
                 proportional: bool = True) -> None:
        super().__init__(system, stats)
        alpha = self.default_alpha if alpha is None else float(alpha)
        if not 0.0 <= alpha <= 1.0:
            raise InputError("alpha", alpha, "must lie in [0, 1]")
        self.alpha = alpha
        self.kappa = newton_kappa
        if predictor not in PREDICTORS:
            raise InputError("predictor", predictor, f"must be one of {PREDICTORS}")
        self.predictor = predictor
        if not isinstance(proportional, (bool, np.bool_)):
            raise InputError("proportional", proportional, "must be true or false")
        self.proportional = bool(proportional)
        self.order = 2 if alpha == 0.5 else 1
        self.error_order = self.order
        self.newton = NewtonSolver(self.stats, NewtonOptions(newton, *newton_tol, newton_max_iter,
                                                              trim_threshold, newton_stop))
        self.jac = JacobianProvider(self)
        self.J = None
        self._gamma = None
        self._prev = None   # (h_prev, F at previous step start)
        self._hist: list[tuple[float, np.ndarray]] = []   # (t, x) at the two previous step starts

    def reset(self) -> None:
        self._prev = None
        self._hist = []

    def _slot(self) -> MatrixSlot:
        return MatrixSlot.for_pattern("J", self.system.n, self.system.jac_sparsity)

    def memory_fields(self):
        """``h alpha`` of the iteration matrix and whether its LU is current, previous step and slope
        (error estimate), the Jacobian, ``F`` at the current point, and the Newton solver's memory
        (Jacobian marked stale, contraction estimate of the last solve)."""
        n = self.system.n
        return (("gamma", 1), ("lu_valid", 1), ("prev_h", 1), ("prev_f", n), ("hist_t", 2), ("hist_x", 2 * n)) + \
            self._slot().fields() + \
            super().memory_fields() + (("newton_stale", 1), ("newton_eta", 1))

    def state(self, t, x):
        n, prev = self.system.n, self._prev
        return {"gamma": scalar(self._gamma), "lu_valid": scalar(self.newton.B is not None),
                "prev_h": scalar(None if prev is None else prev[0]),
                "prev_f": vector(None if prev is None else prev[1], n),
                "hist_t": np.array([h[0] for h in self._hist] + [np.nan] * (2 - len(self._hist))),
                "hist_x": np.concatenate([h[1] for h in self._hist] + [np.full(n, np.nan)] * (2 - len(self._hist))),
                **self._slot().pack(self.J),
                **super().state(t, x), "newton_stale": scalar(self.newton.stale),
                "newton_eta": scalar(self.newton._eta)}

    def restore(self, state, t, x):
        """The LU is recomputed from the saved Jacobian and ``h alpha`` (LAPACK/SuperLU give the same
        factors for the same matrix)."""
        J = self._slot().unpack(state)
        if J is not None:   # in the form JacobianProvider returns
            self.J = sp.csr_matrix(J) if self.system.n > DENSE_MAX else (J.toarray() if sp.issparse(J) else J)
        self._gamma = opt_scalar(state["gamma"])
        prev_h = opt_scalar(state["prev_h"])
        self._prev = None if prev_h is None else (prev_h, np.array(state["prev_f"]))
        n = self.system.n
        self._hist = [(float(tk), np.array(state["hist_x"][k * n:(k + 1) * n]))
                      for k, tk in enumerate(state.get("hist_t", ())) if np.isfinite(tk)]   # absent: older checkpoints
        super().restore(state, t, x)
        self.newton.invalidate()
        if state["lu_valid"][0] == 1.0 and self.J is not None and self._gamma is not None:
            self.newton._set(reduced_matrix(self.J, self.system.n2, self._gamma))
        self.newton.stale, self.newton._eta = bool(state["newton_stale"][0]), float(state["newton_eta"][0])

    def accept(self, att: Attempt) -> None:
        super().accept(att)
        self._prev = (att.h, att.f0)
        self._hist = (self._hist + [(att.t0, att.x0)])[-2:]

    def tolerance_ratio(self, rtol: float) -> float:
        """``rtol_int / rtol``: the trapezoidal rule keeps its global error proportional to rtol
        (module docstring) unless ``proportional=False``; other alpha (order 1) keep rtol."""
        return proportional_ratio(rtol, 2) if self.proportional and self.alpha == 0.5 else 1.0

    def _state(self, y, t, x0, f0, h):
        """Full state from the reduced unknowns ``y = [v, z]`` (2.16)."""
        n2, a = self.system.n2, self.alpha
        if not n2:
            return y
        u = x0[:n2] + h * ((1 - a) * f0[:n2] + a * y[:n2])
        return np.concatenate([u, y])

    def attempt(self, t, x, h):
        n2, a = self.system.n2, self.alpha
        f0 = self.f0(t, x)
        t1 = t + h
        pred = self.predictor
        if pred == "auto":
            pred = "euler" if self.tolerances is None else "linear"
        x_pred = x + h * f0 if (a == 0.0 or pred == "euler") else x
        if a == 0.0:
            x1 = x_pred
            f1 = self.f(t1, x1)
        else:
            gamma = h * a
            if gamma != self._gamma:
                self.newton.invalidate()
                self._gamma = gamma
            y0, fy0 = x[n2:], f0[n2:]
            rhs0 = y0 + h * (1 - a) * fy0

            def residual(y):
                return y - rhs0 - gamma * self.f(t1, self._state(y, t, x, f0, h))[n2:]

            def make_matrix(y, fresh):
                if fresh or self.J is None:
                    self.J = self.jac(t1, self._state(y, t, x, f0, h))
                return reduced_matrix(self.J, n2, gamma)

            if pred == "linear":   # one chord step from x0 without an RHS call (see docstring)
                self.newton.prepare(y0, make_matrix)
                r = h * fy0
                if n2:
                    r = r + gamma * h * (self.J[n2:, :n2] @ x[n2:2 * n2])
                x_pred = np.concatenate([x[:n2], y0 + self.newton.solve_linear(r)])
            eps = scale = None
            kappa = RATE_KAPPA
            if self.need_error and self.tolerances is not None:
                rtol, atol = self.tolerances
                scale = (np.asarray(atol, dtype=float) * np.ones(len(x)))[n2:] + rtol * np.abs(y0)
                eps = np.minimum(self.newton.opt.eps_abs, NEWTON_KAPPA * scale)
                kappa = self.kappa or max(10 * np.finfo(float).eps / rtol, RATE_KAPPA)
            y1, _ = self.newton.solve(residual, x_pred[n2:], make_matrix, eps, scale, kappa)
            x1 = self._state(y1, t, x, f0, h)
            f1 = self.f(t1, x1)
        err = self._error(t, x, h, x1, f0, f1) if self.need_error else None
        return Attempt(t, x, h, x1, err, f0, f1)

    def _error(self, t, x, h, x1, f0, f1):
        if self.alpha == 0.5 and len(self._hist) == 2:   # from the states: see the module docstring
            ts = [self._hist[0][0], self._hist[1][0], t, t + h]
            dd = [self._hist[0][1], self._hist[1][1], x, x1]
            for k in range(1, 4):
                dd = [(dd[i + 1] - dd[i]) / (ts[i + k] - ts[i]) for i in range(len(dd) - 1)]
            est = (h ** 3 / 2) * dd[0]   # h^3 x'''/12, x''' = 6 x[t_{n-2}, ..., t_{n+1}]
        elif self.alpha == 0.5 and self._prev is not None:
            hp, fp = self._prev
            dd = ((f1 - f0) / h - (f0 - fp) / hp) / (h + hp)   # divided difference = x'''/2
            est = (h ** 3 / 6) * dd
        else:
            est = max(abs(self.alpha - 0.5), 0.5 * (self.alpha == 0.5)) * h * (f1 - f0)
        lu = self.newton._lu
        if self.alpha == 0.0 or self.J is None or not isinstance(lu, LU):
            return est
        n2, g = self.system.n2, self._gamma
        if not n2:
            return lu.solve_y(est)
        k_y = lu.solve_y(est[n2:] + g * (self.J[n2:, :n2] @ est[:n2]))
        return np.concatenate([est[:n2] + g * k_y[:n2], k_y])


class Trapezoidal(Theta):
    """Trapezoidal rule (2.15): theta-method with alpha = 1/2, order 2."""

    name = "trapezoidal"


class ImplicitEuler(Theta):
    """Implicit Euler: theta-method with alpha = 1, order 1."""

    name = "implicit-euler"
    default_alpha = 1.0
