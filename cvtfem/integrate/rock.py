"""ROCK2 (Abdulle & Medovikov, Numer. Math. 90, 2001): orthogonal Runge-Kutta-Chebyshev, order 2.

Stability polynomial ``R_s(z) = w(z) P_m(z)``, ``s = m + 2`` stages, with the quadratic factor
``w(z) = 1 + 2 sigma z + tau z^2`` and ``P_m`` from a family orthogonal with respect to
``w(z(x))^2 / sqrt(1 - x^2)`` on ``z(x) = -eps + ell (x - 1)/2``, ``x`` in [-1, 1]. The
published data are ``sigma`` (``FP1``) and ``tau/sigma - sigma`` (``FP2``) for 46 degrees
``MS`` (from Abdulle's ROCK2 code, as tabulated in the MIT-licensed OrdinaryDiffEq.jl);
the recurrence coefficients ``recf`` are *regenerated* here: for each degree the two
unknowns ``(ell, eps)`` are fixed by the order conditions ``R'(0) = 1``, ``R''(0) = 1``,
then a discretised Stieltjes procedure on Gauss-Chebyshev nodes gives the three-term
recurrence ``P_j = mu_j z P_{j-1} + (1 + kappa_j) P_{j-1} - kappa_j P_{j-2}``
(checked against the published ``recf`` to 1e-12 in the tests).
Stages: ``g_j = h mu_j F(g_{j-1}) + (1 + kappa_j) g_{j-1} - kappa_j g_{j-2}``; finishing
``g_{s-1} = g_{s-2} + h sigma F(g_{s-2})``, ``g* = g_{s-1} + h sigma F(g_{s-1})``,
``x1 = g* + h FP2 (F(g_{s-1}) - F(g_{s-2}))``; the last term is the error estimate.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.optimize import fsolve

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper
from cvtfem.integrate.stabilized import spectral_radius

__all__ = ["ROCK2", "rock2_recurrence", "rock2_stability_length", "MS"]

MS = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 22, 24, 26, 28, 30, 33,
      36, 39, 43, 47, 51, 56, 61, 66, 72, 78, 85, 93, 102, 112, 123, 135, 148, 163, 180, 198)
FP1 = (0.4102693550421609, 0.3889624104727243, 0.3804692420283886, 0.3760815680865637,
       0.3735177579729938, 0.3719340231904236, 0.3708571145968057, 0.3700947006022557,
       0.3695328931459086, 0.3691085831661758, 0.368781324965233, 0.3685244707068931,
       0.3683185599507446, 0.3681542178682514, 0.3680181997765286, 0.3679084456991284,
       0.3678181571053212, 0.3678314333608541, 0.3677897070402892, 0.3681800192470787,
       0.3681272993461229, 0.3680840569645587, 0.3680522380648169, 0.3680263578626069,
       0.3680061275157194, 0.3679837719607466, 0.3679668653311732, 0.3679542340323301,
       0.367942933258425, 0.3679349432021754, 0.3679290943359695, 0.3679242023884676,
       0.3679207541681089, 0.3679185472223537, 0.367916869013064, 0.3679158588043139,
       0.3679154592969145, 0.3679154025286917, 0.3679157536198652, 0.3679163676763697,
       0.3679171904021983, 0.3679181786833088, 0.3679192462983425, 0.367920432307971,
       0.3679216942157868, 0.3679229127010114)
FP2 = (0.4495196112243335, 0.4219428123056774, 0.4084335547255627, 0.4009301129475925,
       0.3963598727888637, 0.3934034185789226, 0.3913676516238603, 0.3899091428928617,
       0.388827696299666, 0.3880048656683555, 0.3873650613539532, 0.3868583585730354,
       0.3864499054795832, 0.3861178821587815, 0.3858426294881124, 0.3856144554520791,
       0.3854228843194507, 0.3853156085078759, 0.3851902798680153, 0.3853705093720269,
       0.3851957294861824, 0.3850587241670235, 0.3849515900397918, 0.3848648995575697,
       0.38479450822313, 0.38471172244074, 0.384647872630907, 0.3845979020112835,
       0.3845472492329918, 0.3845088319509754, 0.3844789634065264, 0.3844504092359686,
       0.3844285235163634, 0.3844115660464609, 0.3843957877945634, 0.3843835767106759,
       0.3843727001444428, 0.3843632394180673, 0.3843553120908175, 0.3843487746818896,
       0.3843434800804404, 0.3843392605995229, 0.3843359163858929, 0.3843331309176606,
       0.3843309056586355, 0.3843292556220249)


def _recurrence(m: int, sigma: float, tau: float, ell: float, eps: float) -> np.ndarray:
    """``[mu_1, mu_2, kappa_2, ..., mu_m, kappa_m]`` for the interval ``(ell, eps)``."""
    M = 4 * m + 40
    x = np.cos((2 * np.arange(1, M + 1) - 1) * np.pi / (2 * M))
    z = -eps + ell * (x - 1) / 2
    x0 = 1 + 2 * eps / ell          # where z = 0 (normalisation P_j(0) = 1)
    wt = (1 + 2 * sigma * z + tau * z * z) ** 2
    out = np.empty(2 * m - 1)
    p2, p1 = None, np.ones(M)
    for j in range(1, m + 1):
        n1 = wt @ (p1 * p1)
        a = (wt * x) @ (p1 * p1) / n1
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


def _taylor(recf: np.ndarray) -> tuple[float, float]:
    """``P_m'(0)`` and ``P_m''(0)/2`` from the recurrence."""
    d2, d1, e2, e1 = 0.0, recf[0], 0.0, 0.0
    for i in range(1, len(recf), 2):
        mu, ka = recf[i], recf[i + 1]
        d2, d1, e2, e1 = d1, mu + (1 + ka) * d1 - ka * d2, e1, mu * d1 + (1 + ka) * e1 - ka * e2
    return d1, e1


