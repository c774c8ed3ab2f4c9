"""Compiled (numba) kernels that write a model's sparse Jacobian into the data of a fixed, sorted CSR pattern.

A model builds its pattern and the positions of its constant parts once; per call the kernels add values in place:
:func:`add_mixed_rows` (a block-diagonal map ``B`` times a matrix whose rows in each block share one column list,
as ``M^-1 dQ/dq`` of a chain family), :func:`add_mixed_runs` (the same where each row lands on consecutive
positions), :func:`add_mixed_entries` (``B`` times COO entries, located by binary search) and
:func:`csr_matvec_into` (``B x`` into a slice); :func:`compact` drops the entries left zero; :func:`pair_offsets`
places a table of local maps (contacts) in the pattern once.  Their numpy twin is
scipy's sparse algebra (``tests/assembly/test_fixed_pattern.py``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.elements.jit import njit


def positions(pattern: sp.csr_matrix, rows, cols) -> np.ndarray:
    """Positions (int64) of the entries ``(rows, cols)`` in the data of the sorted CSR ``pattern``; -1 where the
    pattern has no such entry."""
    rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
    start, stop = pattern.indptr[rows], pattern.indptr[rows + 1]
    out = np.full(rows.shape, -1, np.int64)
    if rows.size:
        _search(pattern.indices, start.astype(np.int64), stop.astype(np.int64), cols, out)
    return out


@njit(cache=True)
def _search(indices, start, stop, cols, out):
    for i in range(cols.shape[0]):
        out[i] = _find(indices, start[i], stop[i], cols[i])


@njit(cache=True)
def _find(indices, lo, hi, col):
    """Position of ``col`` in the sorted ``indices[lo:hi]``, or -1."""
    while lo < hi:
        mid = (lo + hi) // 2
        c = indices[mid]
        if c < col:
            lo = mid + 1
        elif c > col:
            hi = mid
        else:
            return mid
    return -1


@njit(cache=True)
def csr_matvec_into(out, offset, indptr, indices, data, x):
    """``out[offset + r] = (B x)[r]`` for the CSR matrix ``B (indptr, indices, data)``."""
    for r in range(indptr.shape[0] - 1):
        s = 0.0
        for k in range(indptr[r], indptr[r + 1]):
            s += data[k] * x[indices[k]]
        out[offset + r] = s


@njit(cache=True)
def add_mixed_rows(data, target, src, src_indptr, b_indptr, b_indices, b_data):
    """``data[target[k]] += (B S)`` entry ``k`` for a matrix ``S`` given by its CSR data ``src`` (row ``s`` at
    ``src[src_indptr[s]:src_indptr[s + 1]]``) whose rows coupled by the CSR map ``B`` have the same column list:
    row ``r`` of ``B S`` is ``sum_s B[r, s] S[s, :]`` on row ``r``'s columns, and ``target`` holds, per entry of
    ``S``, its position in ``data``."""
    for r in range(src_indptr.shape[0] - 1):
        a, length = src_indptr[r], src_indptr[r + 1] - src_indptr[r]
        for k in range(b_indptr[r], b_indptr[r + 1]):
            b, s0 = b_data[k], src_indptr[b_indices[k]]
            for j in range(length):
                data[target[a + j]] += b * src[s0 + j]


@njit(cache=True)
def add_mixed_runs(data, start, src, src_indptr, b_indptr, b_indices, b_data):
    """:func:`add_mixed_rows` where each row's entries land on consecutive positions of ``data``, from ``start[r]``:
    each row summed in a scratch row first, then added (contiguous updates the compiler vectorises; accumulating in
    ``data`` itself took 1.07 ms against 0.78 for the A5 chain's two matrices)."""
    n = src_indptr.shape[0] - 1
    width = 0
    for r in range(n):
        width = max(width, src_indptr[r + 1] - src_indptr[r])
    row = np.empty(width)
    for r in range(n):
        t, length = start[r], src_indptr[r + 1] - src_indptr[r]
        row[:length] = 0.0
        for k in range(b_indptr[r], b_indptr[r + 1]):
            b, s0 = b_data[k], src_indptr[b_indices[k]]
            for j in range(length):
                row[j] += b * src[s0 + j]
        for j in range(length):
            data[t + j] += row[j]


def runs(target: np.ndarray, indptr: np.ndarray) -> np.ndarray | None:
    """The start of each row's run in ``target`` (positions of the rows ``indptr`` delimits) where every row lands on
    consecutive positions (:func:`add_mixed_runs`), else None."""
    ptr = np.asarray(indptr, np.int64)
    if len(target) == 0:
        return None
    inner = np.ones(len(target), bool)
    inner[ptr[:-1][np.diff(ptr) > 0]] = False                   # a row's first entry starts a new run
    if not np.all(np.diff(target)[inner[1:]] == 1):
        return None
    return target[np.minimum(ptr[:-1], len(target) - 1)].astype(np.int64)


@njit(cache=True)
def add_mixed_entries(data, indptr, indices, row_offset, rows, cols, vals, b_indptr, b_indices, b_data, shared):
    """``data += B E`` of the COO entries ``E (rows, cols, vals)`` through the CSC map ``B (b_indptr, b_indices,
    b_data)`` (column ``r`` of ``B`` spreads row ``r`` of ``E``), into the rows ``row_offset + r'`` of the sorted CSR
    pattern ``(indptr, indices)``; with ``shared`` the rows each column of ``B`` spreads to have one column list in the
    pattern (:func:`shared_rows`), so one search serves them all.  Returns the number of nonzero entries that found no
    place in the pattern (0: all in)."""
    missed = 0
    for i in range(rows.shape[0]):
        r, c, d = rows[i], cols[i], vals[i]
        k0, k1 = b_indptr[r], b_indptr[r + 1]
        if k0 == k1:
            continue
        r0 = row_offset + b_indices[k0]
        p0 = _find(indices, indptr[r0], indptr[r0 + 1], c)
        for k in range(k0, k1):
            rr = row_offset + b_indices[k]
            p = p0 - indptr[r0] + indptr[rr] if shared else _find(indices, indptr[rr], indptr[rr + 1], c)
            if p0 >= 0 and p >= 0:
                data[p] += b_data[k] * d
            elif d != 0.0:
                missed += 1
    return missed


@njit(cache=True)
def compact(data, indptr, indices):
    """New CSR arrays ``(data, indices, indptr)`` of the entries of ``data`` (on the pattern ``(indptr, indices)``)
    that are not zero, in their order: what ``eliminate_zeros`` of a copy gives, in one pass."""
    keep = 0
    for k in range(data.shape[0]):
        if data[k] != 0.0:
            keep += 1
    out_data, out_indices = np.empty(keep), np.empty(keep, indices.dtype)
    out_indptr = np.empty(indptr.shape[0], indptr.dtype)
    n = 0
    out_indptr[0] = 0
    for r in range(indptr.shape[0] - 1):
        for k in range(indptr[r], indptr[r + 1]):
            if data[k] != 0.0:
                out_data[n], out_indices[n] = data[k], indices[k]
                n += 1
        out_indptr[r + 1] = n
    return out_data, out_indices, out_indptr


def shared_rows(pattern: sp.csr_matrix, row_offset: int, b: sp.csc_matrix) -> bool:
    """Whether the rows ``row_offset + r'`` of ``pattern`` that each column of ``b`` spreads to share one column list
    (:func:`add_mixed_entries`'s ``shared``)."""
    ptr, idx = pattern.indptr, pattern.indices
    for r in range(b.shape[1]):
        spread = row_offset + b.indices[b.indptr[r]:b.indptr[r + 1]]
        if len(spread) > 1:
            first = idx[ptr[spread[0]]:ptr[spread[0] + 1]]
            if not all(np.array_equal(idx[ptr[s]:ptr[s + 1]], first) for s in spread[1:]):
                return False
    return True


def pair_offsets(pattern: sp.csr_matrix, row_offset: int, b: sp.csc_matrix, cols, rows) -> np.ndarray:
    """Offsets (int64, ``(P, nf, K, n_in, K)``) of the local entries ``(rows[i, o, a], cols[i, j, b])`` of a table of
    ``P`` local maps within the first pattern row that column ``rows[i, o, a]`` of the CSC map ``b`` spreads to
    (``row_offset + b.indices[b.indptr[r]]``; the rows it spreads to must share one column list,
    :func:`shared_rows`); -1 where that row has no such column, 0 where ``b`` spreads the row nowhere.  The
    position table of :func:`cvtfem.elements.chain.sheave_contact_kernel.scatter_jacobian_into`, built once."""
    rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
    P, nf, K = rows.shape
    n_in = cols.shape[1]
    spread = np.diff(b.indptr)[rows] > 0                                    # (P, nf, K)
    r0 = row_offset + b.indices[np.minimum(b.indptr[rows], len(b.indices) - 1)]
    rr = np.broadcast_to(r0[:, :, :, None, None], (P, nf, K, n_in, K))
    cc = np.broadcast_to(cols[:, None, None, :, :], (P, nf, K, n_in, K))
    pos = positions(pattern, rr.ravel(), cc.ravel()).reshape(rr.shape)
    off = np.where(pos >= 0, pos - pattern.indptr[rr], -1)
    return np.ascontiguousarray(np.where(spread[:, :, :, None, None], off, 0), np.int64)


__all__ = ["add_mixed_entries", "add_mixed_rows", "add_mixed_runs", "compact", "csr_matvec_into", "pair_offsets",
           "positions", "runs", "shared_rows"]
