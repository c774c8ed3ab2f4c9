"""Frequency sweeps of periodic responses with and without backlash, and their summary data.

A sweep follows the branch by pseudo-arclength continuation
(:func:`cvtfem.periodic.continuation.continuation`) from the first requested
frequency to the last, either direction, and reports the points landed on the
requested frequencies (every time the branch crosses one) plus the turning
points, in arclength order, each with its Floquet stability.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cvtfem.elements.torsional import LINEAR, TorsionalNetwork
from cvtfem.errors import InputError, NumericalError
from cvtfem.periodic.continuation import Branch, continuation
from cvtfem.periodic.hb import PeriodicSolution, solve_linear, solve_periodic
from cvtfem.periodic.stability import evaluations_estimate, floquet

#: Samples per period for peaks and RMS values.
SAMPLES = 2048
#: Largest estimated right-hand-side evaluations of one Floquet integration a sweep spends (about 15 s
#: for the 29-disk engine train); stiffer networks get no stability and a warning.
FLOQUET_BUDGET = 2e5
#: A multi-valued end is looked for beyond it over ``max(EXTENSION x span, EXTENSION_RELATIVE x frequency)``.
EXTENSION, EXTENSION_RELATIVE = 0.25, 0.1


@dataclass(frozen=True)
class ResponseSweep:
    """Periodic responses along a frequency sweep, in arclength order of the branch.

    Attributes
    ----------
    omega : ndarray (F,) rad/s
    nonlinear : tuple of PeriodicSolution
        With backlash and gap laws (equal to ``linear`` for a linear network).
    linear : tuple of PeriodicSolution
        Every link with its contact stiffness (no backlash).
    wall : float, s
        Wall time of the continuation (nonlinear solves).
    requested, turning : ndarray (F,) bool
        Point landed on a requested frequency; point nearest to a fold.
    floquet_max : ndarray (F,)
        Largest Floquet multiplier modulus per point (NaN without stability).
    branch : Branch
        Every continuation point (for figures).
    index : ndarray (F,) int
        Index of each point in ``branch.solutions``.
    warnings : tuple of str
    """

    omega: np.ndarray
    nonlinear: tuple[PeriodicSolution, ...]
    linear: tuple[PeriodicSolution, ...]
    wall: float
    requested: np.ndarray
    turning: np.ndarray
    floquet_max: np.ndarray
    branch: Branch
    index: np.ndarray
    warnings: tuple[str, ...] = field(default=())

    @property
    def stable(self) -> np.ndarray:
        """Floquet-stable points (F,) bool (``max |mu| < 1``)."""
        return self.floquet_max < 1

    def amplitudes(self) -> np.ndarray:
        """Half peak-to-peak displacement of every node per point (F, S), m."""
        return np.array([np.ptp(s.displacements(SAMPLES), axis=1) / 2 for s in self.nonlinear])

    def peaks(self, which: str = "nonlinear", moments: bool = True) -> np.ndarray:
        """Peak ``|moment|`` (N m) or ``|force|`` (N) of every link per frequency (F, E)."""
        sols = self.nonlinear if which == "nonlinear" else self.linear
        return np.array([np.abs(_values(s, moments)).max(axis=1) for s in sols])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: per point its frequency, branch flags, Floquet stability, the
        harmonic amplitudes of every node and the peak and RMS of every link force and moment,
        with and without backlash; the folds and the continuation's effort."""
        net = self.nonlinear[0].network
        br = self.branch
        out: dict[str, Any] = {"nodes": list(net.names), "links": list(net.link_names),
                               "units": {"frequency": "Hz", "amplitude": "m (circumferential, x = r phi)",
                                         "angle_amplitude": "rad", "force": "N", "moment": "N m"},
                               "folds": [{"frequency": w / (2 * np.pi), "omega": w} for w in br.fold_omega],
                               "continuation": {"steps": br.steps, "rejected": br.rejected, "points": len(br.solutions),
                                                "wall_time_s": self.wall},
                               "warnings": list(self.warnings), "points": []}
        amplitude = self.amplitudes()
        for k, (w, nl, lin) in enumerate(zip(self.omega, self.nonlinear, self.linear)):
            fm = self.floquet_max[k]
            point: dict[str, Any] = {
                "frequency": w / (2 * np.pi), "omega": w, "requested": bool(self.requested[k]),
                "turning_point": bool(self.turning[k]),
                "stable": bool(fm < 1) if np.isfinite(fm) else None,
                "floquet_max_modulus": float(fm) if np.isfinite(fm) else None,
                "amplitude": dict(zip(net.names, amplitude[k].tolist()))}
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
    return sol.link_moments(SAMPLES) if moments else sol.link_forces(SAMPLES)


