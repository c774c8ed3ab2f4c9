"""Compiled (numba) H1 pin–sheave contact over a constant contact map: gather, broad phase, contact, scatter.

The numpy path of :class:`~cvtfem.machines.chain_cvt.ChainCVT` (broad phase, contact map, local inputs ``X``,
:meth:`SheaveContact.local <cvtfem.elements.chain.sheave_contact.SheaveContact.local>` and the scatter through
the output rows) is the tested reference of these kernels (``tests/elements/chain/test_sheave_contact_kernel.py``).
Here one loop runs over every ``(end, shaft)`` pair of the map table built once per model: the pair is a candidate
when its in-plane end position (local inputs 0 and 1) lies within the sheaves' outer radius, and a candidate off
contact (``Delta <= 0``) gives no forces.

Arguments shared by the kernels: ``y = [q, v, constants]``; the map table ``cols``, ``coef`` (P, 9, K) (local
input ``j`` is ``sum_a coef[j, a] y[cols[j, a]]``), the shaft of every pair ``shaft`` (P,), the output rows
``rows``, ``rw`` (P, 5, K) of :meth:`ChainCVT._output_rows`; the constants tuple of :func:`pack`.
Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.contact.kernels import LAW_CODES, _gain
from cvtfem.elements.jit import njit

#: Central-difference steps of the local inputs (m, m/s, rad/s): those of ``SheaveContact.local_jacobian``.
STEPS = np.array([1e-9] * 4 + [1e-6] * 4 + [1e-5])
N_IN, N_OUT = 9, 6


def pack(contact, scale: float) -> tuple:
    """Kernel constants of a :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact` whose outputs are scaled
    by ``scale`` (1 for the mirrored pair, 0.5 for single ends): ``(centres (2, 2), r_outer^2, profiles (2, 3),
    c (2,), (f0, v0, eps, scale), law code)``; a profile row is ``(0, tan gamma, 0)`` (conical) or ``(1, R, y)``
    (toroidal), the face ``f(r) = -s(r)`` of :func:`~cvtfem.elements.chain.sheave_contact.face_profile`."""
    prof = np.zeros((2, 3))
    for k, face in enumerate(contact.faces):
        prof[k] = (0.0, np.tan(face.gamma), 0.0) if face.profile == "conical" else (1.0, face.R, face.y)
    return (np.ascontiguousarray(contact.centres, float), float(contact.r_outer) ** 2, prof,
            np.ascontiguousarray(contact.c, float), np.array([contact.f0, contact.v0, contact.eps, scale]),
            LAW_CODES[contact.law])


@njit(cache=True)
def _inputs(y, cols, coef, i, X):
    """Local inputs ``X`` (9,) of pair ``i``."""
    for j in range(cols.shape[1]):
        s = coef[i, j, 0] * y[cols[i, j, 0]]
        for a in range(1, cols.shape[2]):
            s += coef[i, j, a] * y[cols[i, j, a]]
        X[j] = s


@njit(cache=True)
def _near(y, cols, coef, i, centre, r2):
    """Broad phase of pair ``i``: its end (inputs 0, 1) within the outer radius of its shaft at ``centre``."""
    d0 = coef[i, 0, 0] * y[cols[i, 0, 0]]
    d1 = coef[i, 1, 0] * y[cols[i, 1, 0]]
    for a in range(1, cols.shape[2]):
        d0 += coef[i, 0, a] * y[cols[i, 0, a]]
        d1 += coef[i, 1, a] * y[cols[i, 1, a]]
    d0 -= centre[0]
    d1 -= centre[1]
    return d0 ** 2 + d1 ** 2 < r2


@njit(cache=True)
def _local(X, k, centres, prof, c, par, law, Y):
    """H1 outputs ``Y`` (6,) of one contact on shaft ``k`` (``SheaveContact.local`` at zero tilt, times
    ``par[3]``); returns ``(N, |slip|)`` (0, 0 off contact, ``Y`` then zero)."""
    a0, a1 = X[0] - centres[k, 0], X[1] - centres[k, 1]
    a2 = X[2] - X[3]
    r = np.hypot(a0, a1)
    if prof[k, 0] == 0.0:
        f, fp = -r * prof[k, 1], -prof[k, 1]
    else:
        s = (r + prof[k, 2]) / prof[k, 1]
        f = np.sqrt(prof[k, 1] ** 2 - (r + prof[k, 2]) ** 2)
        fp = -(s / np.sqrt(1.0 - s * s))
    delta = f + a2
    if not delta > 0.0:
        for o in range(6):
            Y[o] = 0.0
        return 0.0, 0.0
    g0, g1 = (fp / r) * a0, (fp / r) * a1
    nn = np.sqrt(1.0 + fp * fp)
    n0, n1, n2 = -g0 / nn, -g1 / nn, -1.0 / nn
    N = c[k] * delta * np.sqrt(delta)
    w0 = X[4] + X[8] * a1
    w1 = X[5] - X[8] * a0
    w2 = X[6] - X[7]
    wn = n0 * w0 + n1 * w1 + n2 * w2
    s0, s1, s2 = w0 - wn * n0, w1 - wn * n1, w2 - wn * n2
    speed = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    nf = N * _gain(speed, par[0], par[1], law, par[2])
    f0, f1, f2 = -nf * s0, -nf * s1, -nf * s2
    F0, F1, F2 = -N * g0 + f0, -N * g1 + f1, -N + f2
    m = 2.0 * par[3]
    Y[0], Y[1], Y[2] = m * F0, m * F1, m * F2
    Y[3] = m * -F2
    Y[4] = m * (a1 * F0 - a0 * F1)
    Y[5] = m * (f0 * s0 + f1 * s1 + f2 * s2)
    return N, speed


@njit(cache=True)
def forces(y, cols, coef, shaft, rows, rw, centres, r2, prof, c, par, law, Q, stats):
    """Add the contact forces to ``Q`` (n2,) and return the friction power (W, <= 0); ``stats`` (2, 2) gets per
    shaft the sum of the normal forces and of ``N |slip|`` (N, N m/s)."""
    X, Y = np.zeros(N_IN), np.zeros(N_OUT)
    K = cols.shape[2]
    power = 0.0
    for i in range(cols.shape[0]):
        k = shaft[i]
        if not _near(y, cols, coef, i, centres[k], r2):
            continue
        _inputs(y, cols, coef, i, X)
        N, speed = _local(X, k, centres, prof, c, par, law, Y)
        if N == 0.0:
            continue
        stats[k, 0] += N
        stats[k, 1] += N * speed
        for o in range(N_OUT - 1):
            for a in range(K):
                Q[rows[i, o, a]] += rw[i, o, a] * Y[o]
        power += Y[N_OUT - 1]
    return power


@njit(cache=True)
def local_jacobians(y, cols, coef, shaft, rows, rw, centres, r2, prof, c, par, law, steps):
    """``(pair (m,), Jl (m, 6, 9))``: the candidates and their local Jacobians ``dY/dX`` by central differences with
    ``steps`` (9,)."""
    X, Xs, Yp, Ym = np.zeros(N_IN), np.zeros(N_IN), np.zeros(N_OUT), np.zeros(N_OUT)
    pair, Jl = np.empty(cols.shape[0], np.int64), np.empty((cols.shape[0], N_OUT, N_IN))
    m = 0
    for i in range(cols.shape[0]):
        k = shaft[i]
        if not _near(y, cols, coef, i, centres[k], r2):
            continue
        _inputs(y, cols, coef, i, X)
        for j in range(N_IN):
            Xs[:] = X
            Xs[j] = X[j] + steps[j]
            _local(Xs, k, centres, prof, c, par, law, Yp)
            Xs[j] = X[j] - steps[j]
            _local(Xs, k, centres, prof, c, par, law, Ym)
            for o in range(N_OUT):
                Jl[m, o, j] = (Yp[o] - Ym[o]) / (2 * steps[j])
        pair[m] = i
        m += 1
    return pair[:m], Jl[:m]


@njit(cache=True)
def jacobian(y, cols, coef, shaft, rows, rw, centres, r2, prof, c, par, law, steps, n_state, r_out, c_out, v_out,
             dD):
    """Entries of ``dQ/dy`` of :func:`forces` (over ``y[:n_state]``, the constants dropped) into ``r_out``,
    ``c_out``, ``v_out`` (their count returned) and ``-d(friction power)/dy`` added to ``dD``: the local Jacobians of
    :func:`local_jacobians` mapped on both sides, ``R^T (dY/dX) P`` (``ChainCVT._contact_entries``)."""
    pair, Jl = local_jacobians(y, cols, coef, shaft, rows, rw, centres, r2, prof, c, par, law, steps)
    return scatter_jacobian(pair, Jl, cols, coef, rows, rw, n_state, dD, r_out, c_out, v_out)


@njit(cache=True)
def scatter_forces(pair, R, rows, rw, Q) -> float:
    """Add the local contact outputs ``R`` (m, nf + 1) of the candidates ``pair`` (m,) through their output rows into
    ``Q`` (n2,); return the summed last output (the friction power, W)."""
    K, nf = rows.shape[2], rows.shape[1]
    power = 0.0
    for t in range(pair.shape[0]):
        i = pair[t]
        for o in range(nf):
            for a in range(K):
                Q[rows[i, o, a]] += rw[i, o, a] * R[t, o]
        power += R[t, nf]
    return power


@njit(cache=True)
def scatter_jacobian(pair, Jl, cols, coef, rows, rw, n_state, dD, r_out, c_out, v_out) -> int:
    """Local contact Jacobians ``Jl`` (m, nf + 1, n_in) of the candidates ``pair`` (m,) mapped on both sides into the
    entries ``r_out``, ``c_out``, ``v_out`` of ``dQ/dy`` (over ``y[:n_state]``; their count returned), the last output
    row (the friction power) as ``-d(power)/dy`` added to ``dD``: ``R^T Jl P`` as ``ChainCVT._contact_entries``."""
    K, nf = cols.shape[2], rows.shape[1]
    n = 0
    for t in range(pair.shape[0]):
        i = pair[t]
        for j in range(Jl.shape[2]):
            for b in range(K):
                col, cw = cols[i, j, b], coef[i, j, b]
                if col >= n_state or cw == 0.0:
                    continue
                dD[col] -= cw * Jl[t, nf, j]
                for o in range(nf):
                    for a in range(K):
                        val = rw[i, o, a] * Jl[t, o, j] * cw
                        if val != 0.0:
                            r_out[n], c_out[n], v_out[n] = rows[i, o, a], col, val
                            n += 1
    return n


@njit(cache=True)
def scatter_jacobian_into(pair, Jl, cols, coef, rows, rw, n_state, dD, offsets, data, indptr, row_offset, b_indptr,
                          b_indices, b_data) -> int:
    """:func:`scatter_jacobian` through a map ``B`` straight into the data of a sorted CSR pattern: ``data += B R^T
    Jl P`` (the CSC map ``B (b_indptr, b_indices, b_data)`` spreads output row ``r`` to the pattern's rows
    ``row_offset + b_indices[k]``, which share one column list), with ``offsets (P, nf, K, n_in, K)`` the position of
    each local entry within its first spread row (:func:`cvtfem.assembly.fixed_pattern.pair_offsets`, built once; -1
    outside the pattern): no search per call.  ``dD`` as :func:`scatter_jacobian`'s.  Returns the number of nonzero
    entries that found no place (0: all in)."""
    K, nf = cols.shape[2], rows.shape[1]
    missed = 0
    for t in range(pair.shape[0]):
        i = pair[t]
        for j in range(Jl.shape[2]):
            for b in range(K):
                col, cw = cols[i, j, b], coef[i, j, b]
                if col >= n_state or cw == 0.0:
                    continue
                dD[col] -= cw * Jl[t, nf, j]
                for o in range(nf):
                    for a in range(K):
                        val = rw[i, o, a] * Jl[t, o, j] * cw
                        r = rows[i, o, a]
                        k0, k1 = b_indptr[r], b_indptr[r + 1]
                        if val == 0.0 or k0 == k1:
                            continue
                        p = offsets[i, o, a, j, b]
                        if p < 0:
                            missed += 1
                            continue
                        for k in range(k0, k1):
                            data[indptr[row_offset + b_indices[k]] + p] += b_data[k] * val
    return missed


__all__ = ["STEPS", "forces", "jacobian", "local_jacobians", "pack", "scatter_forces", "scatter_jacobian",
           "scatter_jacobian_into"]
