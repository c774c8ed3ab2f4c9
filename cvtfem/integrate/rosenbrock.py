"""Stiffly accurate Rosenbrock methods RODAS4 and RODAS5P, with their dense outputs.

In the form of Hairer-Wanner II (7.25), with ``u_i`` the stage increments and ``J = dF/dx`` at the
step's start (``s`` stages, one LU of ``I - h gamma J`` per step):

``(I - h gamma J) u_i = h gamma [F(t0 + c_i h, x0 + sum_j a_ij u_j) + sum_j (C_ij / h) u_j + h d_i F_t]``.

The last stages are evaluated at ``t0 + h`` on ``x0 + sum_j a_sj u_j`` plus the increments before
them: the stage value of the last stage is the embedded solution and ``x1`` that value plus ``u_s``, so
the error estimate is ``u_s``. ``F_t`` is a forward difference (one RHS call per step). A fresh
Jacobian and one LU per accepted step (a rejected step keeps the Jacobian and refactorises); the linear
systems go through the reduced matrix of :mod:`cvtfem.integrate.linsolve` (second-order structure
eliminated, SuperLU when sparse). Dense output: ``x(s) = (1 - s) x0 + s [x1 + (1 - s) P(s)]`` with
``P(s) = H_1 + s (H_2 + s H_3 ...)``, ``H_k = sum_j h_kj u_j``, ``s = (t - t0)/h``.

* ``rodas4``: RODAS4 of Hairer & Wanner (II §IV.7, §VI.4; their code RODAS), 6 stages, order 4 with an
  order-3 embedded solution, ``gamma = 1/4``, L-stable, dense output of order 3.
* ``rodas5p``: Rodas5P of Steinebach (2023; the coefficients as published in OrdinaryDiffEq.jl), 8 stages,
  order 5 with an order-4 embedded solution, ``gamma = 0.2119...``, L-stable, dense output of order 4.

The coefficients are published figures.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.integrate.base import Attempt
from cvtfem.integrate.wmethods import _WBase

__all__ = ["Rodas4", "Rodas5P", "RosenbrockTableau"]


@dataclass(frozen=True)
class RosenbrockTableau:
    """Coefficients of an ``s``-stage method of the form above: ``gamma``; ``c`` (s,); ``a`` and ``cc``
    (s, s) strictly lower, with the stage-value rows of the last stages already including the increments
    before them; ``d`` (s,); dense-output rows ``h`` (k, s)."""

    gamma: float
    c: np.ndarray
    a: np.ndarray
    cc: np.ndarray
    d: np.ndarray
    h: np.ndarray

    @property
    def stacked(self) -> list[np.ndarray]:
        """Per stage ``[a_i; C_i]`` (2, i): both sums of a stage in one product."""
        return [np.vstack([self.a[i, :i], self.cc[i, :i]]) for i in range(len(self.c))]


def _tableau(gamma, c, a_rows, cc_rows, d, h_rows, n_tail):
    """Build a tableau from the lower-triangular rows of the first ``s - n_tail`` stage values; the
    ``n_tail`` last stages take the previous stage value plus the previous increment."""
    s = len(cc_rows) + 1
    a = np.zeros((s, s))
    for i, row in enumerate(a_rows, start=1):
        a[i, :len(row)] = row
    for i in range(s - n_tail, s):
        a[i, :i] = a[i - 1, :i] + np.eye(i)[i - 1]
    cc = np.zeros((s, s))
    for i, row in enumerate(cc_rows, start=1):
        cc[i, :len(row)] = row
    h = np.zeros((len(h_rows), s))
    for k, row in enumerate(h_rows):
        h[k, :len(row)] = row
    return RosenbrockTableau(gamma, np.array(c, dtype=float), a, cc, np.array(d, dtype=float), h)


RODAS4 = _tableau(
    0.25, [0.0, 0.386, 0.21, 0.63, 1.0, 1.0],
    [[1.544], [0.9466785280815826, 0.2557011698983284],
     [3.314825187068521, 2.896124015972201, 0.9986419139977817],
     [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950]],
    [[-5.6688], [-2.430093356833875, -0.2063599157091915],
     [-0.1073529058151375, -9.594562251023355, -20.47028614809616],
     [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160],
     [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054]],
    [0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0],
    [[10.12623508344586, -7.487995877610167, -34.80091861555747, -7.992771707568823, 1.025137723295662],
     [-0.6762803392801253, 6.087714651680015, 16.43084320892478, 24.76722511418386, -6.594389125716872]],
    n_tail=1)

RODAS5P = _tableau(
    0.21193756319429014,
    [0.0, 0.6358126895828704, 0.4095798393397535, 0.9769306725060716, 0.4288403609558664, 1.0, 1.0, 1.0],
    [[3.0], [2.849394379747939, 0.45842242204463923],
     [-6.954028509809101, 2.489845061869568, -10.358996098473584],
     [2.8029986275628964, 0.5072464736228206, -0.3988312541770524, -0.04721187230404641],
     [-7.502846399306121, 2.561846144803919, -11.627539656261098, -0.18268767659942256, 0.030198172008377946]],
    [[-14.155112264123755], [-17.97296035885952, -2.859693295451294],
     [147.12150275711716, -1.41221402718213, 71.68940251302358],
     [165.43517024871676, -0.4592823456491126, 42.90938336958603, -5.961986721573306],
     [24.854864614690072, -3.0009227002832186, 47.4931110020768, 5.5814197821558125, -0.6610691825249471],
     [30.91273214028599, -3.1208243349937974, 77.79954646070892, 34.28646028294783, -19.097331116725623,
      -28.087943162872662],
     [37.80277123390563, -3.2571969029072276, 112.26918849496327, 66.9347231244047, -40.06618937091002,
      -54.66780262877968, -9.48861652309627]],
    [0.21193756319429014, -0.42387512638858027, -0.3384627126235924, 1.8046452872882734, 2.325825639765069,
     0.0, 0.0, 0.0],
    [[25.948786856663858, -2.5579724845846235, 10.433815404888879, -2.3679251022685204, 0.524948541321073,
      1.1241088310450404, 0.4272876194431874, -0.17202221070155493],
     [-9.91568850695171, -0.9689944594115154, 3.0438037242978453, -24.495224566215796, 20.176138334709044,
      15.98066361424651, -6.789040303419874, -6.710236069923372],
     [11.419903575922262, 2.8879645146136994, 72.92137995996029, 80.12511834622643, -52.072871366152654,
      -59.78993625266729, -0.15582684282751913, 4.883087185713722]],
    n_tail=2)


class Rodas4(_WBase):
    """RODAS4: 6-stage Rosenbrock method of order 4(3), L-stable, with order-3 dense output."""

    name, order, error_order, stages = "rodas4", 4, 3, 6
    tableau = RODAS4
    OPTIONS = frozenset()
    STEP_QUANTUM = 1.0   # a new Jacobian (and LU) every step anyway
    controller = "predictive"   # as Hairer's RODAS: fewer rejections before fast transients

    def __init__(self, system, stats=None) -> None:
        super().__init__(system, stats, d=self.tableau.gamma, jac_every=1)
        self._ac = self.tableau.stacked

    def _dfdt(self, t: float, x: np.ndarray, f0: np.ndarray) -> np.ndarray:
        """``dF/dt`` at ``(t, x)`` by a forward difference, 1/s times the units of ``F``."""
        dt = np.sqrt(np.finfo(float).eps * max(1e-5, abs(t)))
        return (self.f(t + dt, x) - f0) / dt

    def attempt(self, t, x, h):
        tab, s = self.tableau, self.stages
        self._refresh(t, x)
        W = self.lu(h)
        g = tab.gamma * h
        f0 = self.f0(t, x)
        ft = h * self._dfdt(t, x, f0)
        u = np.empty((s, len(x)), dtype=np.result_type(x, f0, float))
        u[0] = g * W.solve_full(f0 + tab.d[0] * ft)
        for i in range(1, s):
            shift, couple = self._ac[i] @ u[:i]
            u[i] = g * W.solve_full(self.f(t + tab.c[i] * h, x + shift) + couple / h + tab.d[i] * ft)
        x1 = x + tab.a[s - 1, :s - 1] @ u[:s - 1] + u[s - 1]
        rows = tab.h @ u

        def interp(tq):
            th = (np.asarray(tq, dtype=float) - t) / h
            if np.ndim(th) == 0:
                p = rows[-1]
                for r in rows[-2::-1]:
                    p = r + th * p
                return (1 - th) * x + th * (x1 + (1 - th) * p)
            p = np.outer(rows[-1], np.ones_like(th))
            for r in rows[-2::-1]:
                p = r[:, None] + th * p
            return np.outer(x, 1 - th) + th * (x1[:, None] + (1 - th) * p)

        return Attempt(t, x, h, x1, u[s - 1], f0, interp=interp)


class Rodas5P(Rodas4):
    """Rodas5P: 8-stage Rosenbrock method of order 5(4), L-stable, with order-4 dense output."""

    name, order, error_order, stages = "rodas5p", 5, 4, 8
    tableau = RODAS5P
