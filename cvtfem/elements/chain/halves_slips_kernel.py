"""Compiled twin of the rolling-contact part of :meth:`~cvtfem.elements.chain.halves.ChainA5.friction_slips`: the
values of the slip rows (m/s per unit velocity) in the order the numpy method adds them, and the normal forces (N)
of every contact and Gauss station; :func:`kept_rows` the slip map's rows with a normal force, in CSR.  The numpy
method stays the reference (its tests check this kernel to 1e-12).
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.jit import njit

__all__ = ["kept_rows", "rolling_slip_values"]


@njit(cache=True)
def rolling_slip_values(u, nxt, axis_link, cs, H, ws, contacts, offs, radii, rho0, stiff, weights, vals, N):
    """Fill ``vals`` (``3 S 2 12 n``: per contact ``k``, station ``s``, half ``B`` then ``A``: the ``(n, 4, 2)`` block
    on the half's displacement dofs, then ``(n, 2)`` on the next link's and ``(n, 2)`` on its own) and ``N`` (3, S,
    n).  ``u`` (2, 4, n, 2) the halves' nodal vectors; ``contacts`` (3, 3) rows ``(A, B, sigma)``; ``offs`` (3, 2, 2)
    the offsets of A and B, ``radii`` (3, 2) their radii; ``H`` (4, S) the shape functions at the stations, ``ws``
    (S,) their weights (m)."""
    n, S = u.shape[2], H.shape[1]
    rho_l, nl = np.empty(n), np.empty((n, 2))
    th, nh = np.empty((2, n, 2)), np.empty((2, n, 2))
    for e in range(n):
        x0, x1 = u[1, 0, nxt[e], 0] - u[0, 0, e, 0], u[1, 0, nxt[e], 1] - u[0, 0, e, 1]
        rho_l[e] = np.sqrt(x0 * x0 + x1 * x1)
        nl[e, 0], nl[e, 1] = -x1 / rho_l[e], x0 / rho_l[e]
    for hf in range(2):
        c, s = cs[hf, 0], cs[hf, 1]
        for p in range(n):
            e = axis_link[hf, p]
            t0, t1 = nl[e, 1], -nl[e, 0]                             # tau of the link
            th[hf, p, 0], th[hf, p, 1] = c * t0 - s * t1, c * t1 + s * t0
            nh[hf, p, 0], nh[hf, p, 1] = -th[hf, p, 1], th[hf, p, 0]
    Ux = np.zeros((2, S, n, 2))
    for h in range(2):
        for st in range(S):
            for i in range(4):
                for p in range(n):
                    Ux[h, st, p, 0] += H[i, st] * u[h, i, p, 0]
                    Ux[h, st, p, 1] += H[i, st] * u[h, i, p, 1]
    o = 0
    r = np.empty((2, 2))
    for k in range(contacts.shape[0]):
        A, B, sig = int(contacts[k, 0]), int(contacts[k, 1]), contacts[k, 2]
        for st in range(S):
            for side in range(2):                                    # half B (+), then half A (-)
                h = B if side == 0 else A
                sgn = 1.0 if side == 0 else -1.0
                for p in range(n):
                    for j in range(2):                               # r_A, r_B of pin p
                        hj = A if j == 0 else B
                        r[j, 0] = offs[k, j, 0] * th[hj, p, 0] + offs[k, j, 1] * nh[hj, p, 0]
                        r[j, 1] = offs[k, j, 0] * th[hj, p, 1] + offs[k, j, 1] * nh[hj, p, 1]
                    d0 = Ux[B, st, p, 0] + r[1, 0] - Ux[A, st, p, 0] - r[0, 0]
                    d1 = Ux[B, st, p, 1] + r[1, 1] - Ux[A, st, p, 1] - r[0, 1]
                    rho = np.sqrt(d0 * d0 + d1 * d1)
                    t0, t1 = -d1 / rho, d0 / rho                     # tt = k x d / rho
                    if side == 0:
                        N[k, st, p] = ws[st] * weights[k, p] * stiff[k] * max(-sig * (rho - rho0[k]), 0.0)
                        coef = t0 * (-r[1, 1]) + t1 * r[1, 0] - sig * radii[k, 1]
                    else:
                        coef = -(t0 * (-r[0, 1]) + t1 * r[0, 0] + radii[k, 0])
                    for i in range(4):
                        vals[o + p * 8 + i * 2] = sgn * H[i, st] * t0
                        vals[o + p * 8 + i * 2 + 1] = sgn * H[i, st] * t1
                    e = axis_link[h, p]
                    g = coef / rho_l[e]
                    for c in range(2):
                        vals[o + 8 * n + p * 2 + c] = g * nl[e, c]
                        vals[o + 10 * n + p * 2 + c] = -g * nl[e, c]
                o += 12 * n


@njit(cache=True)
def kept_rows(where, vals, indices, indptr, keep):
    """The rows ``keep`` of the CSR matrix with the pattern ``indices``, ``indptr`` whose entry ``where[i]`` sums
    ``vals[i]``: ``(data, indices, indptr)`` of the kept rows, in order."""
    full = np.zeros(indices.shape[0])
    for i in range(where.shape[0]):
        full[where[i]] += vals[i]
    ptr = np.empty(keep.shape[0] + 1, np.int32)
    ptr[0] = 0
    for k in range(keep.shape[0]):
        ptr[k + 1] = ptr[k] + indptr[keep[k] + 1] - indptr[keep[k]]
    data, ind = np.empty(ptr[-1]), np.empty(ptr[-1], np.int32)
    for k in range(keep.shape[0]):
        o = indptr[keep[k]]
        for b in range(ptr[k + 1] - ptr[k]):
            data[ptr[k] + b], ind[ptr[k] + b] = full[o + b], indices[o + b]
    return data, ind, ptr
