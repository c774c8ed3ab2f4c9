"""ROCK2 and ROCK4: orthogonal Runge-Kutta-Chebyshev methods (spec §11.6).

ROCK2 (Abdulle & Medovikov, Numer. Math. 90, 2001), order 2, ``s = m + 2`` stages, and
ROCK4 (Abdulle, SIAM J. Sci. Comput. 23, 2002), order 4, ``s = m + 4``. Their stability
polynomials are ``R(z) = w(z) P_m(z)``: ``w`` is the stability polynomial of the finishing
procedure (a quadratic for ROCK2, a quartic for ROCK4) and ``P_m`` belongs to the family
orthogonal for ``w(z(x))^2 / sqrt(1 - x^2)``, ``z(x) = -eps + ell (x - 1)/2``, x in [-1, 1].
Only the finishing data are published tables (:mod:`cvtfem.integrate.rock_data`); the
recurrence ``P_j = mu_j z P_{j-1} + (1 + kappa_j) P_{j-1} - kappa_j P_{j-2}`` is regenerated:
for each degree ``(ell, eps)`` solve ``R'(0) = 1``, ``R''(0) = 1`` and a discretised
Stieltjes procedure on Gauss-Chebyshev nodes gives ``(mu_j, kappa_j)``. This reproduces the
published recurrence tables to ~1e-13, and for ROCK4 the third- and fourth-order conditions
then hold as well (tests), which also validates the transcribed tables.
Stages: ``g_j = h mu_j F(g_{j-1}) + (1 + kappa_j) g_{j-1} - kappa_j g_{j-2}``, then the
finishing procedure on ``g_m``.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.optimize import fsolve

from cvtfem.errors import InputError
from cvtfem.integrate import rock_data as D
from cvtfem.integrate.base import Attempt, Stepper
from cvtfem.integrate.stabilized import SpectralRadiusTracker

__all__ = ["ROCK2", "ROCK4", "recurrence", "stability_length", "finishing_polynomial"]

_NPV = np.polynomial.polynomial


def finishing_polynomial(family: int, k: int) -> np.ndarray:
    """Coefficients (ascending) of ``w(z)`` for ROCK``family`` degree index ``k``."""
    if family == 2:
        sigma = D.FP1[k]
        return np.array([1.0, 2 * sigma, sigma * (sigma + D.FP2[k])])
    a21, a31, a32, a41, a42, a43 = D.FPA[k]
    A = np.array([[0, 0, 0, 0], [a21, 0, 0, 0], [a31, a32, 0, 0], [a41, a42, a43, 0.0]])
    b, v, c = np.array(D.FPB[k]), np.ones(4), [1.0]
    for _ in range(4):
        c.append(b @ v)
        v = A @ v
    return np.array(c)


def _degrees(family: int):
    return D.MS2 if family == 2 else D.MS4


def _stieltjes(m: int, wc: np.ndarray, ell: float, eps: float) -> np.ndarray:
    """``[mu_1, mu_2, kappa_2, ..., mu_m, kappa_m]`` for the interval ``(ell, eps)``."""
    M = 4 * m + 60
    x = np.cos((2 * np.arange(1, M + 1) - 1) * np.pi / (2 * M))
    x0 = 1 + 2 * eps / ell                         # where z = 0: normalisation P_j(0) = 1
    wt = _NPV.polyval(-eps + ell * (x - 1) / 2, wc) ** 2
    out = np.empty(2 * m - 1)
    p2, p1 = None, np.ones(M)
    for j in range(1, m + 1):
        a = (wt * x) @ (p1 * p1) / (wt @ (p1 * p1))
        if j == 1:
            q1 = x0 - a
            p = (x - a) / q1
            out[0] = (2 / ell) / q1
        else:
            b = (wt * x) @ (p1 * p2) / (wt @ (p2 * p2))
            q1 = x0 - a - b
            p = ((x - a) * p1 - b * p2) / q1
            out[2 * j - 3], out[2 * j - 2] = (2 / ell) / q1, b / q1
        p2, p1 = p1, p
    return out


def _taylor(recf: np.ndarray, n: int = 5) -> np.ndarray:
    """First ``n`` Taylor coefficients of ``P_m`` from its recurrence."""
    p2 = np.zeros(n)
    p2[0] = 1.0
    p1 = p2.copy()
    p1[1] = recf[0]
    for i in range(1, len(recf), 2):
        mu, ka = recf[i], recf[i + 1]
        p2, p1 = p1, mu * np.concatenate([[0.0], p1[:-1]]) + (1 + ka) * p1 - ka * p2
    return p1


@lru_cache(maxsize=None)
def _interval(family: int, k: int) -> tuple[float, float]:
    """``(ell, eps)`` of degree index ``k >= 2``, by continuation from ``m = 3``."""
    ms, extra = _degrees(family), family
    if k == 2:
        guess = (19.0, 0.09) if family == 2 else (14.6, -0.17)
    else:
        ell, eps = _interval(family, k - 1)
        guess = (ell * ((ms[k] + extra) / (ms[k - 1] + extra)) ** 2, eps)
    wc = finishing_polynomial(family, k)

    def conditions(p):
        c = _NPV.polymul(wc, _taylor(_stieltjes(ms[k], wc, p[0], p[1]), 3))
        return [c[1] - 1.0, c[2] - 0.5]

    sol, info, ok, msg = fsolve(conditions, guess, full_output=True, xtol=1e-13)
    if ok != 1 or max(abs(v) for v in info["fvec"]) > 1e-10:
        raise RuntimeError(f"ROCK{family} degree {ms[k]}: order conditions not solved ({msg})")
    return float(sol[0]), float(sol[1])


@lru_cache(maxsize=None)
def recurrence(family: int, k: int) -> np.ndarray:
    """Recurrence coefficients of ROCK``family`` degree index ``k`` (regenerated)."""
    wc = finishing_polynomial(family, k)
    m = _degrees(family)[k]
    if m == 1:   # P_1 = 1 + mu z, fixed by R'(0) = 1 alone
        return np.array([1.0 - wc[1]])
    if m == 2:   # one free parameter: the published choice
        return np.array(D.RECF_M2[family])
    return _stieltjes(m, wc, *_interval(family, k))


def _R(family: int, k: int, z: np.ndarray) -> np.ndarray:
    recf = recurrence(family, k)
    p2, p1 = np.ones_like(z), 1 + recf[0] * z
    for i in range(1, len(recf), 2):
        mu, ka = recf[i], recf[i + 1]
        p2, p1 = p1, mu * z * p1 + (1 + ka) * p1 - ka * p2
    return _NPV.polyval(z, finishing_polynomial(family, k)) * p1


@lru_cache(maxsize=None)
def stability_length(family: int, k: int) -> float:
    """Real stability interval ``[-beta, 0]`` (sampled ``|R| <= 1``, end bisected)."""
    s = _degrees(family)[k] + family
    z = -np.linspace(0.0, 1.5 * s * s, 15 * s * s + 1001)
    bad = np.flatnonzero(np.abs(_R(family, k, z)) > 1 + 1e-12)
    if not len(bad):
        return float(-z[-1])
    lo, hi = -z[bad[0] - 1], -z[bad[0]]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(_R(family, k, np.array([-mid]))[0]) <= 1 + 1e-12 else (lo, mid)
    return float(lo)


class _Rock(SpectralRadiusTracker, Stepper):
    """Shared parts: degree choice (fixed ``stages`` or from the spectral radius), recurrence."""

    family = 2
    OPTIONS = frozenset({"stages", "spectral_radius", "rho_every"})

    def __init__(self, system, stats=None, stages: int | None = None, spectral_radius=None,
                 rho_every: int = 25) -> None:
        super().__init__(system, stats)
        ms = np.array(_degrees(self.family)) + self.family
        self.fixed = None
        if stages is not None:
            if not (isinstance(stages, (int, np.integer)) and ms[0] <= stages <= ms[-1]):
                raise InputError("stages", stages, f"must be an integer in {ms[0]}..{ms[-1]} or None")
            self.fixed = int(np.searchsorted(ms, stages))
        if spectral_radius is not None and not (callable(spectral_radius) or spectral_radius > 0):
            raise InputError("spectral_radius", spectral_radius, "must be a positive number, a callable or None")
        self._init_rho(spectral_radius, rho_every)
        self.stages = int(ms[self.fixed if self.fixed is not None else 0])
        self._longest = 0.0   # the longest degree's stability length, once known

    def _degree(self, t, x, f0, h) -> int:
        if self.fixed is not None:
            return self.fixed
        rho = self._current_rho(t, x, f0)
        n = len(_degrees(self.family))
        for k in range(n):   # lengths are computed lazily (cached), smallest sufficient degree
            if stability_length(self.family, k) >= h * rho:
                return k
        k = max(range(n), key=lambda k: stability_length(self.family, k))
        self._longest = stability_length(self.family, k)
        return k

    def max_step(self) -> float:
        """The fixed degree's, or (once a step has needed more than any degree offers) the longest degree's
        stability length over the spectral radius, s; inf before (the lengths of all degrees take seconds)."""
        if self.fixed is not None:
            return self._step_cap(stability_length(self.family, self.fixed))
        return self._step_cap(self._longest) if self._longest else np.inf

    def _chebyshev_stages(self, t, x, h, f0, k):
        """The ``m`` recurrence stages; returns ``(g_m, t_m, g_{m-1}, t_{m-1})``."""
        recf = recurrence(self.family, k)
        self.stages = _degrees(self.family)[k] + self.family
        g2, g1 = x, x + h * recf[0] * f0
        c2, c1 = t, t + h * recf[0]
        for i in range(1, len(recf), 2):
            mu, ka = recf[i], recf[i + 1]
            g2, g1 = g1, h * mu * self.f(c1, g1) + (1 + ka) * g1 - ka * g2
            c2, c1 = c1, h * mu + (1 + ka) * c1 - ka * c2
        return g1, c1


class ROCK2(_Rock):
    """ROCK2, order 2; finishing ``g* = (two Euler steps of h sigma)``,
    ``x1 = g* + h FP2 (F(g_{s-1}) - F(g_{s-2}))``; the last term is the error estimate."""

    name, order, error_order, family = "rock2", 2, 1, 2

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        k = self._degree(t, x, f0, h)
        g, c = self._chebyshev_stages(t, x, h, f0, k)
        sigma, fp2 = D.FP1[k], D.FP2[k]
        fa = self.f(c, g)
        g1 = g + h * sigma * fa
        fb = self.f(c + h * sigma, g1)
        corr = h * fp2 * (fb - fa)
        return Attempt(t, x, h, g1 + h * sigma * fb + corr, corr, f0)


class ROCK4(_Rock):
    """ROCK4, order 4; 4-stage finishing RK (``FPA``, ``FPB``) with an embedded order-3
    estimate (``FPBE``, its fifth weight on ``F(x1)``, which is reused as the next ``F0``)."""

    name, order, error_order, family = "rock4", 4, 3, 4

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        k = self._degree(t, x, f0, h)
        g, c = self._chebyshev_stages(t, x, h, f0, k)
        a21, a31, a32, a41, a42, a43 = D.FPA[k]
        b, be = D.FPB[k], D.FPBE[k]
        k1 = self.f(c, g)
        k2 = self.f(c + a21 * h, g + h * a21 * k1)
        k3 = self.f(c + (a31 + a32) * h, g + h * (a31 * k1 + a32 * k2))
        k4 = self.f(c + (a41 + a42 + a43) * h, g + h * (a41 * k1 + a42 * k2 + a43 * k3))
        x1 = g + h * (b[0] * k1 + b[1] * k2 + b[2] * k3 + b[3] * k4)
        err = f1 = None
        if self.need_error:
            f1 = self.f(t + h, x1)
            emb = g + h * (be[0] * k1 + be[1] * k2 + be[2] * k3 + be[3] * k4 + be[4] * f1)
            err = x1 - emb
        return Attempt(t, x, h, x1, err, f0, f1)
