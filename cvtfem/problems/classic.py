"""Smooth and stiff model problems: oscillator, limit cycle, Van der Pol, Prothero-Robinson,
coupled nonlinear oscillators (the ``ode_num_int`` test models, spec §12)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError
from cvtfem.problems.base import Problem

__all__ = ["oscillator", "limit_cycle", "van_der_pol", "van_der_pol_stiff", "prothero_robinson",
           "coupled_oscillators"]


def oscillator(omega: float = 1.0, t_end: float = 10.0) -> Problem:
    """``u'' = -omega^2 u``, ``u(0) = 1``, ``v(0) = 0`` (n2 = 1); exact ``cos(omega t)``."""
    if not omega > 0:
        raise InputError("omega", omega, "must be positive (rad/s)")

    def fun(t, x):
        return np.array([x[1], -omega ** 2 * x[0]])

    def exact(t):
        return np.array([np.cos(omega * t), -omega * np.sin(omega * t)])

    return Problem("oscillator", fun, np.array([1.0, 0.0]), (0.0, t_end), n2=1,
                   jac=lambda t, x: np.array([[0.0, 1.0], [-omega ** 2, 0.0]]), exact=exact)


def limit_cycle(r0: float = 0.3, t_end: float = 2.0) -> Problem:
    """Nonlinear planar system with closed form, for convergence orders.

    ``x' = -y + x (1 - r^2)``, ``y' = x + y (1 - r^2)``: ``theta = t``,
    ``r(t) = (1 + (r0^-2 - 1) e^{-2t})^{-1/2}``.
    """
    def fun(t, q):
        x, y = q
        g = 1 - x * x - y * y
        return np.array([-y + x * g, x + y * g])

    def jac(t, q):
        x, y = q
        g = 1 - x * x - y * y
        return np.array([[g - 2 * x * x, -1 - 2 * x * y], [1 - 2 * x * y, g - 2 * y * y]])

    def exact(t):
        r = 1 / np.sqrt(1 + (r0 ** -2 - 1) * np.exp(-2 * t))
        return np.array([r * np.cos(t), r * np.sin(t)])

    return Problem("limit_cycle", fun, np.array([r0, 0.0]), (0.0, t_end), jac=jac, exact=exact)


def van_der_pol(mu: float = 1.0, t_end: float | None = None) -> Problem:
    """Van der Pol ``u'' = mu (1 - u^2) u' - u`` as ``[u, v]`` (n2 = 1), ``u(0) = 2``."""
    if not mu >= 0:
        raise InputError("mu", mu, "must be non-negative")

    def fun(t, x):
        return np.array([x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]])

    def jac(t, x):
        return np.array([[0.0, 1.0], [-2 * mu * x[0] * x[1] - 1, mu * (1 - x[0] ** 2)]])

    return Problem(f"van_der_pol(mu={mu:g})", fun, np.array([2.0, 0.0]),
                   (0.0, t_end if t_end is not None else 2.0 * max(mu, 3.0)), n2=1, jac=jac)


def van_der_pol_stiff(eps: float = 1e-6, t_end: float = 2.0) -> Problem:
    """Van der Pol in Hairer-Wanner's singular-perturbation scaling (II §IV.10, test set "vdpol"):
    ``u' = v``, ``eps v' = (1 - u^2) v - u``, ``u(0) = 2``, ``v(0) = -2/3`` (n2 = 1); stiffness ~ 1/eps."""
    if not eps > 0:
        raise InputError("eps", eps, "must be positive")

    def fun(t, x):
        return np.array([x[1], ((1 - x[0] ** 2) * x[1] - x[0]) / eps])

    def jac(t, x):
        return np.array([[0.0, 1.0], [(-2 * x[0] * x[1] - 1) / eps, (1 - x[0] ** 2) / eps]])

    return Problem(f"van_der_pol_stiff(eps={eps:g})", fun, np.array([2.0, -2.0 / 3.0]), (0.0, t_end), n2=1,
                   jac=jac)


def prothero_robinson(lam: float = -1e4, t_end: float = 1.0) -> Problem:
    """Stiff 1-D problem ``y' = lam (y - g) + g'`` with ``g = sin t``; exact ``y = g``."""
    def fun(t, y):
        return lam * (y - np.sin(t)) + np.cos(t)

    return Problem("prothero_robinson", fun, np.array([0.0]), (0.0, t_end),
                   jac=lambda t, y: np.array([[lam]]), exact=lambda t: np.array([np.sin(t)]))


def coupled_oscillators(n: int = 10, k: float = 1.0, k3: float = 0.5, t_end: float = 10.0) -> Problem:
    """Chain of ``n`` unit masses, fixed ends, springs ``k d + k3 d^3`` (n2 = n, banded J)."""
    if not (isinstance(n, int) and n >= 1):
        raise InputError("n", n, "must be a positive integer")

    def fun(t, x):
        u, v = x[:n], x[n:]
        ext = np.concatenate([[0.0], u, [0.0]])
        d = np.diff(ext)
        f = k * d + k3 * d ** 3
        return np.concatenate([v, f[1:] - f[:-1]])

    band = sp.diags([1, 1, 1], [-1, 0, 1], shape=(n, n), dtype=bool)
    pattern = sp.bmat([[None, sp.identity(n, dtype=bool)], [band, None]], format="csr")
    pattern = sp.csr_matrix(pattern.astype(bool))
    y0 = np.concatenate([np.sin(np.pi * np.arange(1, n + 1) / (n + 1)), np.zeros(n)])
    return Problem(f"coupled_oscillators(n={n})", fun, y0, (0.0, t_end), n2=n, jac_sparsity=pattern)