def response_sweep(net: TorsionalNetwork, omegas: np.ndarray, N: int, samples: int = 0, tol: float = 1e-10,
                   max_iter: int = 50, backlash: bool = True, stability: bool = True,
                   floquet_rtol: float = 1e-8) -> ResponseSweep:
    """Follow the response from ``omegas[0]`` to ``omegas[-1]`` (rad/s, either direction) through folds.

    Reports the points at every crossing of a requested frequency and the turning points,
    in arclength order, with the no-backlash linear response at the same frequencies and
    (``stability``) the Floquet multipliers of every point.  Warns (``warnings``) when the
    response is multi-valued at an end of the range: there the sweep follows whichever
    solution Newton finds first.  ``max_iter`` bounds Newton at the first point.

    Raises
    ------
    NumericalError
        When the continuation cannot reach ``omegas[-1]``.
    """
    omegas = np.asarray(omegas, float)
    steps = np.diff(omegas)
    if not (omegas.ndim == 1 and omegas.size and (np.all(steps > 0) or np.all(steps < 0))):
        raise InputError("omegas", omegas.tolist(), "must be one frequency or strictly increasing or decreasing")
    nl_net = net if backlash else net.linearized("contact")
    w0, w1 = float(omegas[0]), float(omegas[-1])
    start = time.perf_counter()
    first = solve_periodic(nl_net, w0, N, samples, tol, max_iter, raise_on_failure=True)
    if w0 == w1:
        branch = Branch((first,), (), (), (0,), 0, 0, "one frequency", time.perf_counter() - start)
    else:
        branch = continuation(nl_net, w0, w1, N, samples=samples, tol=tol, targets=omegas, a0=first.a)
    wall = time.perf_counter() - start
    keep = sorted(set(branch.targets) | set(branch.turning_points))
    sols = tuple(branch.solutions[k] for k in keep)
    omega = np.array([s.omega for s in sols])
    warnings = _fold_warnings(nl_net, branch, first, sols[-1], w0, w1, N, samples, tol)
    cost = evaluations_estimate(nl_net, float(omega.min()))
    if stability and cost > FLOQUET_BUDGET:
        stability = False
        warnings += (f"Floquet stability skipped: the variational equations would need about {cost:.2g} "
                     f"right-hand-side evaluations per point (budget {FLOQUET_BUDGET:.0e}; stiff links "
                     f"against a period of {2 * np.pi / omega.min():.3g} s)",)
    fmax = np.array([floquet(s, rtol=floquet_rtol).spectral_radius if stability else np.nan for s in sols])
    lin = tuple(solve_linear(net, w, N) for w in omega)
    return ResponseSweep(omega, sols, lin, wall, np.isin(keep, branch.targets), np.isin(keep, branch.turning_points),
                         fmax, branch, np.array(keep), warnings)


def _fold_warnings(net, branch: Branch, first: PeriodicSolution, last: PeriodicSolution, w0: float, w1: float,
                   N: int, samples: int, tol: float) -> tuple[str, ...]:
    """Why an end of the range is multi-valued: the branch re-crosses it, or folds just outside it."""
    if w0 == w1 or not (net.law != LINEAR).any():
        return ()
    sign = np.sign(w1 - w0)
    out = []
    for end, sol, away, name in ((w0, first, -sign, "starts"), (w1, last, sign, "ends")):
        span = max(EXTENSION * abs(w1 - w0), EXTENSION_RELATIVE * end)
        beyond = [f for f in branch.fold_omega if (f - end) * away > 0]  # the branch turned back across `end`
        fold = max(beyond, key=lambda f: (f - end) * away) if beyond else None
        if fold is None:
            try:
                ext = continuation(net, end, max(end + away * span, end / 2), N, samples=samples, tol=tol, a0=sol.a,
                                   max_folds=1)
            except NumericalError:
                continue
            fold = ext.fold_omega[0] if ext.fold_omega else None
        if fold is not None:
            out.append(f"the sweep {name} at {end / (2 * np.pi):.6g} Hz where the response is multi-valued (a fold at "
                       f"{fold / (2 * np.pi):.6g} Hz lies beyond it): it follows the solution found first there; "
                       f"a range reaching past {fold / (2 * np.pi):.6g} Hz sweeps the whole resonance curve")
    return tuple(out)
