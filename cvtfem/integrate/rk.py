"""Explicit Runge-Kutta methods with embedded error control (spec §3.1).

EULER, RK4 and the Dormand-Prince pairs DOPRI45 (5(4), FSAL), DOPRI56 (6(5), 8 stages,
Dormand-Prince; coefficients as in the ``ode_num_int`` reference implementation) and DOPRI78
(Prince-Dormand 1981 8(7), 13 stages). Methods differ only in class-level tableaux.
The higher-order solution is propagated (local extrapolation) unless ``propagate="low"``;
source A's ref-impl propagates the lower one, which lowers the observed order by one.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper

__all__ = ["ExplicitRK", "Euler", "RK4", "DOPRI45", "DOPRI56", "DOPRI78", "rk_step"]


def rk_step(f, t, x, h, A, b, c, f0, b_err=None):
    """One explicit RK step; returns ``(x1, err or None, K)``, ``K`` the stage slopes (s, n)."""
    s = len(c)
    K = np.empty((s,) + x.shape, dtype=np.result_type(x, f0, h))
    K[0] = f0
    for i in range(1, s):
        K[i] = f(t + c[i] * h, x + h * (A[i, :i] @ K[:i]))
    x1 = x + h * (b @ K)
    err = None if b_err is None else h * (b_err @ K)
    return x1, err, K


class ExplicitRK(Stepper):
    """Tableau-driven explicit RK; subclasses set ``A``, ``b``, ``c`` and optionally ``b_low``."""

    substep_dense = True   # events on a step of the method itself (no continuous extension here)

    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    b_low: np.ndarray | None = None
    low_order: int | None = None
    fsal = False
    OPTIONS = frozenset({"propagate"})

    def __init__(self, system, stats=None, propagate: str = "high") -> None:
        super().__init__(system, stats)
        if propagate not in ("high", "low"):
            raise InputError("propagate", propagate, "must be 'high' or 'low'")
        b, b_low = self.b, self.b_low
        self.stages = len(self.c)
        if b_low is not None:
            if propagate == "low":
                b, b_low = b_low, b
                self.order = self.low_order
            self.error_order = min(self.order, self.low_order)
            self._b_err = b - b_low
        else:
            self._b_err = None
        self._b = b
        self.fsal = self.fsal and propagate == "high"

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        x1, err, K = rk_step(self.f, t, x, h, self.A, self._b, self.c, f0, self._b_err)
        f1 = K[-1] if self.fsal else None
        return Attempt(t, x, h, x1, err, f0, f1)


def _lower(rows, s):
    A = np.zeros((s, s))
    for i, row in enumerate(rows, start=1):
        A[i, :len(row)] = row
    return A


class Euler(ExplicitRK):
    """Explicit Euler, order 1 (baseline)."""

    name, order = "euler", 1
    A, b, c = np.zeros((1, 1)), np.array([1.0]), np.array([0.0])


class RK4(ExplicitRK):
    """Classical fourth-order Runge-Kutta."""

    name, order = "rk4", 4
    A = _lower([[0.5], [0, 0.5], [0, 0, 1]], 4)
    b = np.array([1, 2, 2, 1]) / 6
    c = np.array([0, 0.5, 0.5, 1])


class DOPRI45(ExplicitRK):
    """Dormand-Prince 5(4), 7 stages, FSAL (Hairer-Norsett-Wanner I, Table II.5.2)."""

    name, order, low_order, fsal = "dopri45", 5, 4, True
    A = _lower([[1 / 5], [3 / 40, 9 / 40], [44 / 45, -56 / 15, 32 / 9],
                [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729],
                [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
                [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]], 7)
    b = np.array([35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0])
    b_low = np.array([5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])
    c = np.array([0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1])


class DOPRI56(ExplicitRK):
    """Dormand-Prince 6(5), 8 stages, ``c = (0, 1/10, 2/9, 3/7, 3/5, 4/5, 1, 1)``."""

    name, order, low_order = "dopri56", 6, 5
    A = _lower([[1 / 10], [-2 / 81, 20 / 81], [615 / 1372, -270 / 343, 1053 / 1372],
                [3243 / 5500, -54 / 55, 50949 / 71500, 4998 / 17875],
                [-26492 / 37125, 72 / 55, 2808 / 23375, -24206 / 37125, 338 / 459],
                [5561 / 2376, -35 / 11, -24117 / 31603, 899983 / 200772, -5225 / 1836, 3925 / 4056],
                [465467 / 266112, -2945 / 1232, -5610201 / 14158144, 10513573 / 3212352,
                 -424325 / 205632, 376225 / 454272, 0]], 8)
    b = np.array([61 / 864, 0, 98415 / 321776, 16807 / 146016, 1375 / 7344, 1375 / 5408, -37 / 1120, 1 / 10])
    b_low = np.array([821 / 10800, 0, 19683 / 71825, 175273 / 912600, 395 / 3672, 785 / 2704, 3 / 50, 0])
    c = np.array([0, 1 / 10, 2 / 9, 3 / 7, 3 / 5, 4 / 5, 1, 1])


class DOPRI78(ExplicitRK):
    """Prince-Dormand 8(7), 13 stages (J. Comput. Appl. Math. 7, 1981, rational approximations)."""

    name, order, low_order = "dopri78", 8, 7
    A = _lower([
        [1 / 18], [1 / 48, 1 / 16], [1 / 32, 0, 3 / 32], [5 / 16, 0, -75 / 64, 75 / 64],
        [3 / 80, 0, 0, 3 / 16, 3 / 20],
        [29443841 / 614563906, 0, 0, 77736538 / 692538347, -28693883 / 1125000000,
         23124283 / 1800000000],
        [16016141 / 946692911, 0, 0, 61564180 / 158732637, 22789713 / 633445777,
         545815736 / 2771057229, -180193667 / 1043307555],
        [39632708 / 573591083, 0, 0, -433636366 / 683701615, -421739975 / 2616292301,
         100302831 / 723423059, 790204164 / 839813087, 800635310 / 3783071287],
        [246121993 / 1340847787, 0, 0, -37695042795 / 15268766246, -309121744 / 1061227803,
         -12992083 / 490766935, 6005943493 / 2108947869, 393006217 / 1396673457,
         123872331 / 1001029789],
        [-1028468189 / 846180014, 0, 0, 8478235783 / 508512852, 1311729495 / 1432422823,
         -10304129995 / 1701304382, -48777925059 / 3047939560, 15336726248 / 1032824649,
         -45442868181 / 3398467696, 3065993473 / 597172653],
        [185892177 / 718116043, 0, 0, -3185094517 / 667107341, -477755414 / 1098053517,
         -703635378 / 230739211, 5731566787 / 1027545527, 5232866602 / 850066563,
         -4093664535 / 808688257, 3962137247 / 1805957418, 65686358 / 487910083],
        [403863854 / 491063109, 0, 0, -5068492393 / 434740067, -411421997 / 543043805,
         652783627 / 914296604, 11173962825 / 925320556, -13158990841 / 6184727034,
         3936647629 / 1978049680, -160528059 / 685178525, 248638103 / 1413531060, 0]], 13)
    b = np.array([14005451 / 335480064, 0, 0, 0, 0, -59238493 / 1068277825, 181606767 / 758867731,
                  561292985 / 797845732, -1041891430 / 1371343529, 760417239 / 1151165299,
                  118820643 / 751138087, -528747749 / 2220607170, 1 / 4])
    b_low = np.array([13451932 / 455176623, 0, 0, 0, 0, -808719846 / 976000145,
                      1757004468 / 5645159321, 656045339 / 265891186, -3867574721 / 1518517206,
                      465885868 / 322736535, 53011238 / 667516719, 2 / 45, 0])
    c = np.array([0, 1 / 18, 1 / 12, 1 / 8, 5 / 16, 3 / 8, 59 / 400, 93 / 200,
                  5490023248 / 9719169821, 13 / 20, 1201146811 / 1299019798, 1, 1])
