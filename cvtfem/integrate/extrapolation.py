"""Aitken-Neville extrapolation over a base one-step method (spec §3.2, §4.1).

Stage ``k`` takes ``n_k`` base steps of ``h/n_k`` from the same ``x0``; the tableau
``T[j,k+1] = T[j,k] + (T[j,k] - T[j-1,k]) / ((n_j/n_{j-k})^gamma - 1)`` with ``gamma = 2``
for the symmetric Gragg base and 1 otherwise. Order = base order + (stages-1)*gamma; the
difference of the last two diagonal entries is the error estimate.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper

__all__ = ["step_sequence", "Extrapolator", "EulerExtrapolation", "GBS", "GBSSmooth", "euler_base",
           "gragg_base"]

SEQUENCES = ("harmonic", "romberg", "bulirsch")


def step_sequence(name: str, k: int) -> np.ndarray:
    """First ``k`` entries: harmonic 1,2,3,..; Romberg 1,2,4,8,..; Bulirsch 1,2,3,4,6,8,12,.."""
    if name == "harmonic":
        return np.arange(1, k + 1)
    if name == "romberg":
        return 2 ** np.arange(k)
    if name == "bulirsch":
        seq = [1, 2, 3]
        while len(seq) < k:
            seq.append(2 * seq[-2])
        return np.array(seq[:k])
    raise InputError("sequence", name, f"must be one of {SEQUENCES}")


def euler_base(f, t, x, h, n, f0):
    """``n`` explicit Euler steps of ``h/n`` (order 1, asymmetric)."""
    H = h / n
    y = x + H * f0
    for i in range(1, n):
        y = y + H * f(t + i * H, y)
    return y


def gragg_base(f, t, x, h, n, f0, smooth=False):
    """Gragg's leapfrog with ``2n`` substeps ``H = h/(2n)``; optional smoothing step.

    ``y1 = y0 + H f(y0)``, ``y_{i+1} = y_{i-1} + 2H f(y_i)``; smoothing
    ``S = (y_{2m-1} + 2 y_{2m} + y_{2m+1})/4`` computed as ``(U + V)/2`` with ``U = y_{2m}``,
    ``V = y_{2m-1} + H f(y_{2m})`` (spec §3.2).
    """
    m2 = 2 * n
    H = h / m2
    y_prev, y = x, x + H * f0
    for i in range(1, m2):
        y_prev, y = y, y_prev + 2 * H * f(t + i * H, y)
    if smooth:
        return 0.5 * (y + y_prev + H * f(t + h, y))
    return y


class Extrapolator(Stepper):
    """Fixed-stage extrapolation of a base method (no order control, as the ref-impl)."""

    base_order = 1
    gamma = 1
    OPTIONS = frozenset({"stages", "sequence"})
    substep_dense = True   # events on a step of the method itself (no continuous extension here)

    def __init__(self, system, stats=None, stages: int = 4, sequence: str = "harmonic") -> None:
        super().__init__(system, stats)
        if not (isinstance(stages, (int, np.integer)) and 1 <= stages <= 12):
            raise InputError("stages", stages, "must be an integer in 1..12")
        self.n_seq = step_sequence(sequence, stages)
        self.stages = int(stages)
        self.order = self.base_order + (stages - 1) * self.gamma
        self.error_order = self.order - self.gamma if stages > 1 else None

    def base(self, t, x, h, n, f0):  # pragma: no cover - abstract
        raise NotImplementedError

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        T = []
        prev_diag = None
        for j, n in enumerate(self.n_seq):
            row = [self.base(t, x, h, int(n), f0)]
            for k in range(j):
                r = (n / self.n_seq[j - k - 1]) ** self.gamma
                row.append(row[k] + (row[k] - T[j - 1][k]) / (r - 1))
            if j == len(self.n_seq) - 1 and j > 0:
                prev_diag = T[j - 1][j - 1]
            T.append(row)
        x1 = T[-1][-1]
        err = None if prev_diag is None else x1 - prev_diag
        return Attempt(t, x, h, x1, err, f0)


class EulerExtrapolation(Extrapolator):
    """EULER-Xp: explicit Euler extrapolated over ``stages`` = p rows; order p."""

    name, base_order, gamma = "euler-extrapolation", 1, 1

    def base(self, t, x, h, n, f0):
        return euler_base(self.f, t, x, h, n, f0)


class GBS(Extrapolator):
    """GBSp: Gragg-Bulirsch-Stoer without smoothing; order 2p for p stages."""

    name, base_order, gamma = "gbs", 2, 2
    smooth = False

    def base(self, t, x, h, n, f0):
        return gragg_base(self.f, t, x, h, n, f0, self.smooth)


class GBSSmooth(GBS):
    """GBSps: Gragg-Bulirsch-Stoer with Gragg's smoothing step; order 2p."""

    name = "gbs-smooth"
    smooth = True
