"""Rosenbrock method RODAS4 (Hairer-Wanner II §IV.7 and §VI.4; order 4, embedded order 3).

Six stages, stiffly accurate and L-stable (``R(-inf) = 0``), with ``gamma = 1/4``. In the form of
Hairer-Wanner (7.25), with ``u_i`` the stage increments and ``J = dF/dx`` at the step's start:

``(I - h gamma J) u_i = h gamma [F(t0 + c_i h, x0 + sum_j a_ij u_j) + sum_j (C_ij / h) u_j + h d_i F_t]``,

``x1 = x0 + sum_{j<=5} a_6j u_j + u_6``: the stage values of stages 5 and 6 are the embedded
(order 3) and the order-4 solutions, so the error estimate is ``u_6``. ``F_t`` is a forward
difference (one RHS call per step). The coefficients are the published figures of Hairer & Wanner
(their code RODAS, choice of Hairer-Wanner II §VI.4). A fresh Jacobian and one LU per accepted step
(a rejected step keeps the Jacobian and refactorises); the linear systems go through the reduced
matrix of :mod:`cvtfem.integrate.linsolve` (second-order structure eliminated, SuperLU when sparse).

Dense output (order 3, from the same code): ``x(s) = (1 - s) x0 + s [x1 + (1 - s)(H2 + s H3)]``,
``s = (t - t0)/h``, ``H2 = sum_j h2_j u_j``, ``H3 = sum_j h3_j u_j`` (``j = 1..5``).
"""
from __future__ import annotations

import numpy as np

from cvtfem.integrate.base import Attempt
from cvtfem.integrate.wmethods import _WBase

__all__ = ["Rodas4"]

GAMMA = 0.25
C = np.array([0.0, 0.386, 0.21, 0.63, 1.0, 1.0])      # stage times
A = np.zeros((6, 6))                                  # stage values x0 + sum_j A[i, j] u_j
A[1, 0] = 1.544
A[2, :2] = [0.9466785280815826, 0.2557011698983284]
A[3, :3] = [3.314825187068521, 2.896124015972201, 0.9986419139977817]
A[4, :4] = [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950]
A[5, :5] = A[4, :5] + np.eye(5)[4]                    # stage 6 = stage 5 value + u_5
CC = np.zeros((6, 6))                                 # coupling C_ij / h
CC[1, 0] = -5.6688
CC[2, :2] = [-2.430093356833875, -0.2063599157091915]
CC[3, :3] = [-0.1073529058151375, -9.594562251023355, -20.47028614809616]
CC[4, :4] = [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160]
CC[5, :5] = [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054]
AC = [np.vstack([A[i, :i], CC[i, :i]]) for i in range(6)]   # both sums of stage i in one product
D = np.array([0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0])   # F_t weights
H2 = np.array([10.12623508344586, -7.487995877610167, -34.80091861555747, -7.992771707568823,
               1.025137723295662])
H3 = np.array([-0.6762803392801253, 6.087714651680015, 16.43084320892478, 24.76722511418386,
               -6.594389125716872])


class Rodas4(_WBase):
    """RODAS4: 6-stage Rosenbrock method of order 4(3), L-stable, with order-3 dense output."""

    name, order, error_order, stages = "rodas4", 4, 3, 6
    OPTIONS = frozenset()
    STEP_QUANTUM = 1.0   # a new Jacobian (and LU) every step anyway
    controller = "predictive"   # as Hairer's RODAS: fewer rejections before fast transients

    def __init__(self, system, stats=None) -> None:
        super().__init__(system, stats, d=GAMMA, jac_every=1)

    def _dfdt(self, t: float, x: np.ndarray, f0: np.ndarray) -> np.ndarray:
        """``dF/dt`` at ``(t, x)`` by a forward difference, 1/s times the units of ``F``."""
        dt = np.sqrt(np.finfo(float).eps * max(1e-5, abs(t)))
        return (self.f(t + dt, x) - f0) / dt

    def attempt(self, t, x, h):
        self._refresh(t, x)
        W = self.lu(h)
        g = GAMMA * h
        f0 = self.f0(t, x)
        ft = h * self._dfdt(t, x, f0)
        u = np.empty((6, len(x)), dtype=np.result_type(x, f0, float))
        u[0] = g * W.solve_full(f0 + D[0] * ft)
        for i in range(1, 6):
            shift, couple = AC[i] @ u[:i]
            u[i] = g * W.solve_full(self.f(t + C[i] * h, x + shift) + couple / h + D[i] * ft)
        x1 = x + A[5, :5] @ u[:5] + u[5]
        h2, h3 = H2 @ u[:5], H3 @ u[:5]

        def interp(tq):
            s = (np.asarray(tq, dtype=float) - t) / h
            if np.ndim(s) == 0:
                return (1 - s) * x + s * (x1 + (1 - s) * (h2 + s * h3))
            return np.outer(x, 1 - s) + np.outer(x1, s) + np.outer(h2, s * (1 - s)) + np.outer(h3, s * s * (1 - s))

        return Attempt(t, x, h, x1, u[5], f0, interp=interp)
