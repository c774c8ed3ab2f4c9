"""Sparsity and graph colouring of Jacobians; coloured finite differences (spec §11.3).

Columns ``i, j`` of ``dF/dx`` may share one finite-difference evaluation when no row has
non-zeros in both (Curtis-Powell-Reid; Ypma 1987): a colouring of the column intersection
graph ``S^T S``.  One Jacobian then costs as many right-hand-side calls as there are colours
(``F(x)`` is reused).  Nothing here knows what the states mean.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

__all__ = ["color_columns", "coloured_difference"]


def color_columns(pattern: sp.spmatrix, order: str = "largest_first") -> np.ndarray:
    """Greedy colouring of the column intersection graph of ``pattern`` (n_rows, n).

    Returns ``colors`` (n,) with ``colors[j]`` the group of column ``j``; columns in one group
    have disjoint row supports. ``order``: ``"largest_first"`` (by degree) or ``"natural"``.
    """
    S = sp.csc_matrix(pattern, dtype=bool).astype(np.int32)  # int8 counts wrap: 256 shared rows look like none
    G = (S.T @ S).tocsr()
    n = G.shape[0]
    degree = np.diff(G.indptr)
    visit = np.argsort(-degree, kind="stable") if order == "largest_first" else np.arange(n)
    colors = np.full(n, -1, dtype=np.int64)
    for j in visit:
        used = set(colors[G.indices[G.indptr[j]:G.indptr[j + 1]]].tolist())
        c = 0
        while c in used:
            c += 1
        colors[j] = c
    return colors


def coloured_difference(fun: Callable, t: float, x: np.ndarray, f0: np.ndarray, pattern: sp.coo_matrix,
                        colors: np.ndarray, delta: np.ndarray | None = None) -> sp.csr_matrix:
    """Forward-difference Jacobian of ``fun(t, x)`` on the non-zeros of ``pattern`` (COO), one call per colour.

    ``delta`` (n,): increments (default ``sqrt(eps) max(|x|, 1)``, rounded to representable steps).
    Returns CSR ``(n_rows, n)``; entries outside ``pattern`` are zero.
    """
    if delta is None:
        delta = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(x), 1.0)
        delta = (x + delta) - x
    rows, cols = pattern.row, pattern.col
    vals = np.empty(len(rows), dtype=np.result_type(x, f0))
    for c in range(int(colors.max()) + 1 if len(colors) else 0):
        mask = colors == c
        xp = x.copy()
        xp[mask] += delta[mask]
        df = fun(t, xp) - f0
        sel = mask[cols]
        vals[sel] = df[rows[sel]] / delta[cols[sel]]
    return sp.csr_matrix((vals, (rows, cols)), shape=pattern.shape)
