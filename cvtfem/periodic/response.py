"""Frequency sweeps of periodic responses with and without backlash, and their summary data.

A sweep walks the frequencies in order, starting Newton at each point from
the previous converged solution (natural continuation; use
:func:`cvtfem.periodic.continuation.continuation` through folds).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from cvtfem.elements.torsional import LINEAR, TorsionalNetwork
from cvtfem.periodic.hb import PeriodicSolution, solve_linear, solve_periodic

#: Samples per period for peaks and RMS values.
SAMPLES = 2048


@dataclass(frozen=True)
class ResponseSweep:
    """Periodic responses over a list of base frequencies.

    Attributes
    ----------
    omega : ndarray (F,) rad/s
    nonlinear : tuple of PeriodicSolution
        With backlash and gap laws (equal to ``linear`` for a linear network).
    linear : tuple of PeriodicSolution
        Every link with its contact stiffness (no backlash).
    wall : float, s
        Wall time of the nonlinear solves.
    """

    omega: np.ndarray
    nonlinear: tuple[PeriodicSolution, ...]
    linear: tuple[PeriodicSolution, ...]
    wall: float

    def peaks(self, which: str = "nonlinear", moments: bool = True) -> np.ndarray:
        """Peak ``|moment|`` (N m) or ``|force|`` (N) of every link per frequency (F, E)."""
        sols = self.nonlinear if which == "nonlinear" else self.linear
        return np.array([np.abs(_values(s, moments)).max(axis=1) for s in sols])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: per frequency the harmonic amplitudes of every node and the
        peak and RMS of every link force and moment, with and without backlash."""
        net = self.nonlinear[0].network
        out: dict[str, Any] = {"nodes": list(net.names), "links": list(net.link_names),
                               "units": {"frequency": "Hz", "amplitude": "m (circumferential, x = r phi)",
                                         "angle_amplitude": "rad", "force": "N", "moment": "N m"},
                               "points": []}
        for w, nl, lin in zip(self.omega, self.nonlinear, self.linear):
            point: dict[str, Any] = {"frequency": w / (2 * np.pi), "omega": w}
            for key, sol in (("backlash", nl), ("no_backlash", lin)):
                amp = sol.amplitudes()
                f, m = _values(sol, False), _values(sol, True)
                point[key] = {
                    "converged": sol.converged, "iterations": sol.iterations, "message": sol.message,
                    "harmonic_amplitudes": {name: amp[s].tolist() for s, name in enumerate(net.names)},
                    "harmonic_angle_amplitudes": {name: (amp[s] / net.radius[s]).tolist()
                                                  for s, name in enumerate(net.names)},
                    "link_force_peak": dict(zip(net.link_names, np.abs(f).max(axis=1).tolist())),
                    "link_force_rms": dict(zip(net.link_names, np.sqrt((f ** 2).mean(axis=1)).tolist())),
                    "link_moment_peak": dict(zip(net.link_names, np.abs(m).max(axis=1).tolist())),
                    "link_moment_rms": dict(zip(net.link_names, np.sqrt((m ** 2).mean(axis=1)).tolist())),
                }
            out["points"].append(point)
        return out


def _values(sol: PeriodicSolution, moments: bool) -> np.ndarray:
    if not sol.converged:
        return np.full((sol.network.n_links, SAMPLES), np.nan)
    return sol.link_moments(SAMPLES) if moments else sol.link_forces(SAMPLES)


def response_sweep(net: TorsionalNetwork, omegas: np.ndarray, N: int, samples: int = 0, tol: float = 1e-10,
                   max_iter: int = 50, backlash: bool = True) -> ResponseSweep:
    """Nonlinear and linear periodic responses at every base frequency ``omegas`` (rad/s).

    Non-converged points are kept with ``converged = False`` (their peaks are NaN
    in :meth:`ResponseSweep.peaks` and flagged in the JSON), never silently.
    """
    omegas = np.asarray(omegas, float)
    nonlinear_net = net if backlash else net.linearized("contact")
    has_nl = bool((nonlinear_net.law != LINEAR).any())
    start = time.perf_counter()
    nl: list[PeriodicSolution] = []
    prev = None
    for w in omegas:
        if has_nl:
            sol = solve_periodic(nonlinear_net, w, N, samples, tol, max_iter, a0=prev)
            if not sol.converged and prev is not None:
                sol = solve_periodic(nonlinear_net, w, N, samples, tol, max_iter)
            prev = sol.a if sol.converged else None
        else:
            sol = solve_linear(nonlinear_net, w, N)
        nl.append(sol)
    wall = time.perf_counter() - start
    lin = tuple(solve_linear(net, w, N) for w in omegas)
    return ResponseSweep(omegas, tuple(nl), lin, wall)
