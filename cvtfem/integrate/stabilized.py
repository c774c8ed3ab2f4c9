"""Stabilized explicit Runge-Kutta-Chebyshev method RKC (spec §11.6).

Second-order RKC of Sommeijer, Shampine & Verwer (J. Comput. Appl. Math. 88, 1997), damping
``eps = 2/13``: ``w0 = 1 + eps/s^2``, ``w1 = T_s'(w0)/T_s''(w0)``, ``b_j = T_j''/T_j'^2``
(``b_0 = b_1 = b_2``), ``a_j = 1 - b_j T_j(w0)``; stability polynomial
``R_s(z) = a_s + b_s T_s(w0 + w1 z)``, real stability length ``beta(s) = (1 + w0)/w1``
(about ``0.653 s^2``). Stages ``s`` fixed (option ``stages``) or chosen each step from a
spectral-radius estimate (nonlinear power iteration) so that ``h rho <= beta(s)``.
Error estimate (SSV97): ``(12 (x0 - x1) + 6 h (F0 + F1)) / 15``; adaptive runs control it against
``rtol_int = 0.5 rtol^(3/2)`` (option ``proportional``, default on), so the global
error of this order-2 method stays proportional to rtol
(:func:`cvtfem.integrate.base.proportional_ratio`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, StepFailure, Stepper, proportional_ratio

__all__ = ["RKC", "rkc_coefficients", "rkc_stability_length", "spectral_radius", "rkc1_coefficients",
           "RKC1_DAMPING", "RKC1_BETA_PER_S2"]

EPS_DAMP = 2 / 13
MAX_STAGES = 1000
RHO_SAFETY = 1.2


def _chebyshev(s: int, w0: float):
    """``T_j, T_j', T_j''`` at ``w0`` for ``j = 0..s``."""
    T, dT, ddT = np.zeros(s + 1), np.zeros(s + 1), np.zeros(s + 1)
    T[0], T[1], dT[1] = 1.0, w0, 1.0
    for j in range(2, s + 1):
        T[j] = 2 * w0 * T[j - 1] - T[j - 2]
        dT[j] = 2 * T[j - 1] + 2 * w0 * dT[j - 1] - dT[j - 2]
        ddT[j] = 4 * dT[j - 1] + 2 * w0 * ddT[j - 1] - ddT[j - 2]
    return T, dT, ddT


def rkc_coefficients(s: int):
    """Stage coefficients ``(mu, nu, mu_t, gamma_t, c)`` of s-stage RKC (index 1..s used)."""
    if s < 2:
        raise InputError("stages", s, "must be at least 2 for RKC")
    w0 = 1 + EPS_DAMP / s ** 2
    T, dT, ddT = _chebyshev(s, w0)
    w1 = dT[s] / ddT[s]
    b = np.empty(s + 1)
    b[2:] = ddT[2:] / dT[2:] ** 2
    b[0] = b[1] = b[2]
    a = 1 - b * T
    mu, nu, mu_t, gam_t = (np.zeros(s + 1) for _ in range(4))
    mu_t[1] = b[1] * w1
    for j in range(2, s + 1):
        mu[j] = 2 * b[j] * w0 / b[j - 1]
        nu[j] = -b[j] / b[j - 2]
        mu_t[j] = 2 * b[j] * w1 / b[j - 1]
        gam_t[j] = -a[j - 1] * mu_t[j]
    c = np.zeros(s + 1)
    c[2:] = dT[s] * ddT[2:] / (ddT[s] * dT[2:])
    c[1] = c[2] / dT[2]
    return mu, nu, mu_t, gam_t, c


#: The damped first-order Chebyshev method (Hundsdorfer & Verwer, 2003, V.1): damping ``eps`` (``|R| <= 1 / T_s(w0)``
#: on the plateau: 0.27-0.29 at ``eps = 2``, where RKC's usual 0.05 leaves 0.95) and a lower bound of its real stability
#: length over ``s^2`` at that damping (``(1 + w0) / w1 >= 0.96 s^2``; about ``2 s^2`` for small ``eps``).
RKC1_DAMPING, RKC1_BETA_PER_S2 = 2.0, 0.96


@lru_cache(maxsize=None)
def rkc1_coefficients(s: int) -> tuple:
    """``(mu, nu, mu_t)`` of the s-stage damped first-order Chebyshev method ``Y_1 = Y_0 + mu_t[1] h F(Y_0)``,
    ``Y_j = mu[j] Y_{j-1} + nu[j] Y_{j-2} + mu_t[j] h F(Y_{j-1})`` (j = 2..s), ``R_s(z) = T_s(w0 + w1 z) / T_s(w0)``
    with ``w0 = 1 + eps / s^2``, ``w1 = T_s(w0) / T_s'(w0)``."""
    if s < 1:
        raise InputError("stages", s, "must be at least 1")
    w0 = 1 + RKC1_DAMPING / s ** 2
    T, dT, _ = _chebyshev(s, w0)
    w1 = T[s] / dT[s]
    mu, nu, mu_t = np.zeros(s + 1), np.zeros(s + 1), np.zeros(s + 1)
    mu_t[1] = w1 / w0
    mu[2:] = 2 * w0 * T[1:s] / T[2:]
    nu[2:] = -T[:s - 1] / T[2:]
    mu_t[2:] = 2 * w1 * T[1:s] / T[2:]
    return mu, nu, mu_t


@lru_cache(maxsize=None)
def rkc_stability_length(s: int) -> float:
    """Real stability interval ``[-beta, 0]`` of s-stage RKC: ``beta = (1 + w0)/w1``."""
    w0 = 1 + EPS_DAMP / s ** 2
    _, dT, ddT = _chebyshev(s, w0)
    return (1 + w0) * ddT[s] / dT[s]