@lru_cache(maxsize=None)
def _interval(k: int) -> tuple[float, float]:
    """``(ell, eps)`` of degree index ``k`` by continuation from degree 3 (solved once)."""
    if k == 2:
        guess = (19.0, 0.09)
    elif k < 2:
        ell3, eps3 = _interval(2)
        guess = (ell3 * ((MS[k] + 2) / 5) ** 2, eps3)
    else:
        ell, eps = _interval(k - 1)
        guess = (ell * ((MS[k] + 2) / (MS[k - 1] + 2)) ** 2, eps)
    m, sigma = MS[k], FP1[k]
    tau = sigma * (sigma + FP2[k])

    def conditions(p):
        d, e = _taylor(_recurrence(m, sigma, tau, p[0], p[1]))
        return [d + 2 * sigma - 1, e + 2 * sigma * d + tau - 0.5]

    sol, info, ok, msg = fsolve(conditions, guess, full_output=True, xtol=1e-13)
    if ok != 1 or max(abs(v) for v in info["fvec"]) > 1e-10:
        raise RuntimeError(f"ROCK2 degree {m}: order conditions not solved ({msg})")
    return float(sol[0]), float(sol[1])


@lru_cache(maxsize=None)
def rock2_recurrence(k: int) -> np.ndarray:
    """Recurrence coefficients of degree index ``k`` (``m = MS[k]``, ``s = m + 2`` stages)."""
    sigma = FP1[k]
    if MS[k] == 1:   # P_1 = 1 + mu z, fixed by R'(0) = 1 alone
        return np.array([1 - 2 * sigma])
    ell, eps = _interval(k)
    return _recurrence(MS[k], sigma, sigma * (sigma + FP2[k]), ell, eps)


def _R(k: int, z: np.ndarray) -> np.ndarray:
    recf, sigma = rock2_recurrence(k), FP1[k]
    tau = sigma * (sigma + FP2[k])
    p2, p1 = np.ones_like(z), 1 + recf[0] * z
    for i in range(1, len(recf), 2):
        mu, ka = recf[i], recf[i + 1]
        p2, p1 = p1, mu * z * p1 + (1 + ka) * p1 - ka * p2
    return (1 + 2 * sigma * z + tau * z * z) * p1


@lru_cache(maxsize=None)
def rock2_stability_length(k: int) -> float:
    """Real stability interval ``[-beta, 0]`` of degree index ``k`` (sampled |R| <= 1)."""
    s = MS[k] + 2
    z = -np.linspace(0.0, 1.5 * s * s, 15 * s * s + 1001)   # spacing < 0.1, extrema ~4 apart
    bad = np.flatnonzero(np.abs(_R(k, z)) > 1 + 1e-12)
    if not len(bad):
        return float(-z[-1])
    lo, hi = -z[bad[0] - 1], -z[bad[0]]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(_R(k, np.array([-mid]))[0]) <= 1 + 1e-12 else (lo, mid)
    return float(lo)


class ROCK2(Stepper):
    """ROCK2, order 2; ``stages`` fixed (the smallest tabulated ``s >= stages``) or automatic."""

    name, order, error_order = "rock2", 2, 1
    OPTIONS = frozenset({"stages", "spectral_radius", "rho_every"})

    def __init__(self, system, stats=None, stages: int | None = None, spectral_radius=None,
                 rho_every: int = 25) -> None:
        super().__init__(system, stats)
        if stages is not None:
            if not (isinstance(stages, (int, np.integer)) and 3 <= stages <= MS[-1] + 2):
                raise InputError("stages", stages, f"must be an integer in 3..{MS[-1] + 2} or None")
            self.fixed = int(np.searchsorted(np.array(MS) + 2, stages))
        else:
            self.fixed = None
        self.rho_user, self.rho_every = spectral_radius, int(rho_every)
        self._rho, self._rho_age = None, 0
        self.stages = MS[self.fixed] + 2 if self.fixed is not None else 3

    def _degree(self, t, x, f0, h) -> int:
        if self.fixed is not None:
            return self.fixed
        if callable(self.rho_user):
            rho = float(self.rho_user(t, x))
        elif self.rho_user is not None:
            rho = float(self.rho_user)
        else:
            if self._rho is None or self._rho_age >= self.rho_every:
                self._rho = 1.2 * spectral_radius(self.f, t, x, f0)
                self._rho_age = 0
            rho = self._rho
        for k in range(len(MS)):
            if rock2_stability_length(k) >= h * rho:
                return k
        return len(MS) - 1

    def accept(self, att):
        super().accept(att)
        self._rho_age += 1

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        k = self._degree(t, x, f0, h)
        self.stages = MS[k] + 2
        recf, sigma, fp2 = rock2_recurrence(k), FP1[k], FP2[k]
        tj = t + h * recf[0]
        g2, g1 = x, x + h * recf[0] * f0
        c2, c1 = t, tj
        for i in range(1, len(recf), 2):
            mu, ka = recf[i], recf[i + 1]
            g2, g1 = g1, h * mu * self.f(c1, g1) + (1 + ka) * g1 - ka * g2
            c2, c1 = c1, h * mu + (1 + ka) * c1 - ka * c2
        fa = self.f(c1, g1)
        g_s1 = g1 + h * sigma * fa
        fb = self.f(c1 + h * sigma, g_s1)
        corr = h * fp2 * (fb - fa)
        x1 = g_s1 + h * sigma * fb + corr
        return Attempt(t, x, h, x1, corr, f0)
