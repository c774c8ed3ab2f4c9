"""Pseudo-arclength continuation of periodic responses in the base frequency (beyond source B).

Follows the branch ``r(a, omega) = 0`` through turning points (where sweeps up
and down jump), with the bordered (Keller) corrector: two block-sweep solves
per iteration, ``J z1 = -r`` and ``J z2 = -dr/domega``.  Variables are scaled
(harmonics by the largest RMS amplitude met so far, ``omega`` by its start value)
so the arclength mixes comparable numbers on the way up a resonance and down.
The tangent at every accepted point is the null vector of ``[J, dr/domega]``
(one more solve), oriented along the previous one: its ``omega`` component
changes sign exactly at a fold, which is then located by regula falsi on that
component.  The step adapts to the corrector's iteration count; requested
frequencies (``targets``) are landed on exactly by Newton at fixed ``omega``
from the interpolated branch.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from cvtfem.blas import single_thread_blas
from cvtfem.elements.torsional import TorsionalNetwork
from cvtfem.errors import InputError, NumericalError
from cvtfem.periodic.blocktri import solve_mixed
from cvtfem.periodic.hb import (PeriodicSolution, _symmetrize, default_samples, linearize_mixed, load_harmonics,
                                newton, prepare, solve_periodic)

#: Corrector iterations the step control aims at: ``ds *= clip(TARGET_ITERATIONS / its, 1/2, 2)``.
TARGET_ITERATIONS = 4
#: Fold location: at most this many regula-falsi steps, stopping when ``|d omega / ds| <= FOLD_TOL``
#: (scaled: ``omega`` by the start frequency).
FOLD_ITERATIONS, FOLD_TOL = 8, 1e-6
#: Smallest cosine between successive tangents of an accepted step (larger turns halve the step).
MIN_TANGENT_COS = 0.9


@dataclass(frozen=True)
class Branch:
    """Solutions along a continuation branch, in arclength order.

    Attributes
    ----------
    solutions : tuple of PeriodicSolution
    turning_points : tuple of int
        Indices of the fold points (located where ``d omega / ds = 0`` to ``FOLD_TOL``; the
        nearer step point if that fails).
    fold_omega : tuple of float, rad/s
        Frequency of each turning point.
    targets : tuple of int
        Indices of the points landed on the requested frequencies, in arclength order
        (a frequency the branch crosses three times appears three times).
    steps, rejected : int
        Accepted and rejected (halved) continuation steps.
    message : str
        Why the continuation stopped.
    wall : float, s
    """

    solutions: tuple[PeriodicSolution, ...]
    turning_points: tuple[int, ...]
    fold_omega: tuple[float, ...]
    targets: tuple[int, ...]
    steps: int
    rejected: int
    message: str
    wall: float

    @property
    def omega(self) -> np.ndarray:
        return np.array([s.omega for s in self.solutions])


def _domega(net: TorsionalNetwork, omega: float, a: np.ndarray, D) -> np.ndarray:
    """``dr/domega`` (S, K) of the Galerkin residual."""
    N = (a.shape[1] - 1) // 2
    n = np.arange(-N, N + 1)
    node = (-2 * n ** 2 * omega * net.m[:, None] + 1j * n * net.b[:, None]) * a
    return node + D.T @ (1j * n * net.d[:, None] * (D @ a))


def continuation(net: TorsionalNetwork, omega_start: float, omega_stop: float, N: int, ds: float = 0.05,
                 samples: int = 0, tol: float = 1e-9, max_steps: int = 2000, max_corrector: int = 8,
                 ds_min: float = 1e-6, ds_max: float = 1.0, targets=(), a0: np.ndarray | None = None,
                 max_folds: int | None = None) -> Branch:
    """Follow the periodic response from ``omega_start`` towards ``omega_stop`` (rad/s), either direction.

    Parameters
    ----------
    ds, ds_min, ds_max : float
        Initial, smallest and largest arclength step in scaled variables; the step
        is halved when the corrector fails or the tangent turns by more than about
        25 degrees, and scaled by ``TARGET_ITERATIONS / iterations`` (within 1/2..2)
        after each accepted step.
    tol : float
        Relative residual norm of the corrector.
    targets : sequence of float, rad/s
        Frequencies to land on whenever the branch crosses them (``omega_stop`` always is one).
    a0 : ndarray (S, 2N+1), optional
        Start for the first solve at ``omega_start``.
    max_folds : int, optional
        Stop after this many turning points (message "stopped at a fold").

    Raises
    ------
    NumericalError
        When the step falls below ``ds_min`` or ``max_steps`` is reached before ``omega_stop``.
    """
    if not (np.isfinite(omega_start) and np.isfinite(omega_stop) and omega_start > 0 and omega_stop > 0
            and omega_start != omega_stop):
        raise InputError("omega_stop", omega_stop, "must be positive and differ from `omega_start`")
    clock = time.perf_counter()
    sign = 1.0 if omega_stop > omega_start else -1.0
    goals = np.unique(np.append(np.asarray(targets, float), omega_stop))
    p = load_harmonics(net, N)
    if not np.any(p):
        raise InputError("torsional.load", "no nonzero amplitude", "must excite the network (a load with a nonzero "
                         "amplitude): without one the periodic response is zero at every frequency, with no branch "
                         "to follow")
    with single_thread_blas():
        first = solve_periodic(net, omega_start, N, samples=samples, tol=tol, a0=a0, raise_on_failure=True)
        M = first.samples or default_samples(N)
        topo = prepare(net)
        D = net.incidence()
        scale_p = max(np.linalg.norm(p), 1e-300)
        scale = [max(np.linalg.norm(first.a) / np.sqrt(first.a.size), 1e-300)]  # grows with the response
        W = omega_start

        def dot(ua, uw, va, vw):
            return float(np.vdot(ua, va).real / scale[0] ** 2 + uw * vw / W ** 2)

        def jacobian(w, a):
            r, Nd, Ld, dense, Ldense = linearize_mixed(net, w, a, p, M, D)
            return r, lambda g: _symmetrize(solve_mixed(Nd, Ld, dense, Ldense, net.i, net.j, _symmetrize(g),
                                                        topo)[0])

        def tangent(w, a, ref_a, ref_w):
            _, solve = jacobian(w, a)
            ta, tw = solve(-_domega(net, w, a, D)), 1.0
            norm = np.sqrt(dot(ta, tw, ta, tw))
            if dot(ta, tw, ref_a, ref_w) < 0:
                norm = -norm
            return ta / norm, tw / norm

        def corrector(a_p, w_p, ta, tw):
            a_c, w_c = a_p.copy(), w_p
            for its in range(1, max_corrector + 1):
                r, solve = jacobian(w_c, a_c)
                if np.linalg.norm(r) / scale_p <= tol:
                    return a_c, w_c, its
                z1 = solve(-r)
                z2 = solve(-_domega(net, w_c, a_c, D))
                g = dot(ta, tw, a_c - a_p, w_c - w_p)
                dw = (-g - dot(ta, 0.0, z1, 0.0)) / (tw / W ** 2 + dot(ta, 0.0, z2, 0.0))
                a_c, w_c = a_c + z1 + dw * z2, w_c + dw
                if not np.all(np.isfinite(a_c)) or w_c <= 0:
                    return None
            return None

        def land(goal, a0_, w0, a1, w1, step):
            """Newton at fixed ``goal`` from the branch interpolated between two points; None if it strays."""
            lam = (goal - w0) / (w1 - w0)
            guess = a0_ + lam * (a1 - a0_)
            a_g, ok, hist, _ = newton(net, goal, p, guess, M, topo, D, tol, max_corrector)
            if not ok or np.sqrt(dot(a_g - guess, 0.0, a_g - guess, 0.0)) > step:
                return None
            return PeriodicSolution(net, goal, a_g, True, len(hist) - 1, tuple(hist), "sweep", "converged", M)

        def refine_fold(a0_, w0, ta0, tw0, h, tw1):
            """The fold inside a step of length ``h`` from ``(a0_, w0)``: regula falsi on the tangent's
            ``omega`` component along the step, the kept end's value halved (Illinois-type); None if the
            first corrector fails."""
            lo, hi, f_lo, f_hi, best = 0.0, h, tw0, tw1, None
            for _ in range(FOLD_ITERATIONS):
                mid = lo + (hi - lo) * f_lo / (f_lo - f_hi)
                out = corrector(a0_ + mid * ta0, w0 + mid * tw0, ta0, tw0)
                if out is None:
                    return best
                a_m, w_m, its_m = out
                f_m = tangent(w_m, a_m, ta0, tw0)[1]
                best = PeriodicSolution(net, w_m, a_m, True, its_m - 1, (), "sweep", "converged", M)
                if abs(f_m) <= FOLD_TOL * W:
                    break
                if f_m * f_lo > 0:
                    lo, f_lo, f_hi = mid, f_m, f_hi / 2
                else:
                    hi, f_hi, f_lo = mid, f_m, f_lo / 2
            return best

        a, omega, base = first.a, omega_start, 0
        ta, tw = tangent(omega, a, np.zeros_like(a), sign)
        sols, hits, turns = [first], [0] if np.any(goals == omega_start) else [], []
        steps = rejected = 0
        message = "reached omega_stop"
        while (omega - omega_stop) * sign < 0:
            if max_folds is not None and len(turns) >= max_folds:
                message = "stopped at a fold"
                break
            if steps >= max_steps:
                raise NumericalError(f"arclength continuation did not reach {omega_stop:.6g} rad/s in max_steps = "
                                     f"{max_steps} steps (now at omega = {omega:.6g} rad/s, step {ds:.3g})",
                                     component="continuation")
            if not min(omega_start, omega_stop) / 2 < omega < 2 * max(omega_start, omega_stop):
                raise NumericalError(f"the branch left the frequency range at omega = {omega:.6g} rad/s after "
                                     f"{len(turns)} folds (a closed or detached branch?)", component="continuation")
            out = corrector(a + ds * ta, omega + ds * tw, ta, tw)
            if out is not None:
                a_c, w_c, its = out
                new_ta, new_tw = tangent(w_c, a_c, ta, tw)
                if dot(ta, tw, new_ta, new_tw) < MIN_TANGENT_COS:
                    out = None
            if out is None:
                rejected += 1
                ds /= 2
                if ds < ds_min:
                    raise NumericalError(f"arclength continuation stalled at omega = {omega:.6g} rad/s: the corrector "
                                         f"fails for every step down to ds_min = {ds_min:g}", component="continuation")
                continue
            steps += 1
            length = np.sqrt(dot(a_c - a, w_c - omega, a_c - a, w_c - omega))
            fold = refine_fold(a, omega, ta, tw, ds, new_tw) if new_tw * tw < 0 else None
            new = PeriodicSolution(net, w_c, a_c, True, its - 1, (), "sweep", "converged", M)
            if new_tw * tw < 0 and fold is None:  # not located: the nearer step point stands for the fold
                turns.append(base if abs(tw) <= abs(new_tw) else -1)
            ends = [sols[base]] + ([fold] if fold is not None else []) + [new]
            start_index = base
            for first_end, end in zip(ends[:-1], ends[1:]):  # a fold splits the step: omega monotonic in each part
                w0, w1 = first_end.omega, end.omega
                for goal in sorted(goals[(goals - w0) * (w1 - goals) > 0], key=lambda g: abs(g - w0)):
                    hit = land(goal, first_end.a, w0, end.a, w1, length)
                    if hit is not None:
                        sols.append(hit)
                        hits.append(len(sols) - 1)
                    else:  # ill-conditioned next to a fold: the nearer end stands for it (-1: ``end``)
                        hits.append(start_index if abs(w0 - goal) <= abs(w1 - goal) else -1)
                sols.append(end)
                start_index = len(sols) - 1
                hits = [start_index if h == -1 else h for h in hits]
                if end is fold:
                    turns.append(len(sols) - 1)
            base = len(sols) - 1
            turns = [base if t == -1 else t for t in turns]
            if np.any(goals == w_c):
                hits.append(base)
            a, omega, ta, tw = a_c, w_c, new_ta, new_tw
            rms = np.linalg.norm(a) / np.sqrt(a.size)
            if rms > scale[0]:  # rescale to the largest response so far; the tangent keeps unit length
                scale[0] = rms
                norm = np.sqrt(dot(ta, tw, ta, tw))
                ta, tw = ta / norm, tw / norm
            ds = float(np.clip(ds * np.clip(TARGET_ITERATIONS / max(its - 1, 1), 0.5, 2.0), ds_min, ds_max))
    folds = tuple(float(sols[t].omega) for t in turns)
    return Branch(tuple(sols), tuple(turns), folds, tuple(hits), steps, rejected, message,
                  time.perf_counter() - clock)
