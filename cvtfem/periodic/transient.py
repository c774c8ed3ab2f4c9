"""Comparison path: the same network integrated in time to periodic steady state.

The integrator is the module variable :data:`integrate` (``solve_ivp``
signature); swapping in ``cvtfem.integrate.solve`` is one line.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from cvtfem.elements.torsional import TorsionalNetwork
from cvtfem.errors import InputError, NumericalError

#: Time integrator with the ``scipy.integrate.solve_ivp`` signature.
integrate = solve_ivp


@dataclass(frozen=True)
class SteadyState:
    """Periodic steady state found by time integration.

    Attributes
    ----------
    omega : float, rad/s
    periods : int
        Periods integrated until the state repeated within ``tol`` (the last,
        sampled period included).
    wall : float, s
        Wall time of the whole run.
    nfev : int
        Right-hand-side evaluations.
    t : ndarray (M,) s
        Sample times over the last period (from its start).
    x, v : ndarray (S, M)
        Displacements (m) and velocities (m/s) over the last period.
    link_forces : ndarray (E, M), N
    change : float
        Relative change of the state over the last period.
    """

    omega: float
    periods: int
    wall: float
    nfev: int
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    link_forces: np.ndarray
    change: float


def steady_state(net: TorsionalNetwork, omega: float, method: str = "DOP853", rtol: float = 1e-10,
                 atol: float | np.ndarray = 1e-14, tol: float = 1e-8, max_periods: int = 2000,
                 samples: int = 1024, y0: np.ndarray | None = None) -> SteadyState:
    """Integrate period by period from ``y0`` (default rest) until ``y(kT)`` repeats.

    Parameters
    ----------
    net : TorsionalNetwork
    omega : float, rad/s
        Base frequency (period ``2 pi / omega``).
    method, rtol, atol :
        Passed to :data:`integrate`.
    tol : float
        Stop when ``max|y(kT) - y((k-1)T)| <= tol * max|y(kT)|`` separately for
        displacements and velocities.
    max_periods : int
        Budget; :class:`NumericalError` past it.
    samples : int
        Samples of the last period (equally spaced, end excluded).
    """
    if not omega > 0:
        raise InputError("omega", omega, "must be positive (rad/s)")
    S = net.n_nodes
    T = 2 * np.pi / omega
    rhs = net.first_order_rhs(omega)
    y = np.zeros(2 * S) if y0 is None else np.asarray(y0, float).copy()
    start = time.perf_counter()
    nfev = 0
    change = np.inf
    for k in range(1, max_periods + 1):
        sol = integrate(rhs, (0.0, T), y, method=method, rtol=rtol, atol=atol)
        if sol.status != 0:
            raise NumericalError(f"time integration failed: {sol.message}", t=(k - 1) * T + sol.t[-1],
                                 component=f"steady_state({method})")
        nfev += sol.nfev
        y_new = sol.y[:, -1]
        change = max(np.abs(y_new[:S] - y[:S]).max() / max(np.abs(y_new[:S]).max(), 1e-300),
                     np.abs(y_new[S:] - y[S:]).max() / max(np.abs(y_new[S:]).max(), 1e-300))
        y = y_new
        if change <= tol:
            break
    else:
        raise NumericalError(f"no periodic steady state within {max_periods} periods (last relative change "
                             f"{change:.2e} > {tol:.1e}); the response may be non-periodic",
                             component="steady_state")
    t = np.arange(samples) * T / samples
    sol = integrate(rhs, (0.0, T), y, method=method, rtol=rtol, atol=atol, t_eval=t)
    nfev += sol.nfev
    wall = time.perf_counter() - start
    D = net.incidence()
    x, v = sol.y[:S], sol.y[S:]
    return SteadyState(omega, k + 1, wall, nfev, t, x, v, net.forces(D @ x, D @ v), change)
