"""Hertz contacts on a compliant face: the penetrations of point contacts whose forces open the face (issue 20).

``m`` contacts press one face; contact ``i`` would penetrate ``Delta_r,i`` (m) on a rigid face, and the face opens
at ``i`` by ``d_i = sum_j K_ij N_j`` under the contact forces ``N_j = c max(Delta_j, 0)^1.5`` (``K`` the face's
symmetric positive definite influence matrix, m/N).  The true penetrations solve
``R(Delta) = Delta - Delta_r + K N(Delta) = 0``.  The forces are the minimiser of the strictly convex
complementary energy ``Psi(N) = N^T K N / 2 + sum 3/5 c^(-2/3) N^(5/3) - N^T Delta_r`` over ``N >= 0``, so the
solution is unique; ``R`` is ``-K`` times ``Psi``'s gradient on the active set and the Newton step on ``R``
(Jacobian ``I + K diag(N')``, ``N' = 1.5 c Delta^0.5``) is a descent direction of ``Psi`` (its slope is
``-R^T (diag(N')^-1 + K)^-1 R < 0``): damped Newton, a step taken when it satisfies Armijo on ``Psi`` or halves
the residual (the latter near the solution, where ``Psi`` changes below its rounding).  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import NumericalError

#: Newton iterations before giving up; the residual bound relative to the largest rigid-face penetration.
MAX_ITER, RTOL = 60, 1e-12


def complementary_energy(N, K, c: float, delta_r) -> float:
    """``Psi(N)`` (J) of forces ``N >= 0`` (N)."""
    return float(0.5 * N @ K @ N + 0.6 * c ** (-2 / 3) * np.sum(N ** (5 / 3)) - N @ delta_r)


def compliant_penetrations(delta_r, K, c: float):
    """``(Delta, N, iterations)``: true penetrations (m, (m,); <= 0 off contact: the gap less the opening) and
    forces (N) of contacts of Hertz constant ``c`` (N/m^1.5) with rigid-face penetrations ``delta_r`` on a face of
    influence matrix ``K`` (m/N).  ``K = 0`` gives ``Delta = delta_r`` exactly."""
    delta_r = np.asarray(delta_r, float)
    m = len(delta_r)
    if m == 0:
        return delta_r.copy(), np.zeros(0), 0
    scale = max(float(delta_r.max()), 0.0)
    if scale == 0.0:                                   # nothing touches: no force, no opening
        return delta_r.copy(), np.zeros(m), 0
    on = delta_r > 0
    kappa = np.maximum(K[:, on].sum(axis=1), np.diag(K))      # a ring-load estimate of each point's give
    with np.errstate(divide="ignore"):
        start = np.where(kappa > 0, (np.maximum(delta_r, 0) / np.where(kappa > 0, kappa, 1) / c) ** (2 / 3), np.inf)
    delta = np.where(on, np.minimum(delta_r, start), delta_r)
    tol = RTOL * scale

    def state(d):  # noqa: ANN001, ANN202
        root = np.sqrt(np.maximum(d, 0.0))
        N = c * np.maximum(d, 0.0) * root
        return N, 1.5 * c * root, d - delta_r + K @ N

    N, dN, R = state(delta)
    for it in range(1, MAX_ITER + 1):
        if np.abs(R).max() <= tol:
            return delta, N, it - 1
        step = np.linalg.solve(np.eye(m) + K * dN[None, :], -R)
        trial = delta + step
        Nt, dNt, Rt = state(trial)
        if not np.abs(Rt).max() <= 0.5 * np.abs(R).max():              # not halved: Armijo on Psi
            psi, slope = complementary_energy(N, K, c, delta_r), float(np.sum(R * dN * step))
            alpha = 1.0
            while (complementary_energy(Nt, K, c, delta_r) > psi + 1e-4 * alpha * slope and alpha >= 1e-8
                   and not np.abs(Rt).max() <= 0.5 * np.abs(R).max()):
                alpha *= 0.5
                trial = delta + alpha * step
                Nt, dNt, Rt = state(trial)
        delta, N, dN, R = trial, Nt, dNt, Rt
    if np.abs(R).max() <= tol:
        return delta, N, MAX_ITER
    raise NumericalError(f"the contacts on a compliant face did not converge in {MAX_ITER} Newton steps (residual "
                         f"{np.abs(R).max():.3g} m against {tol:.3g} m)", component="compliant_penetrations")
