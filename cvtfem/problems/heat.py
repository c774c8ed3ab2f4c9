"""1-D heat equation ``u_t = u_xx`` on (0, 1), ``u = 0`` at both ends, method of lines."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError
from cvtfem.problems.base import Problem

__all__ = ["heat1d"]


def heat1d(N: int = 1000, t_end: float = 0.1) -> Problem:
    """Second-difference semi-discretisation with ``N`` interior nodes, ``dx = 1/(N+1)``.

    ``u0 = sin(pi x) + 0.5 sin(5 pi x)``; the exact semi-discrete solution is
    ``sum_k a_k exp(lam_k t) sin(k pi x)`` with ``lam_k = -(4/dx^2) sin^2(k pi dx / 2)``.
    The Jacobian is tridiagonal (``jac`` sparse, ``jac_sparsity`` given); its spectral
    radius is about ``4/dx^2`` (4e6 1/s for N = 1000).
    """
    if not (isinstance(N, (int, np.integer)) and N >= 3):
        raise InputError("N", N, "must be an integer >= 3")
    dx = 1.0 / (N + 1)
    x = np.arange(1, N + 1) * dx
    A = sp.diags([1.0, -2.0, 1.0], [-1, 0, 1], shape=(N, N), format="csr") / dx ** 2
    modes = ((1, 1.0), (5, 0.5))

    def fun(t, u):
        return A @ u

    def exact(t):
        return sum(a * np.exp(-(4 / dx ** 2) * np.sin(k * np.pi * dx / 2) ** 2 * t) * np.sin(k * np.pi * x)
                   for k, a in modes)

    return Problem(f"heat1d(N={N})", fun, exact(0.0), (0.0, t_end), jac=lambda t, u: A,
                   jac_sparsity=A != 0, exact=exact, info={"rho": 4 / dx ** 2, "x": x})
