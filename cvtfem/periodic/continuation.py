"""Pseudo-arclength continuation of periodic responses in the base frequency (beyond source B).

Follows the branch ``r(a, omega) = 0`` through turning points (where sweeps up
and down jump), with the bordered (Keller) corrector: two block-sweep solves
per iteration, ``J z1 = -r`` and ``J z2 = -dr/domega``.  Variables are scaled
(harmonics by the start's RMS amplitude, ``omega`` by its start value) so the
arclength mixes comparable numbers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.torsional import TorsionalNetwork
from cvtfem.errors import InputError, NumericalError
from cvtfem.periodic.hb import (PeriodicSolution, _symmetrize, default_samples, linearize, load_harmonics,
                                prepare, single_thread_blas, solve_periodic)
from cvtfem.periodic.blocktri import solve_blocks


@dataclass(frozen=True)
class Branch:
    """Solutions along a continuation branch, in arclength order.

    Attributes
    ----------
    solutions : tuple of PeriodicSolution
    turning_points : tuple of int
        Indices where ``omega`` changes direction (folds of the response curve).
    message : str
        Why the continuation stopped.
    """

    solutions: tuple[PeriodicSolution, ...]
    turning_points: tuple[int, ...]
    message: str

    @property
    def omega(self) -> np.ndarray:
        return np.array([s.omega for s in self.solutions])


def _domega(net: TorsionalNetwork, omega: float, a: np.ndarray, D) -> np.ndarray:
    """``dr/domega`` (S, K) of the Galerkin residual."""
    N = (a.shape[1] - 1) // 2
    n = np.arange(-N, N + 1)
    node = (-2 * n ** 2 * omega * net.m[:, None] + 1j * n * net.b[:, None]) * a
    return node + D.T @ (1j * n * net.d[:, None] * (D @ a))


def continuation(net: TorsionalNetwork, omega_start: float, omega_stop: float, N: int, ds: float = 0.02,
                 samples: int = 0, tol: float = 1e-9, max_steps: int = 400, max_corrector: int = 8,
                 ds_max: float = 0.1) -> Branch:
    """Follow the periodic response from ``omega_start`` towards ``omega_stop`` (rad/s).

    Parameters
    ----------
    ds, ds_max : float
        Initial and largest arclength step in scaled variables (``omega`` scaled
        by ``omega_start``); halved on corrector failure, grown by 1.3 after
        quick convergence.
    tol : float
        Relative residual norm of the corrector.
    """
    if not (omega_start > 0 and omega_stop > 0 and omega_start != omega_stop):
        raise InputError("omega_stop", omega_stop, "must be positive and differ from `omega_start`")
    with single_thread_blas():
        first = solve_periodic(net, omega_start, N, samples=samples, tol=tol, raise_on_failure=True)
        M = first.samples or default_samples(N)
        topo = prepare(net)
        D = net.incidence()
        p = load_harmonics(net, N)
        scale_p = max(np.linalg.norm(p), 1e-300)
        A = max(np.linalg.norm(first.a) / np.sqrt(first.a.size), 1e-300)
        W = omega_start

        def dot(ua, uw, va, vw):
            return float(np.vdot(ua, va).real / A ** 2 + uw * vw / W ** 2)

        def solve(Nb, L, rhs):
            return _symmetrize(solve_blocks(Nb, L, net.i, net.j, rhs[:, None], topo)[0][:, 0])

        a, omega = first.a, omega_start
        _, Nb, L = linearize(net, omega, a, p, M, D)
        ta = solve(Nb, L, -_domega(net, omega, a, D))
        tw = 1.0 if omega_stop > omega_start else -1.0
        ta, norm = ta * tw, np.sqrt(dot(ta, 1.0, ta, 1.0))
        ta, tw = ta / norm, tw / norm
        sols, turns, message = [first], [], "reached omega_stop"
        for _ in range(max_steps):
            while True:
                a_p, w_p = a + ds * ta, omega + ds * tw
                a_c, w_c, ok, its = a_p.copy(), w_p, False, 0
                for its in range(1, max_corrector + 1):
                    r, Nb, L = linearize(net, w_c, a_c, p, M, D)
                    if np.linalg.norm(r) / scale_p <= tol:
                        ok = True
                        break
                    z1 = solve(Nb, L, -r)
                    z2 = solve(Nb, L, -_domega(net, w_c, a_c, D))
                    g = dot(ta, tw, a_c - a_p, w_c - w_p)
                    dw = (-g - dot(ta, 0.0, z1, 0.0)) / (tw / W ** 2 + dot(ta, 0.0, z2, 0.0))
                    a_c, w_c = a_c + z1 + dw * z2, w_c + dw
                    if not np.all(np.isfinite(a_c)) or w_c <= 0:
                        break
                if ok:
                    break
                ds /= 2
                if ds < 1e-6:
                    raise NumericalError(f"arclength continuation stalled at omega = {omega:.6g} rad/s "
                                         "(corrector fails for every step)", component="continuation")
            new_ta, new_tw = a_c - a, w_c - omega
            norm = np.sqrt(dot(new_ta, new_tw, new_ta, new_tw))
            new_ta, new_tw = new_ta / norm, new_tw / norm
            if new_tw * tw < 0:
                turns.append(len(sols) - 1)
            ta, tw, a, omega = new_ta, new_tw, a_c, w_c
            sols.append(PeriodicSolution(net, omega, a, True, its, (), "sweep", "converged", M))
            if its <= 3:
                ds = min(ds * 1.3, ds_max)
            if (omega - omega_stop) * np.sign(omega_stop - omega_start) >= 0:
                break
            if not min(omega_start, omega_stop) * 0.5 < omega < 2 * max(omega_start, omega_stop):
                message = "left the frequency range"
                break
        else:
            message = f"stopped after max_steps = {max_steps}"
    return Branch(tuple(sols), tuple(turns), message)
