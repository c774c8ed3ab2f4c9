"""Linearly implicit W-methods SW24-d and W1-d (spec §4.1, eqs. (2.12)-(2.14)).

``W = I - h d A`` with ``A`` any approximation of ``dF/dx`` (here the Jacobian from the
provider, refreshed every ``jac_every`` steps); with second-order structure ``W`` is solved
through the reduced matrix of :mod:`cvtfem.integrate.linsolve`. The LU is reused while ``A``
and ``h`` are unchanged (the controller keeps ``h`` unless it wants >= 1.3x).
W1-d is order 1 for any ``d`` and ``A``; its extrapolation (harmonic sequence) is
``w1-extrapolation`` (Deuflhard-Bornemann §6.4.2).

Defaults damp stiff components (``A = J``, scalar test equation, ``z = h lambda``):
SW24-d has ``R(z) = [1 + (1 - 2d) z + (d^2 - 2d + 1/2) z^2] / (1 - d z)^2`` (the 2-stage Rosenbrock
function), ``R(-inf) = 1 - 2/d + 1/(2 d^2)``: -1 at the source's d = 1/2 (no damping, like the
trapezoidal rule), -1/2 at d = 1, 0 at ``d = 1 - 1/sqrt(2)`` (L-stable and A-stable, as d >= 1/4;
the default). W1-d has ``R = 1 + z/(1 - d z)``, ``R(-inf) = 1 - 1/d``: 0 at the default d = 1 (linearly
implicit Euler), and every extrapolated W1-1 entry then also vanishes at ``-inf``.

SW24 is order 2: adaptive runs control its local error against ``rtol_int = rtol^(3/2)`` (option
``proportional``, default on; :func:`cvtfem.integrate.base.proportional_ratio`), so its global error stays
proportional to rtol (docs/integrators.md, "Tolerance proportionality").
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper, proportional_ratio
from cvtfem.integrate.extrapolation import Extrapolator
from cvtfem.integrate.jacobian import JacobianProvider
from cvtfem.integrate.linsolve import LU, reduced_matrix

__all__ = ["SW24", "W1", "W1Extrapolation"]

#: Relative difference of two step sizes below which they share one LU of ``I - h d A``: the rounding of
#: ``t_end - t`` at a fixed step's end.  Using the other step's matrix is the W-method with ``A`` scaled by
#: ``1 +- H_ROUNDOFF``: a W-method keeps its order for any ``A``.
H_ROUNDOFF = 1e-9


class _WBase(Stepper):
    """Shared parts: ``d``, the matrix ``A`` and cached LUs of ``I - h d A`` per step size."""

    OPTIONS = frozenset({"d", "jac_every"})
    STEP_QUANTUM = 1.3

    default_d = 1.0

    def __init__(self, system, stats=None, d: float | None = None, jac_every: int = 1, **kw) -> None:
        super().__init__(system, stats, **kw)
        d = self.default_d if d is None else d
        if not 0.0 < d <= 1.0:
            raise InputError("d", d, "must lie in (0, 1]")
        if not (isinstance(jac_every, (int, np.integer)) and jac_every >= 1):
            raise InputError("jac_every", jac_every, "must be a positive integer (steps per Jacobian)")
        self.d, self.jac_every = float(d), int(jac_every)
        self.jac = JacobianProvider(self)
        self.A = None
        self._age = 0
        self._lus: dict[float, LU] = {}

    def _refresh(self, t, x) -> None:
        if self.A is None or self._age >= self.jac_every:
            self.A = self.jac(t, x)
            self._age = 0
            self._lus = {}

    def accept(self, att: Attempt) -> None:
        super().accept(att)
        self._age += 1

    def lu(self, h: float) -> LU:
        """LU of ``W = I - h d A`` (reduced), cached while ``A`` is unchanged; a step within round-off (relative
        ``H_ROUNDOFF``) of a cached one reuses its LU (the last step of a fixed-step run, ``t_end - t``)."""
        lu = self._lus.get(h)
        if lu is None:
            lu = next((v for k, v in self._lus.items() if abs(k - h) <= H_ROUNDOFF * h), None)
        if lu is None:
            n2, g = self.system.n2, h * self.d
            if len(self._lus) > 8:
                self._lus = {}
            lu = self._lus[h] = LU(self.stats, reduced_matrix(self.A, n2, g), n2, g,
                                         self.A[n2:, :n2])
        return lu


class SW24(_WBase):
    """Steihaug-Wolfbrandt SW24-d: order 2 for any ``A``; 2 more stages estimate the error."""

    name, order, error_order, stages = "sw24", 2, 2, 2
    default_d = 1.0 - 1.0 / np.sqrt(2.0)   # L-stable (see module docstring)
    OPTIONS = _WBase.OPTIONS | {"proportional"}

    def __init__(self, system, stats=None, d: float | None = None, jac_every: int = 1,
                 proportional: bool = True) -> None:
        super().__init__(system, stats, d=d, jac_every=jac_every)
        if not isinstance(proportional, (bool, np.bool_)):
            raise InputError("proportional", proportional, "must be true or false")
        self.proportional = bool(proportional)

    def tolerance_ratio(self, rtol: float) -> float:
        """Global error proportional to rtol unless ``proportional=False`` (module docstring)."""
        return proportional_ratio(rtol, 2, 1.0) if self.proportional else 1.0

    def attempt(self, t, x, h):
        self._refresh(t, x)
        W = self.lu(h)
        f0 = self.f0(t, x)
        hd = h * self.d
        k1 = W.solve_full(f0)
        k2 = W.solve_full(self.f(t + 2 * h / 3, x + (2 * h / 3) * k1) - (4 / 3) * hd * (self.A @ k1))
        x1 = x + 0.25 * h * (k1 + 3 * k2)
        err = None
        if self.need_error:
            f1 = self.f(t + h, x1)
            k3 = W.solve_full(f1)
            k4 = W.solve_full(self.f(t + 5 * h / 3, x1 + (2 * h / 3) * k3)
                              + hd * (self.A @ ((2 / 3) * k1 + 6 * k2)))
            err = (h / 8) * (k1 - 5 * k2 + 5 * k3 - k4)
        return Attempt(t, x, h, x1, err, f0)


class W1(_WBase):
    """W1-d: ``x1 = x0 + h k1``, ``W k1 = F(t0, x0)``; order 1, no error estimate."""

    name, order, error_order = "w1", 1, None

    def attempt(self, t, x, h):
        self._refresh(t, x)
        f0 = self.f0(t, x)
        return Attempt(t, x, h, x + h * self.lu(h).solve_full(f0), None, f0)


class W1Extrapolation(_WBase, Extrapolator):
    """W1-d-Xp: W1-d extrapolated with ``stages`` rows (harmonic by default); order p."""

    name, base_order, gamma = "w1-extrapolation", 1, 1
    OPTIONS = _WBase.OPTIONS | Extrapolator.OPTIONS

    def __init__(self, system, stats=None, d: float | None = None, jac_every: int = 1, stages: int = 4,
                 sequence: str = "harmonic") -> None:
        super().__init__(system, stats, d=d, jac_every=jac_every, stages=stages, sequence=sequence)

    def attempt(self, t, x, h):
        self._refresh(t, x)
        return Extrapolator.attempt(self, t, x, h)

    def base(self, t, x, h, n, f0):
        H = h / n
        W = self.lu(H)
        y = x + H * W.solve_full(f0)
        for i in range(1, n):
            y = y + H * W.solve_full(self.f(t + i * H, y))
        return y