def spectral_radius(f, t, x, f0, v0=None, max_iter: int = 50, rtol: float = 0.01) -> float:
    """Nonlinear power iteration for ``rho(dF/dx)`` at ``(t, x)`` (RKC's ``rkcrho``), 1/s."""
    if v0 is None:   # F(x) plus a fixed rough vector, so that high modes are present
        rough = np.random.default_rng(12345).standard_normal(x.shape)
        nf = np.linalg.norm(f0)
        rough /= np.linalg.norm(rough)
        v = f0 / nf + rough if nf > 0 else rough
        if np.linalg.norm(v) < 0.5:   # F and the rough vector nearly cancel (e.g. one equation)
            v = rough
    else:
        v = np.array(v0, dtype=float)
    xnorm = np.linalg.norm(x)
    dx = np.sqrt(np.finfo(float).eps) * max(xnorm, 1.0)
    v *= dx / np.linalg.norm(v)
    rho = 0.0
    for _ in range(max_iter):
        dfv = f(t, x + v) - f0
        nrm = np.linalg.norm(dfv)
        rho_new = nrm / dx
        if nrm == 0.0:
            return rho_new
        v = dfv * (dx / nrm)
        if abs(rho_new - rho) <= rtol * rho_new:
            return rho_new
        rho = rho_new
    return rho


class SpectralRadiusTracker:
    """Spectral-radius bookkeeping shared by the stabilized explicit methods.

    ``rho_user`` is a number, a callable ``rho(t, x)`` or None (power iteration,
    refreshed every ``rho_every`` accepted steps, times :data:`RHO_SAFETY`).
    """

    substep_dense = True   # events on a step of the method itself (its stage count may change there)

    def _init_rho(self, spectral_radius_option, rho_every) -> None:
        self.rho_user, self.rho_every = spectral_radius_option, int(rho_every)
        self._rho, self._rho_age = None, 0

    def _current_rho(self, t, x, f0) -> float:
        if callable(self.rho_user):
            return float(self.rho_user(t, x))
        if self.rho_user is not None:
            return float(self.rho_user)
        if self._rho is None or self._rho_age >= self.rho_every:
            rho = RHO_SAFETY * spectral_radius(self.f, t, x, f0)
            if not np.isfinite(rho):   # the state or F overflowed: a failed attempt, not a crash
                raise StepFailure(f"spectral-radius estimate is {rho} at t = {t:.6g} s")
            self._rho, self._rho_age = rho, 0
        return self._rho

    def accept(self, att):
        super().accept(att)
        self._rho_age += 1

    def _step_cap(self, length: float) -> float:
        """``length`` (a real stability length) over the last spectral-radius estimate, s (inf before the
        first estimate or with a callable ``spectral_radius``): longer steps leave the stability region of
        every available degree and would only be rejected by the error estimate, again and again."""
        rho = self._rho if self.rho_user is None else None if callable(self.rho_user) else float(self.rho_user)
        return length / rho if rho else np.inf


class RKC(SpectralRadiusTracker, Stepper):
    """Runge-Kutta-Chebyshev, order 2; ``stages`` fixed, or None for automatic selection."""

    name, order, error_order = "rkc", 2, 2
    OPTIONS = frozenset({"stages", "spectral_radius", "rho_every", "proportional"})

    def __init__(self, system, stats=None, stages: int | None = None, spectral_radius=None,
                 rho_every: int = 25, proportional: bool = True) -> None:
        super().__init__(system, stats)
        if not isinstance(proportional, (bool, np.bool_)):
            raise InputError("proportional", proportional, "must be true or false")
        self.proportional = bool(proportional)
        if stages is not None and not (isinstance(stages, (int, np.integer)) and 2 <= stages <= MAX_STAGES):
            raise InputError("stages", stages, f"must be an integer in 2..{MAX_STAGES} or None (automatic)")
        if spectral_radius is not None and not (callable(spectral_radius) or spectral_radius > 0):
            raise InputError("spectral_radius", spectral_radius, "must be a positive number, a callable or None")
        self.fixed_stages = stages
        self.stages = stages or 2
        self._init_rho(spectral_radius, rho_every)
        self._coef: dict[int, tuple] = {}

    def tolerance_ratio(self, rtol: float) -> float:
        """Global error proportional to rtol unless ``proportional=False`` (module docstring)."""
        return proportional_ratio(rtol, 2) if self.proportional else 1.0

    def _stage_count(self, t, x, f0, h) -> int:
        if self.fixed_stages:
            return self.fixed_stages
        rho = self._current_rho(t, x, f0)
        s = max(2, int(np.sqrt(h * rho / 0.653)))
        while rkc_stability_length(s) < h * rho and s < MAX_STAGES:
            s += 1
        return s

    def max_step(self) -> float:
        """The largest (or the fixed) stage count's stability length over the spectral radius, s."""
        return self._step_cap(rkc_stability_length(self.fixed_stages or MAX_STAGES))

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        s = self.stages = self._stage_count(t, x, f0, h)
        if s not in self._coef:
            self._coef[s] = rkc_coefficients(s)
        mu, nu, mu_t, gam_t, c = self._coef[s]
        hf0 = h * f0
        y_prev, y = x, x + mu_t[1] * hf0
        for j in range(2, s + 1):
            y_new = ((1 - mu[j] - nu[j]) * x + mu[j] * y + nu[j] * y_prev
                     + mu_t[j] * h * self.f(t + c[j - 1] * h, y) + gam_t[j] * hf0)
            y_prev, y = y, y_new
        err = None
        f1 = None
        if self.need_error:
            f1 = self.f(t + h, y)
            err = (12 * (x - y) + 6 * h * (f0 + f1)) / 15
        return Attempt(t, x, h, y, err, f0, f1)
