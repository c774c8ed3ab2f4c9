"""Splitting methods for a stiff part the model solves itself (the halves' friction of A5): ``strang-friction``.

The system carries a :class:`~cvtfem.integrate.system.StiffSplit` ``x' = f_E + f_I``: ``f_E`` goes to an explicit
method whose stage count follows the spectral radius of ``f_E`` alone, ``f_I`` to the model's own backward Euler
(for A5 the halves' internal friction with the positions frozen,
:meth:`~cvtfem.machines.chain_halves_cvt.ChainHalvesCVT.friction_solve`).  Schemes (:data:`SCHEMES`):

* ``strang``: ``I(h/2) o E(h) o I(h/2)``; order 1 (backward Euler's half steps; Strang's order 2 needs a
  second-order ``I``), stable for a dissipative ``f_I`` at any step;
* ``frozen``: the forces of one backward-Euler step of ``f_I`` after the explicit impulse ``h f_E(x)`` (velocity
  rows), held constant over the explicit step; their work is booked at the power they deliver along it (the split's
  ``hold``), so the energy balance stays the explicit method's;
* ``frozen-mid``: the same from a half step after half the impulse (the forces of the step's middle);
* ``imex-rk4``: an additive (IMEX) Runge-Kutta method of order 2: RK4's tableau on ``f_E`` and the stiffly accurate
  ESDIRK :data:`IMEX_RK4_IMPLICIT` (the same nodes and weights; ``R(inf) = 0``) on ``f_I``, each implicit stage one
  backward-Euler solve of the split at the stage's positions (three per step) whose rate is booked with the power of
  its forces at the stage's velocities (the split's ``hold``: ``f_I`` of the stage state, not the solve's own
  kinetic-energy balance over the stage), ``f_I`` at the step's start as ``F - f_E`` (one RHS call, shared with the
  dense output of the step before); the option ``explicit`` is not used;
* ``imex-rk4-2``: the same with an explicit third stage of the ESDIRK (``f_I = F - f_E`` there: one RHS call instead
  of a solve), two solves per step;
* ``multirate-rk4``: no solve.  RK4 on the averaged rate ``f_eta`` of the multirate Runge-Kutta-Chebyshev idea
  (Abdulle, Grote & Rosilho de Souza, Math. Comp. 2022): at each stage ``f_E`` plus the mean acceleration of the
  stiff part over ``eta = 2/3 h``, found by integrating ``u' = a_E + f_I(u)`` (positions frozen, ``a_E`` the stage's
  explicit accelerations held) with the strongly damped first-order Chebyshev method
  (:func:`~cvtfem.integrate.stabilized.rkc1_coefficients`), as many stages as the split's ``rate`` bound asks (the
  cheap stiff part is evaluated many times, ``f_E`` four times a step); that mean force's work booked by ``hold``.
  Order one; the stiff part's rate at the middle node is shared by the two middle stages, the end node's carried to
  the next step's first.  The only scheme with an error estimate (adaptive runs): the embedded third-order solution
  with RK4's weights on the first three stages and ``1/6`` on the averaged rate at the step's end (``k5``, first
  same as last: it is the next step's first stage while ``h`` stays), taken on ``f_E`` alone:
  ``err = h/6 (f_E(y4) - f_E(x1))``.  It measures RK4's truncation on the frictionless dynamics; the averaging's
  error is ``O(eta)`` and the averaged friction modes sit near ``h lambda = -1.5`` at every step by construction, so
  an estimate of them would shrink ``h`` without gain.  The option ``max_step`` (s) caps the steps (the study's step,
  docs/accuracy-cost.md).

The other schemes take fixed steps only.  The friction solves count as ``nnewton`` (iterations) and ``nlu`` (one
sparse LU each), timed in ``t_lu``; multirate-rk4 counts its Chebyshev stages as ``nnewton``.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper
from cvtfem.integrate.stabilized import RKC1_BETA_PER_S2, rkc1_coefficients
from cvtfem.integrate.system import OdeSystem

__all__ = ["StrangFriction"]

#: The explicit methods a split step may use.
EXPLICIT = ("dumka3", "rk4", "rock4", "dopri45")
#: How a step combines the two parts (module docstring).
SCHEMES = ("strang", "frozen", "frozen-mid", "imex-rk4", "imex-rk4-2", "multirate-rk4")
#: The implicit tableaus of the IMEX schemes (rows 2-4; the first stage explicit): nodes ``(0, 1/2, 1/2, 1)`` and
#: weights ``(1, 2, 2, 1)/6`` as RK4's (so each pair has order 2), the last row the weights (stiffly accurate), the
#: middle rows chosen for ``R(inf) = 0`` with ``|R| <= 1`` on the left half-plane; ``imex-rk4-2`` has an explicit
#: third stage (``a_33 = 0``: ``f_I`` evaluated there, two solves per step instead of three).
IMEX_RK4_IMPLICIT = {"imex-rk4": ((0.0, 0.5), (0.25, -0.25, 0.5), (1 / 6, 1 / 3, 1 / 3, 1 / 6)),
                     "imex-rk4-2": ((0.1, 0.4), (0.1, 0.4, 0.0), (1 / 6, 1 / 3, 1 / 3, 1 / 6))}
_RK4_EXPLICIT = ((0.5,), (0.0, 0.5), (0.0, 0.0, 1.0))
#: multirate-rk4: the inner span over the step (the inner method leaves a stiff mode at ``|R| <= 0.29``, so its mean
#: rate lies in ``[-1.29 / eta, -0.71 / eta]``: at ``eta = 2/3 h`` RK4 sees it at ``h lambda`` in ``[-1.9, -1.1]`` and
#: damps it to 0.28-0.34 a step); power iterations per step for the stiff part's spectral radius (warm started from
#: the step before; more at the first step) and the margin on it.
ETA, POWER_ITERATIONS, FIRST_POWER_ITERATIONS, SAFETY = 2 / 3, 4, 30, 1.2
#: multirate-rk4 run adaptive keeps ``h`` unless the controller asks 1.2x or more (the last stage stays the next
#: step's first, whose averaging span follows ``h``).
MULTIRATE_STEP_QUANTUM = 1.2


class StrangFriction(Stepper):
    """``explicit`` (a registered explicit method, default DUMKA3, with its options ``stages``, ``spectral_radius``,
    ``rho_every``) on ``f_E``, the system's own backward Euler on ``f_I``, combined by ``scheme`` (:data:`SCHEMES`);
    ``friction`` names a variant of the system's split (A5: ``"all"``, the pin-sheave friction in ``f_I`` too;
    default the split itself, the halves' friction); ``max_step`` (s): the largest step of an adaptive
    ``multirate-rk4`` run."""

    name, order = "strang-friction", 1
    #: Runs only on a system with a :class:`~cvtfem.integrate.system.StiffSplit` (generic method loops skip it).
    needs_split = True
    OPTIONS = frozenset({"explicit", "scheme", "friction", "max_step", "stages", "spectral_radius", "rho_every"})

    def __init__(self, system: OdeSystem, stats=None, explicit: str = "dumka3", scheme: str = "strang",
                 friction: str | None = None, max_step: float = np.inf, **options) -> None:
        super().__init__(system, stats)
        from cvtfem.integrate.methods import METHODS

        if system.split is None:
            raise InputError("method", self.name, "needs a system with a stiff split (StiffSplit): the A5 chain with "
                                                  "internal friction (variants (e), (zh)) has one")
        if explicit not in EXPLICIT:
            raise InputError("explicit", explicit, f"must be one of {EXPLICIT}")
        cls = METHODS[explicit]
        unknown = set(options) - cls.OPTIONS
        if unknown:
            raise InputError("options", sorted(unknown), f"must be options of {explicit}: {sorted(cls.OPTIONS)}")
        if scheme not in SCHEMES:
            raise InputError("scheme", scheme, f"must be one of {SCHEMES}")
        if isinstance(max_step, bool) or not (isinstance(max_step, (int, float)) and max_step > 0):
            raise InputError("max_step", max_step, "must be a step > 0, s")
        if scheme != "multirate-rk4" and np.isfinite(max_step):
            raise InputError("max_step", max_step, "is taken by scheme=multirate-rk4 alone (the others have fixed "
                                                   "steps)")
        self.scheme, self._frozen, self._power, self._end, self._last = scheme, None, None, None, None
        if scheme == "multirate-rk4":
            self.error_order, self.STEP_QUANTUM, self._h_max = 3, MULTIRATE_STEP_QUANTUM, float(max_step)
        split = self.split = system.split.variant(friction)
        if scheme == "multirate-rk4" and split.rate is None:
            raise InputError("scheme", scheme, "needs the split's `rate` (the stiff part's rate at frozen positions)")
        if scheme != "strang" and split.hold is None:
            raise InputError("scheme", scheme, "needs the split's `hold` (the work rate of the held forces)")
        if scheme == "strang":
            fun = split.explicit
        else:
            def fun(t, x):
                return split.explicit(t, x) + split.hold(x, self._frozen)
        inner = OdeSystem(fun=fun, n=system.n, n2=system.n2)
        self.inner = cls(inner, self.stats, **options)
        self.inner.need_error = False

    def _implicit(self, t, x, h):
        st = self.stats
        with st.timer("t_lu"):
            x1, its = self.split.solve(t, x, h)
        st.add("nnewton", its)
        st.add("nlu", its)
        return x1

    def _imex_rk4(self, t, x, h):
        """One step of ``imex-rk4`` or ``imex-rk4-2`` (module docstring) and ``F`` at its start."""
        split, st, fun = self.split, self.stats, self.system.fun
        F0 = self.f0(t, x)                                   # the dense output's F at the last step's end
        KE = [split.explicit(t, x)]
        KI = [F0 - KE[0]]
        st.add("nfev")
        for aE, aI in zip(_RK4_EXPLICIT, IMEX_RK4_IMPLICIT[self.scheme]):
            ti = t + h * sum(aE)
            pred = x + h * (sum(a * k for a, k in zip(aE, KE)) + sum(a * k for a, k in zip(aI[:-1], KI)))
            if aI[-1] > 0.0:
                hi = h * aI[-1]
                y = self._implicit(ti, pred, hi)
                KE.append(split.explicit(ti, y))
                KI.append(split.hold(y, (y - pred) / hi))    # the stage's friction rate: its power at its v
                st.add("nfev")
            else:                                            # an explicit stage of f_I too
                y = pred
                KE.append(split.explicit(ti, y))
                KI.append(fun(ti, y) - KE[-1])
                st.add("nfev", 2)
        b = IMEX_RK4_IMPLICIT[self.scheme][-1]
        return x + h * sum(bi * (ke + ki) for bi, ke, ki in zip(b, KE, KI)), F0

    def _averaged(self, t, x, h, first=False, reuse=False):
        """The averaged rate ``f_eta(x)`` of ``multirate-rk4``: ``f_E(x)`` plus the split's held rate (:meth:`hold`)
        of the stiff part's mean acceleration over ``eta``, ``(u(eta) - v) / eta - a_E``, where ``u' = a_E + rate(u)``
        from ``u(0) = v`` (the velocities) with the positions frozen (``a_E``: ``f_E(x)``'s velocity rows), by the
        damped first-order Chebyshev method with as many stages as the rate's spectral radius asks.  ``first``: a new
        step (the radius is estimated again); ``reuse``: the rate of the stage before (the same node)."""
        split, st, n2 = self.split, self.stats, self.system.n2
        fe = split.explicit(t, x)
        st.add("nfev")
        if not reuse:
            with st.timer("t_lu"):
                self._rate = split.rate(x)
        if first:
            with st.timer("t_lu"):
                its = POWER_ITERATIONS if self._power is not None else FIRST_POWER_ITERATIONS
                radius, self._power = self._rate.bound(self._power, its)
                self._bound = SAFETY * radius
        rate, eta = self._rate, ETA * h
        s = max(2, int(np.ceil(np.sqrt(eta * self._bound / RKC1_BETA_PER_S2))))
        st.add("nnewton", s)
        a, v = fe[n2:2 * n2], x[n2:2 * n2]
        u = rate.advance(v, a, eta, rkc1_coefficients(s))
        d = np.zeros_like(x)
        d[n2:2 * n2] = (u - v) / eta - a
        self._fe = fe
        return fe + split.hold(x, d)

    def _near_end(self, t, x, h) -> bool:
        """The stiff rate of the last node (:attr:`_end`) serves ``x`` at ``t``: the same time and positions within
        ``h`` times the largest speed (the friction set of the same contacts)."""
        n2, end = self.system.n2, self._end
        near = (end is not None and end[0] == t
                and np.abs(x[:n2] - end[1]).max() <= h * np.abs(x[n2:2 * n2]).max())
        if near:
            self._rate = end[2]
        return near

    def _multirate_rk4(self, t, x, h):
        """One step of ``multirate-rk4``: RK4 on the averaged rate (the middle stages share their stiff rate), and
        with ``need_error`` the error estimate from the averaged rate at the end (kept as the next first stage)."""
        n2, last = self.system.n2, self._last
        if last is not None and last[0] == t and last[1] == h and np.array_equal(last[2], x):
            k1 = last[3]
        else:
            k1 = self._averaged(t, x, h, first=True, reuse=self._near_end(t, x, h))
        self._end = self._last = None
        k2 = self._averaged(t + h / 2, x + h / 2 * k1, h)
        k3 = self._averaged(t + h / 2, x + h / 2 * k2, h, reuse=True)
        y4 = x + h * k3
        k4 = self._averaged(t + h, y4, h)
        fe4, self._end = self._fe, (t + h, y4[:n2], self._rate)
        x1 = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if not self.need_error:
            return x1, None
        k5 = self._averaged(t + h, x1, h, first=True, reuse=self._near_end(t + h, x1, h))
        self._end, self._last = (t + h, x1[:n2], self._rate), (t + h, h, x1, k5)
        return x1, h / 6 * (fe4 - self._fe)

    def max_step(self) -> float:
        return self._h_max if self.scheme == "multirate-rk4" else np.inf

    def attempt(self, t, x, h):
        if self.scheme == "multirate-rk4":
            self.stages = 4
            x1, err = self._multirate_rk4(t, x, h)
            return Attempt(t, x, h, x1, err=err)
        if self.scheme in IMEX_RK4_IMPLICIT:
            y, F0 = self._imex_rk4(t, x, h)
            self.stages = 4
            return Attempt(t, x, h, y, f0=F0)
        if self.scheme != "strang":
            fe = self.split.explicit(t, x)
            self.stats.add("nfev")
            pred, n2 = x.copy(), self.system.n2
            hi = h if self.scheme == "frozen" else 0.5 * h
            pred[n2:] += hi * fe[n2:]                 # positions frozen: the explicit impulse of the step (or half)
            d = (self._implicit(t, pred, hi) - pred) / hi
            self._frozen = d
            self.inner._start = (t, x.copy(), fe + self.split.hold(x, d))    # its F at the start: known
            y = self.inner.attempt(t, x, h).x1
        else:
            y = self._implicit(t, x, 0.5 * h)
            y = self.inner.attempt(t, y, h).x1
            y = self._implicit(t + h, y, 0.5 * h)
        self.stages = self.inner.stages
        self.inner.accept(Attempt(t, y, h, y))
        return Attempt(t, x, h, y)
