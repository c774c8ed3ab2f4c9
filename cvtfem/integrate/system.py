"""The right-hand-side protocol (spec §1, §11.1): second-order structure, Jacobian, events.

The state is ``x = [u (n2), v (n2), z (n1)]`` with ``F = [v, F_v, F_z]`` (spec eq. (2.4)),
so ``len(x) = 2*n2 + n1``. A plain ``f(t, y)`` is the special case ``n2 = 0``. Implicit
methods use the structure to eliminate ``u`` from their linear systems (spec (2.16)-(2.17)).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError

__all__ = ["OdeSystem", "StiffSplit", "as_system", "events_from_callables"]


@dataclass(frozen=True)
class StiffSplit:
    """``x' = f_E(t, x) + f_I(t, x)`` with a stiff part ``f_I`` the model solves itself.

    ``explicit(t, x)`` is ``f_E``; ``solve(t, x, h)`` returns ``(x_new, iterations)``: backward Euler of
    ``x' = f_I(t, x)`` over ``h`` from ``x`` (``x_new = x + h f_I(t, x_new)``, each iteration one sparse LU);
    ``hold(x, d)`` (optional) the rate at ``x`` of the stiff part's forces held constant: ``d``'s velocity rows (the
    forces' accelerations) and the work rows at the power those forces deliver at ``x``.  ``rate(x)`` (optional) the
    stiff part with the positions of ``x`` frozen, for multirate-rk4: an object with ``advance(v, a, eta,
    coefficients)`` (``u(eta)`` of ``u' = a + f_I(u)`` from the velocities ``v`` by the given Chebyshev stages) and
    ``bound(z, iterations)`` (a spectral radius of ``f_I``'s velocity Jacobian, at least, and the power iterate).
    ``variants`` (optional) other splits of the same system by name, each as such a tuple ``(explicit, solve[, hold,
    None, rate])`` (A5: ``"all"``, all friction in the stiff part); :meth:`variant` picks one.
    """

    explicit: Callable[[float, np.ndarray], np.ndarray]
    solve: Callable[[float, np.ndarray, float], tuple]
    hold: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
    variants: dict | None = None
    rate: Callable[[np.ndarray], object] | None = None

    def variant(self, name: str | None) -> "StiffSplit":
        """This split (``name`` None) or its variant ``name``."""
        if name is None:
            return self
        if name not in (self.variants or {}):
            raise InputError("friction", name, f"must be one of the split's variants {sorted(self.variants or {})}")
        return StiffSplit(*self.variants[name])


@dataclass(frozen=True)
class OdeSystem:
    """An ODE ``x' = F(t, x, phi)`` with optional structure, Jacobian and events.

    Parameters
    ----------
    fun : callable ``fun(t, x) -> (n,)``
        Right-hand side with the discrete state ``phi`` frozen (the model keeps ``phi``).
    n : int
        State length ``2*n2 + n1``.
    n2 : int
        Number of second-order pairs: ``x[:n2]`` are coordinates ``u``, ``x[n2:2*n2]`` their
        velocities ``v``, and the RHS must satisfy ``F[:n2] = v``.
    jac : callable ``jac(t, x) -> (n, n)`` (dense or sparse) or None
        Analytic Jacobian ``dF/dx``.
    jac_sparsity : sparse or array (n, n) or None
        Structural non-zeros of ``dF/dx`` (union over discrete states, spec §11.3).
    events : callable ``events(t, x) -> (m,)`` or None
        Event indicators ``e_k(t, x)`` (spec eq. (2.6)).
    event_direction : (m,) int
        +1 fires on - to +, -1 on + to -, 0 on both.
    event_terminal : (m,) bool
        Stop the integration when indicator ``k`` fires.
    switch : callable ``switch(t, x, fired) -> x_new or None``
        The discrete-state automaton: called once per event with the boolean mask of all
        indicators firing together (simultaneous events); may return a new state (impacts).
    split : :class:`StiffSplit` or None
        The RHS split into an explicit and a stiff part (the splitting methods of :mod:`cvtfem.integrate.imex`);
        :func:`as_system` also takes it as a tuple of its fields (what a model's ``stiff_split`` gives).
    """

    fun: Callable[[float, np.ndarray], np.ndarray]
    n: int
    n2: int = 0
    jac: Callable | None = None
    jac_sparsity: sp.csr_matrix | None = None
    events: Callable[[float, np.ndarray], np.ndarray] | None = None
    event_direction: np.ndarray | None = None
    event_terminal: np.ndarray | None = None
    switch: Callable | None = None
    split: StiffSplit | None = None

    @property
    def n1(self) -> int:
        """Number of first-order states ``z``."""
        return self.n - 2 * self.n2

    @property
    def n_events(self) -> int:
        return 0 if self.event_direction is None else len(self.event_direction)


def events_from_callables(events) -> tuple[Callable, np.ndarray, np.ndarray]:
    """Turn ``solve_ivp``-style event callables into one vector indicator function."""
    events = list(events) if isinstance(events, (list, tuple)) else [events]
    for k, ev in enumerate(events):
        if not callable(ev):
            raise InputError(f"events[{k}]", ev, "must be callable as e(t, y) -> float")
    direction = np.array([float(getattr(ev, "direction", 0.0)) for ev in events])
    terminal = np.array([bool(getattr(ev, "terminal", False)) for ev in events])

    def indicators(t, x):
        return np.array([float(ev(t, x)) for ev in events])

    return indicators, np.sign(direction).astype(int), terminal


def as_system(fun, y0: np.ndarray, *, n2: int = 0, jac=None, jac_sparsity=None, events=None,
              switch=None, split=None) -> OdeSystem:
    """Build an :class:`OdeSystem` from ``solve``'s arguments, validating them.

    ``fun`` may already be an :class:`OdeSystem` (then the other arguments must be absent) or
    an object with ``rhs`` and ``n2`` attributes (a model, spec §11.1); ``events`` may be an
    ``(indicators, direction, terminal)`` tuple, one callable or a list of callables.
    """
    if isinstance(fun, OdeSystem):
        if fun.n != len(y0):
            raise InputError("y0", f"length {len(y0)}", f"must have the system length {fun.n}")
        return fun
    if hasattr(fun, "rhs") and hasattr(fun, "n2"):
        model = fun
        return as_system(model.rhs, y0, n2=model.n2, jac=getattr(model, "jac", None),
                         jac_sparsity=getattr(model, "jac_sparsity", None),
                         events=_model_events(model), switch=getattr(model, "switch", None),
                         split=getattr(model, "stiff_split", None))
    if not callable(fun):
        raise InputError("fun", fun, "must be callable as fun(t, y) -> array")
    n = len(y0)
    if not (isinstance(n2, (int, np.integer)) and 0 <= 2 * n2 <= n):
        raise InputError("n2", n2, f"must be an integer with 0 <= 2*n2 <= len(y0) = {n}")
    if jac is not None and not callable(jac):
        const = sp.csr_matrix(jac) if sp.issparse(jac) else np.asarray(jac, dtype=float)
        if const.shape != (n, n):
            raise InputError("jac", f"shape {const.shape}", f"must be ({n}, {n})")
        jac = lambda t, x, _j=const: _j  # noqa: E731 - constant Jacobian
    if jac_sparsity is not None:
        jac_sparsity = sp.csr_matrix(jac_sparsity, dtype=bool)
        if jac_sparsity.shape != (n, n):
            raise InputError("jac_sparsity", f"shape {jac_sparsity.shape}", f"must be ({n}, {n})")
    direction = terminal = None
    if events is not None:
        if isinstance(events, tuple) and len(events) == 3 and not callable(events[1]):
            events, direction, terminal = events
            direction = np.asarray(direction, dtype=int)
            terminal = np.asarray(terminal, dtype=bool)
        else:
            events, direction, terminal = events_from_callables(events)
    if switch is not None and not callable(switch):
        raise InputError("switch", switch, "must be callable as switch(t, x, fired) -> x or None")
    if isinstance(split, tuple) and not isinstance(split, StiffSplit) and len(split) in (2, 3, 4):
        split = StiffSplit(*split)                       # a model's (explicit, solve[, hold[, variants]])
    if split is not None and not (isinstance(split, StiffSplit) and callable(split.explicit) and callable(split.solve)):
        raise InputError("split", split, "must be a StiffSplit(explicit, solve, hold=None, variants=None), such a "
                                         "tuple, or None")
    return OdeSystem(fun=fun, n=n, n2=int(n2), jac=jac, jac_sparsity=jac_sparsity, events=events,
                     event_direction=direction, event_terminal=terminal, switch=switch, split=split)


def _model_events(model):
    if getattr(model, "events", None) is None:
        return None
    m = len(model.event_direction)
    terminal = getattr(model, "event_terminal", None)
    return (model.events, model.event_direction, np.zeros(m, bool) if terminal is None else terminal)
