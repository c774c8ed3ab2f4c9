"""The slip maps' helpers: the kept rows of a summed CSR pattern (against scipy) and the tangent-plane basis of
:func:`half_end_slips._plane` (orthonormal, spanning the slips, its choice not hanging on round-off in a tie)."""
import numpy as np
import scipy.sparse as sp

from cvtfem.elements.chain.half_end_slips import _plane
from cvtfem.elements.chain.halves_slips_kernel import kept_rows


def test_kept_rows_equal_scipys_summed_and_sliced_matrix():
    rng = np.random.default_rng(3)
    rows, cols = rng.integers(0, 40, 600), rng.integers(0, 90, 600)
    key = rows * 90 + cols
    unique, where = np.unique(key, return_inverse=True)
    indptr = np.searchsorted(unique // 90, np.arange(41))
    vals = rng.standard_normal(600)
    keep = np.flatnonzero(rng.random(40) < 0.6)
    data, ind, ptr = kept_rows(where, vals, unique % 90, indptr, keep)
    B = sp.csr_matrix((data, ind, ptr), shape=(len(keep), 90))
    ref = sp.csr_matrix((vals, (rows, cols)), shape=(40, 90))[keep]
    assert B.has_sorted_indices and np.array_equal(B.indptr, ref.indptr) and np.array_equal(B.indices, ref.indices)
    assert np.abs(B.toarray() - ref.toarray()).max() <= 1e-14 * np.abs(vals).max()


def test_plane_basis_spans_the_slips_and_breaks_ties_by_order():
    n = np.array([0.3, -0.4, 0.5]) / np.linalg.norm([0.3, -0.4, 0.5])
    rng = np.random.default_rng(5)
    V = rng.standard_normal((6, 3))
    V -= np.outer(V @ n, n)                          # in the plane normal to n
    V[4] = -V[2] * (1 + 1e-15)                       # a rate and its sheave's opposite one: a tie up to round-off
    V[2] *= 10
    V[4] *= 10
    basis = np.empty((2, 3))
    _plane(V, basis)
    assert np.abs(basis @ basis.T - np.eye(2)).max() < 1e-15
    assert np.abs(V - (V @ basis.T) @ basis).max() < 1e-14 * np.abs(V).max()       # spans every slip
    assert np.allclose(basis[0], V[2] / np.linalg.norm(V[2]), rtol=0, atol=1e-15)    # the first of the tie
    W = V.copy()
    W[2] *= 1 - 1e-15                                # the tie's round-off the other way: the same basis
    basis2 = np.empty((2, 3))
    _plane(W, basis2)
    assert np.abs(basis2 - basis).max() < 1e-14
