"""Ritz functions of the transversely compressible band (6+2n models).

Spec: low-order digest section 4.4, eqs. (1.52)-(1.56).  With ``xi = theta / theta*``
in [-1, 1] and ``j = 1, 2, ...``:
``f_theta,2j-1 = cos(j pi xi / 2) - cos(j pi / 2)``, ``f_theta,2j = sin(j pi xi / 2) - xi sin(j pi / 2)``
and ``f_r = -d f_theta / d theta`` (local inextensibility (1.54)).
"""
from __future__ import annotations

import numpy as np


def ritz_shapes(xi, n: int):
    """Shape functions ``F_i(xi) = f_theta,i`` and their xi-derivatives ``F_i'``, each ``(n, len(xi))``."""
    xi = np.asarray(xi, dtype=float)
    i = np.arange(1, n + 1)[:, None]
    j = (i + 1) // 2
    a = j * np.pi / 2
    odd = (i % 2) == 1
    F = np.where(odd, np.cos(a * xi) - np.cos(a), np.sin(a * xi) - xi * np.sin(a))
    dF = np.where(odd, -a * np.sin(a * xi), a * np.cos(a * xi) - np.sin(a))
    return F, dF


def ritz_functions(xi, theta_star, n: int):
    """``f_theta`` and ``f_r = -F'(xi) / theta*`` on an arc of half-angle ``theta_star`` (may be complex)."""
    F, dF = ritz_shapes(xi, n)
    return F, -dF / theta_star


def ritz_alpha(n: int, nodes: int = 64):
    """``alpha_ij = int_{-1}^{1} F_i' F_j' dxi`` (section 4.4 [D]); exact by Gauss-Legendre quadrature.

    Examples
    --------
    >>> a = ritz_alpha(6)
    >>> bool(abs(a[0, 2] - 4 * np.pi / 3) < 1e-12 and abs(a[1, 3] - 2 * np.pi / 3) < 1e-12)
    True
    """
    x, w = np.polynomial.legendre.leggauss(nodes)
    _, dF = ritz_shapes(x, n)
    return (dF * w) @ dF.T
