"""Rosenbrock-W method ROS34PW2 of Rang & Angermann (2005): order 3 for any matrix ``A``, reusable over steps.

A W-method keeps its order whatever ``A`` approximates ``dF/dx`` (Hairer-Wanner II §IV.7, "W-methods"), so ``A``
may be the Jacobian of an earlier step: ``jac_every`` steps share one ``A`` and, at a fixed step, one LU of the
reduced ``I - h gamma A`` (:mod:`cvtfem.integrate.linsolve`). ROS34PW2 has 4 stages (4 RHS calls and 4 solves per
step), order 3 with an embedded order-2 solution, ``gamma = 0.4358665215...``, is L-stable with ``A = J``, stiffly
accurate, and satisfies the Prothero-Robinson conditions (the "P"); the coefficients are the published ones
(Rang, J. & Angermann, L., BIT 45 (2005) 761-787, Table "ROS34PW2").

In the transformed variables of Hairer-Wanner II (7.25)-(7.27) (``u_i`` the stage increments, ``a = alpha
Gamma^-1``, ``C = diag(1/gamma) - Gamma^-1``, ``m = b Gamma^-1``):

``(I - h gamma A) u_i = h gamma [F(t0 + alpha_i h, x0 + sum_j a_ij u_j) + sum_j (C_ij / h) u_j]``,
``x1 = x0 + sum_i m_i u_i``, error ``sum_i (m_i - mhat_i) u_i``.

No ``dF/dt`` term: it is the ``t`` column of the Jacobian of the autonomous system ``(x, t)``, which the W-method
may approximate by zero (its order conditions hold for any ``A``), so the order stays 3 on non-autonomous problems.
Dense output for ``t_eval`` is the cubic Hermite interpolant (the next step's ``F(t1, x1)``, reused).
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt
from cvtfem.integrate.wmethods import _WBase

__all__ = ["ROS34PW2", "transformed"]

#: Published coefficients (alpha_ij, gamma_ij with gamma_ii = GAMMA, b, bhat) of ROS34PW2.
GAMMA = 0.435866521508459
ALPHA = np.array([[0.0, 0.0, 0.0, 0.0],
                  [0.87173304301691801, 0.0, 0.0, 0.0],
                  [0.84457060015369423, -0.11299064236484185, 0.0, 0.0],
                  [0.0, 0.0, 1.0, 0.0]])
GAMMAS = np.array([[GAMMA, 0.0, 0.0, 0.0],
                   [-0.87173304301691801, GAMMA, 0.0, 0.0],
                   [-0.90338057013044082, 0.054180672388095326, GAMMA, 0.0],
                   [0.24212380706095346, -1.2232505839045147, 0.54526025533510214, GAMMA]])
B = np.array([0.24212380706095346, -1.2232505839045147, 1.5452602553351020, GAMMA])
BHAT = np.array([0.37810903145819369, -0.096042292212423178, 0.5, 0.21793326075422950])


def transformed(alpha, gammas, b, bhat):
    """``(a, C, m, mhat, c)`` of the transformed form (module docstring) from published ``alpha``, ``Gamma``
    (lower triangular with equal diagonal), ``b``, ``bhat``; ``c = alpha 1``, the stage times' fractions."""
    gi = np.linalg.inv(gammas)
    return (np.asarray(alpha) @ gi, np.diag(1.0 / np.diag(gammas)) - gi, np.asarray(b) @ gi,
            np.asarray(bhat) @ gi, np.asarray(alpha).sum(axis=1))


class ROS34PW2(_WBase):
    """ROS34PW2: 4-stage Rosenbrock-W method of order 3(2); ``A`` reused over ``jac_every`` steps."""

    name, order, error_order, stages = "ros34pw2", 3, 2, 4
    OPTIONS = frozenset({"jac_every"})
    default_d = GAMMA
    tableau = transformed(ALPHA, GAMMAS, B, BHAT)

    def __init__(self, system, stats=None, jac_every: int = 1) -> None:
        super().__init__(system, stats, jac_every=jac_every)
        a, C, m, mhat, _ = self.tableau
        if not np.all(np.isfinite(a)):   # pragma: no cover - a published tableau
            raise InputError("tableau", self.name, "must have a regular Gamma")
        self._ac = [np.vstack([a[i, :i], C[i, :i]]) for i in range(self.stages)]
        self._m, self._dm = m, m - mhat

    def attempt(self, t, x, h):
        _, _, _, _, c = self.tableau
        self._refresh(t, x)
        W = self.lu(h)
        g = self.d * h
        f0 = self.f0(t, x)
        u = np.empty((self.stages, len(x)), dtype=np.result_type(x, f0, float))
        u[0] = g * W.solve_full(f0)
        for i in range(1, self.stages):
            shift, couple = self._ac[i] @ u[:i]
            u[i] = g * W.solve_full(self.f(t + c[i] * h, x + shift) + couple / h)
        x1 = x + self._m @ u
        err = self._dm @ u if self.need_error else None
        return Attempt(t, x, h, x1, err, f0)
