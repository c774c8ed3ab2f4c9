"""The compiled fill of a fixed CSR pattern against scipy's sparse algebra (its twin)."""
import numpy as np
import scipy.sparse as sp

from cvtfem.assembly import fixed_pattern as FP


def _block_map(rng, n, size=3):
    """A random block-diagonal map (blocks of ``size``) as CSR."""
    return sp.block_diag([rng.normal(size=(size, size)) for _ in range(n // size)], format="csr")


def test_positions_find_every_entry_and_flag_the_absent():
    rng = np.random.default_rng(1)
    P = sp.random(40, 50, density=0.2, random_state=2, format="csr")
    P.sort_indices()
    r, c = P.nonzero()
    pos = FP.positions(P, r, c)
    assert np.array_equal(P.indices[pos], c) and np.all(pos >= P.indptr[r]) and np.all(pos < P.indptr[r + 1])
    dense = P.toarray() != 0
    rr, cc = rng.integers(0, 40, 200), rng.integers(0, 50, 200)
    absent = FP.positions(P, rr, cc) < 0
    assert np.array_equal(absent, ~dense[rr, cc])


def test_csr_matvec_into_a_slice_equals_scipy():
    rng = np.random.default_rng(3)
    B = _block_map(rng, 30)
    x = rng.normal(size=30)
    out = np.full(40, np.nan)
    FP.csr_matvec_into(out, 7, B.indptr, B.indices, B.data, x)
    assert np.allclose(out[7:37], B @ x, rtol=1e-14, atol=0) and np.isnan(out[:7]).all() and np.isnan(out[37:]).all()


def test_mixed_rows_and_mixed_entries_equal_the_sparse_products():
    """``B S`` (rows coupled by ``B`` share columns) and ``B E`` (COO with duplicates) land where scipy puts them, in
    the rows after an offset of a larger pattern; entries outside the pattern are counted, not written."""
    rng = np.random.default_rng(4)
    n, off = 30, 5
    B = _block_map(rng, n)
    blocks = np.arange(n) // 3                    # each block's rows couple to a random set of other blocks
    cols_of = {b: np.sort(rng.choice(n, 8, replace=False)) for b in range(n // 3)}
    rows = np.concatenate([np.full(8, r) for r in range(n)])
    cols = np.concatenate([cols_of[blocks[r]] for r in range(n)])
    S = sp.csr_matrix((rng.normal(size=rows.size), (rows, cols)), shape=(n, n))
    S.sort_indices()
    er, ec = rng.integers(0, n, 60), rng.integers(0, n, 60)
    ev = rng.normal(size=60)
    E = sp.csr_matrix((ev, (er, ec)), shape=(n, n))
    want = (B @ S + B @ E).toarray()
    full = np.zeros((n + off, n))
    full[off:] = 1.0
    P = sp.csr_matrix(full)
    P.sort_indices()
    srow = np.repeat(np.arange(n), np.diff(S.indptr))
    data = np.zeros(P.nnz)
    FP.add_mixed_rows(data, FP.positions(P, off + srow, S.indices), S.data, S.indptr.astype(np.int64),
                      B.indptr.astype(np.int64), B.indices.astype(np.int64), B.data)
    Bc = sp.csc_matrix(B)
    mix = (Bc.indptr.astype(np.int64), Bc.indices.astype(np.int64), Bc.data)
    assert FP.shared_rows(P, off, Bc)
    rows_only = data.copy()
    for shared in (False, True):
        data = rows_only.copy()
        missed = FP.add_mixed_entries(data, P.indptr, P.indices, off, er, ec, ev, *mix, shared)
        got = sp.csr_matrix((data, P.indices, P.indptr), shape=P.shape).toarray()[off:]
        assert missed == 0
        assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max()
    sparse_pattern = sp.csr_matrix(np.eye(n + off, n))
    assert not FP.shared_rows(sparse_pattern, off, Bc)
    assert FP.add_mixed_entries(np.zeros(n + off), sparse_pattern.indptr, sparse_pattern.indices, off, er, ec, ev,
                                *mix, False) > 0


def test_runs_and_mixed_runs_equal_mixed_rows():
    """Rows landing on consecutive positions: :func:`add_mixed_runs` from the run starts equals
    :func:`add_mixed_rows`; a row with a gap (or an empty row list) has no runs."""
    rng = np.random.default_rng(6)
    n = 12
    B = _block_map(rng, n)
    S = sp.csr_matrix((rng.normal(size=n * 5), np.tile(np.arange(5), n), np.arange(0, 5 * n + 1, 5)), shape=(n, 5))
    ptr = S.indptr.astype(np.int64)
    target = (np.arange(n)[:, None] * 9 + 2 + np.arange(5)[None, :]).ravel()   # rows 9 apart, 5 consecutive each
    start = FP.runs(target, ptr)
    assert np.array_equal(start, 9 * np.arange(n) + 2)
    args = (B.indptr.astype(np.int64), B.indices.astype(np.int64), B.data)
    a, b = np.zeros(9 * n + 2), np.zeros(9 * n + 2)
    FP.add_mixed_rows(a, target, S.data, ptr, *args)
    FP.add_mixed_runs(b, start, S.data, ptr, *args)
    assert np.array_equal(a, b) and np.abs(a).max() > 0
    gap = target.copy()
    gap[3] += 1
    assert FP.runs(gap, ptr) is None and FP.runs(np.zeros(0, np.int64), np.zeros(1, np.int64)) is None


def test_compact_equals_eliminate_zeros_and_leaves_the_pattern():
    rng = np.random.default_rng(8)
    A = sp.random(30, 40, density=0.3, random_state=9, format="csr")
    A.sort_indices()
    A.data[rng.random(A.nnz) < 0.4] = 0.0
    A.data[0] = 0.0
    indices, indptr = A.indices.copy(), A.indptr.copy()
    data, ci, cp = FP.compact(A.data, A.indptr, A.indices)
    B = A.copy()
    B.eliminate_zeros()
    assert np.array_equal(data, B.data) and np.array_equal(ci, B.indices) and np.array_equal(cp, B.indptr)
    assert np.array_equal(A.indices, indices) and np.array_equal(A.indptr, indptr)


def test_pair_offsets_and_scatter_into_the_pattern_equal_the_coo_path():
    """A table of local maps (contacts: output rows ``R``, input columns ``P``, duplicates and zero weights) scattered
    ``B R^T Jl P`` straight into the pattern through :func:`pair_offsets` equals its COO entries
    (:func:`sheave_contact_kernel.scatter_jacobian`) through :func:`add_mixed_entries`, and the power rows alike; an
    entry outside the pattern is counted, not written."""
    from cvtfem.elements.chain.sheave_contact_kernel import scatter_jacobian, scatter_jacobian_into
    rng = np.random.default_rng(11)
    n, off, P_, nf, K, n_in = 30, 4, 7, 3, 2, 5
    B = sp.csc_matrix(_block_map(rng, n))
    mix = (B.indptr.astype(np.int64), B.indices.astype(np.int64), B.data)
    cols = rng.integers(0, 2 * n, (P_, n_in, K))
    coef = rng.normal(size=(P_, n_in, K))
    coef[0, 1, 1] = 0.0
    rows = rng.integers(0, n, (P_, nf, K))
    rw = rng.normal(size=(P_, nf, K))
    pair = np.array([5, 1, 3, 1], np.int64)                       # pair 1 twice: its entries add up
    Jl = rng.normal(size=(len(pair), nf + 1, n_in))
    full = np.zeros((n + off, 2 * n))
    full[off:] = 1.0
    Pat = sp.csr_matrix(full)
    Pat.sort_indices()
    size = len(pair) * nf * K * n_in * K
    r, c, d, dD_coo = np.empty(size, np.int64), np.empty(size, np.int64), np.empty(size), np.zeros(2 * n)
    k = scatter_jacobian(pair, Jl, cols, coef, rows, rw, 2 * n, dD_coo, r, c, d)
    want = np.zeros(Pat.nnz)
    assert FP.add_mixed_entries(want, Pat.indptr, Pat.indices, off, r[:k], c[:k], d[:k], *mix, True) == 0
    offsets = FP.pair_offsets(Pat, off, B, cols, rows)
    got, dD = np.zeros(Pat.nnz), np.zeros(2 * n)
    assert scatter_jacobian_into(pair, Jl, cols, coef, rows, rw, 2 * n, dD, offsets, got, Pat.indptr, off, *mix) == 0
    assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max() and np.abs(want).max() > 0
    assert np.array_equal(dD, dD_coo)
    sparse = sp.csr_matrix(np.eye(n + off, 2 * n))                # most entries outside
    offsets = FP.pair_offsets(sparse, off, B, cols, rows)
    assert (offsets < 0).any()
    assert scatter_jacobian_into(pair, Jl, cols, coef, rows, rw, 2 * n, np.zeros(2 * n), offsets,
                                 np.zeros(sparse.nnz), sparse.indptr, off, *mix) > 0
