"""Block-tridiagonal solves of branched networks: the block sweep (spec section 8.2).

The sweep takes a network in through-numbering
(:func:`cvtfem.assembly.numbering.through_numbering`) and eliminates
nodes in reverse through-numbering, each into its parent (the previous chain
node, or the branch node for the first node of a side branch: this is the
source's equilibrium at branch nodes), and back-substitutes in through-numbering
(continuity of displacements at branch nodes).  Cost is linear in the number
of nodes.  Loops (not trees) go to sparse LU.

Block systems are written as node blocks ``N`` (S, B, K, K), link blocks
``L`` (E, B, K, K) for links ``i -> j`` (``j = -1``: ground) and right-hand side
``g`` (S, B, K): ``(N_s + sum_{e at s} L_e) a_s - sum_{e=(s,t)} L_e a_t = g_s``.
``B`` is a batch axis (decoupled harmonics in the linear case).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph
import scipy.sparse.linalg as spla

from cvtfem.assembly.numbering import Topology
from cvtfem.errors import InputError, NumericalError

#: Relative residual above which the sweep result is replaced by sparse LU.
RESIDUAL_LIMIT = 1e-8


def check_grounded(n_nodes: int, i: np.ndarray, j: np.ndarray, k_ground: np.ndarray, names=None) -> None:
    """Every connected part needs a ground link of positive stiffness (harmonic n = 0)."""
    inner = j >= 0
    g = sp.coo_matrix((np.ones(inner.sum()), (i[inner], j[inner])), shape=(n_nodes, n_nodes))
    _, labels = csgraph.connected_components(g, directed=False)
    grounded = np.zeros(labels.max() + 1, bool)
    grounded[labels[i[~inner & (k_ground > 0)]]] = True
    bad = np.flatnonzero(~grounded[labels])
    if bad.size:
        who = names[bad[0]] if names is not None else int(bad[0])
        raise InputError("torsional.link", f"part containing {who!r}",
                         "must have a link to ground (b = \"ground\") with positive stiffness: "
                         "otherwise the mean (n = 0) harmonic is undetermined (spec 8.1, soft clamp)")


def _scatter(rows: np.ndarray, n_rows: int) -> sp.csr_matrix:
    """Sparse 0/1 matrix summing entries ``k`` into row ``rows[k]`` (replaces slow ``np.add.at``)."""
    return sp.csr_matrix((np.ones(len(rows)), (rows, np.arange(len(rows)))), shape=(n_rows, len(rows)))


def diagonal_blocks(N: np.ndarray, L: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """``G0_s = N_s + sum of the blocks of links at s`` (S, B, K, K)."""
    inner = j >= 0
    ends = np.concatenate([i, j[inner]])
    blocks = np.concatenate([L, L[inner]]).reshape(len(ends), -1)
    return N + (_scatter(ends, N.shape[0]) @ blocks).reshape(N.shape)


def apply(N: np.ndarray, L: np.ndarray, i: np.ndarray, j: np.ndarray, a: np.ndarray,
          G0: np.ndarray | None = None) -> np.ndarray:
    """Matrix-vector product of the block system with ``a`` (S, B, K); ``G0``: precomputed diagonal blocks."""
    G0 = diagonal_blocks(N, L, i, j) if G0 is None else G0
    out = np.einsum("sbkl,sbl->sbk", G0, a)
    inner = j >= 0
    if not inner.any():
        return out
    Li, ii, jj = L[inner], i[inner], j[inner]
    coupled = np.concatenate([np.einsum("ebkl,ebl->ebk", Li, a[jj]), np.einsum("ebkl,ebl->ebk", Li, a[ii])])
    return out - (_scatter(np.concatenate([ii, jj]), a.shape[0]) @ coupled.reshape(len(coupled), -1)).reshape(a.shape)


def assemble(N: np.ndarray, L: np.ndarray, i: np.ndarray, j: np.ndarray, batch: int) -> sp.csc_matrix:
    """Sparse matrix (S K x S K) of batch member ``batch`` (COO -> CSC in one call)."""
    S, K = N.shape[0], N.shape[-1]
    G = diagonal_blocks(N, L, i, j)[:, batch]
    inner = j >= 0
    Lb = -L[inner, batch]
    kk, ll = np.meshgrid(np.arange(K), np.arange(K), indexing="ij")
    blocks = [(np.arange(S), np.arange(S), G), (i[inner], j[inner], Lb), (j[inner], i[inner], Lb)]
    rows = np.concatenate([(r[:, None, None] * K + kk).ravel() for r, _, _ in blocks])
    cols = np.concatenate([(c[:, None, None] * K + ll).ravel() for _, c, _ in blocks])
    vals = np.concatenate([v.ravel() for _, _, v in blocks])
    return sp.csc_matrix((vals, (rows, cols)), shape=(S * K, S * K))


def solve_sparse(N, L, i, j, g) -> np.ndarray:
    """Solve by sparse LU (SuperLU), one factorisation per batch member."""
    S, B, K = g.shape
    a = np.empty_like(g, dtype=complex)
    for bb in range(B):
        try:
            lu = spla.splu(assemble(N, L, i, j, bb))
        except RuntimeError as err:   # SuperLU: "Factor is exactly singular"
            raise NumericalError(f"the harmonic-balance Newton system is singular ({err}): a group of disks has no "
                                 "stiffness to ground in its current contact state (an open gap with zero "
                                 "`gap_stiffness`?)", component="periodic.blocktri") from None
        a[:, bb] = lu.solve(g[:, bb].reshape(-1)).reshape(S, K)
    return a


def _diagonal(blocks: np.ndarray) -> np.ndarray:
    """Which blocks (n, B, K, K) are diagonal."""
    K = blocks.shape[-1]
    off = blocks.reshape(blocks.shape[0], -1)[:, :-1].reshape(blocks.shape[0], -1, K + 1)[:, :, 1:]
    return ~np.any(off != 0, axis=(1, 2)) if K > 1 else np.ones(blocks.shape[0], bool)


def block_sweep(topo: Topology, N: np.ndarray, L: np.ndarray, i: np.ndarray, j: np.ndarray,
                g: np.ndarray, G0: np.ndarray | None = None) -> np.ndarray:
    """Tree block elimination (the modified vector sweep, spec 8.2).

    Forward: ``X_s = G_s^-1 L_s``, ``y_s = G_s^-1 g_s`` (one LU per block, via
    ``numpy.linalg.solve``), ``G_p -= L_s X_s``, ``g_p += L_s y_s``; back:
    ``a_s = y_s + X_s a_p``.  Nodes whose blocks stay diagonal (linear links
    away from the root's nonlinear ones) are eliminated with O(K) vector
    operations instead of O(K^3).  ``G0``: precomputed :func:`diagonal_blocks`.
    Returns ``a`` (S, B, K).
    """
    G = diagonal_blocks(N, L, i, j) if G0 is None else G0.copy()
    g = g.astype(complex, copy=True)
    S, B, K = g.shape
    X = np.zeros((S, B, K, K), complex)
    y = np.empty((S, B, K), complex)
    Lp = np.zeros((S, B, K, K), complex)
    has = topo.parent_link >= 0
    Lp[has] = L[topo.parent_link[has]]
    dense = ~_diagonal(G)
    dense_link = ~_diagonal(Lp)
    parent = topo.parent
    diag = np.arange(K)
    rhs = np.empty((B, K, K + 1), complex)
    for s in topo.order[::-1]:
        p = parent[s]
        if dense[s] or dense_link[s]:
            rhs[..., :K] = Lp[s]
            rhs[..., K] = g[s]
            sol = np.linalg.solve(G[s], rhs)
            X[s], y[s] = sol[..., :K], sol[..., K]
            if p >= 0:
                G[p] -= Lp[s] @ X[s]
                g[p] += np.einsum("bkl,bl->bk", Lp[s], y[s])
                dense[p] = True
        else:
            Gd, Ld = G[s][:, diag, diag], Lp[s][:, diag, diag]
            X[s][:, diag, diag] = Ld / Gd
            y[s] = g[s] / Gd
            if p >= 0:
                G[p][:, diag, diag] -= Ld * Ld / Gd
                g[p] += Ld * y[s]
    a = np.empty_like(y)
    for s in topo.order:
        p = parent[s]
        a[s] = y[s] if p < 0 else y[s] + np.einsum("bkl,bl->bk", X[s], a[p])
    return a


def solve_blocks(N: np.ndarray, L: np.ndarray, i: np.ndarray, j: np.ndarray, g: np.ndarray,
                 topo: Topology | None, method: str = "auto") -> tuple[np.ndarray, str]:
    """Solve the block system; returns ``(a, method_used)``.

    ``method``: "sweep" (trees only), "sparse" or "auto" (sweep, checked by its
    residual, falling back to sparse LU; sparse LU for loops).
    """
    if method not in ("auto", "sweep", "sparse"):
        raise InputError("method", method, "must be 'auto', 'sweep' or 'sparse'")
    if method == "sweep" and topo is None:
        raise InputError("method", method, "needs a tree network (this one has a loop); use 'sparse'")
    if topo is not None and method != "sparse":
        G0 = diagonal_blocks(N, L, i, j)
        with np.errstate(all="ignore"):
            try:
                a = block_sweep(topo, N, L, i, j, g, G0)
            except np.linalg.LinAlgError:
                a = np.full_like(g, np.nan, dtype=complex)
        res = np.linalg.norm(apply(N, L, i, j, a, G0) - g) if np.all(np.isfinite(a)) else np.inf
        if res <= RESIDUAL_LIMIT * max(np.linalg.norm(g), 1e-300) or method == "sweep":
            return a, "sweep"
    a = solve_sparse(N, L, i, j, g)
    if not np.all(np.isfinite(a)):
        raise NumericalError("the harmonic-balance system is singular (check damping and ground links)",
                             component="periodic block solve")
    return a, "sparse"


def _mixed_ends(i: np.ndarray, j: np.ndarray, vals: np.ndarray, S: int) -> np.ndarray:
    """Sum ``vals`` (E, K) of links into both their end nodes (S, K) (ground ends dropped)."""
    inner = j >= 0
    ends = np.concatenate([i, j[inner]])
    return (_scatter(ends, S) @ np.concatenate([vals, vals[inner]]))


def apply_mixed(Nd, Ld, dense, Ldense, i, j, a) -> np.ndarray:
    """:func:`apply` for mixed storage (see :func:`solve_mixed`), one batch member: ``a`` (S, K)."""
    S = a.shape[0]
    ja = np.where(j >= 0, j, 0)
    aj = np.where((j >= 0)[:, None], a[ja], 0)
    dl = a[i] - aj  # link deflection harmonics (E, K)
    flux = Ld * dl
    if dense.size:
        flux[dense] = np.einsum("ekl,el->ek", Ldense, dl[dense])
    out = Nd * a + _scatter(i, S) @ flux
    inner = j >= 0
    return out - _scatter(j[inner], S) @ flux[inner]


def _to_real_vec(v: np.ndarray) -> np.ndarray:
    """Harmonics ``n = -N..N`` (..., K) of a real signal -> real unitary cos/sin coordinates (..., K).

    Order ``[z_0, c_1, s_1, ..., c_N, s_N]`` with ``z_n = (c_n - i s_n) / sqrt 2``,
    ``z_-n = (c_n + i s_n) / sqrt 2`` (the map ``T`` is unitary).  A non-conjugate-symmetric
    part of ``v`` (round-off) is dropped.
    """
    K = v.shape[-1]
    N = (K - 1) // 2
    pos, neg = v[..., N + 1:], v[..., N - 1::-1]
    out = np.empty(v.shape, float)
    out[..., 0] = v[..., N].real
    out[..., 1::2] = ((pos + neg) / np.sqrt(2)).real
    out[..., 2::2] = (1j * (pos - neg) / np.sqrt(2)).real
    return out


def _from_real_vec(w: np.ndarray) -> np.ndarray:
    """Inverse of :func:`_to_real_vec`: ``T w`` (..., K) complex."""
    K = w.shape[-1]
    N = (K - 1) // 2
    z = np.empty(w.shape, complex)
    z[..., N] = w[..., 0]
    c, s = w[..., 1::2], w[..., 2::2]
    z[..., N + 1:] = (c - 1j * s) / np.sqrt(2)
    z[..., N - 1::-1] = (c + 1j * s) / np.sqrt(2)
    return z


def _to_real_mat(A: np.ndarray) -> np.ndarray:
    """``T^H A T`` (K, K), real for a block of a real operator (``A_{-n,-m} = conj A_{n,m}``)."""
    B = _to_real_vec_cols(A)
    return _to_real_rows(B)


def _to_real_vec_cols(A: np.ndarray) -> np.ndarray:
    """``A T`` (complex): columns combined as in :func:`_from_real_vec`."""
    K = A.shape[-1]
    N = (K - 1) // 2
    out = np.empty(A.shape, complex)
    pos, neg = A[:, N + 1:], A[:, N - 1::-1]
    out[:, 0] = A[:, N]
    out[:, 1::2] = (pos + neg) / np.sqrt(2)
    out[:, 2::2] = (-1j * pos + 1j * neg) / np.sqrt(2)
    return out


def _to_real_rows(B: np.ndarray) -> np.ndarray:
    """``T^H B`` (real part): rows combined as in :func:`_to_real_vec`."""
    K = B.shape[0]
    N = (K - 1) // 2
    out = np.empty(B.shape, float)
    pos, neg = B[N + 1:], B[N - 1::-1]
    out[0] = B[N].real
    out[1::2] = ((pos + neg) / np.sqrt(2)).real
    out[2::2] = (1j * (pos - neg) / np.sqrt(2)).real
    return out


def _diag_to_real(d: np.ndarray) -> np.ndarray:
    """``T^H diag(d) T`` (K, K) real (2 x 2 blocks per harmonic pair) for ``d_-n = conj d_n``."""
    K = d.shape[-1]
    N = (K - 1) // 2
    out = np.zeros((K, K))
    out[0, 0] = d[N].real
    dp = d[N + 1:]
    k = np.arange(1, K, 2)
    out[k, k] = dp.real
    out[k + 1, k + 1] = dp.real
    out[k, k + 1] = dp.imag
    out[k + 1, k] = -dp.imag
    return out


def block_sweep_mixed(topo: Topology, Nd, Ld, dense, Ldense, i, j, g) -> np.ndarray:
    """:func:`block_sweep` for one batch member with mixed storage: diagonal blocks as vectors.

    ``Nd`` (S, K) node diagonals, ``Ld`` (E, K) link diagonals, ``dense`` (Ed,) indices of
    links with full blocks ``Ldense`` (Ed, K, K) (their ``Ld`` rows are ignored), ``g`` (S, K).
    Dense storage only where the elimination fills in.  All blocks are those of a real
    operator in harmonics ``n = -N..N`` (``A_{-n,-m} = conj A_{n,m}``), so the dense
    eliminations run in the unitary real cos/sin basis (:func:`_to_real_vec`): real LU
    and products, about 4x less work than complex.  Returns the conjugate-symmetric
    solution ``a`` (S, K) (for a conjugate-symmetric ``g``).
    """
    S, K = g.shape
    Ld = np.array(Ld, complex)
    Ld[dense] = 0
    Gd = Nd + _mixed_ends(i, j, Ld, S)
    g = g.astype(complex, copy=True)
    full: dict[int, np.ndarray] = {}  # real-basis dense blocks
    link_full = {int(e): _to_real_mat(Ldense[k]) for k, e in enumerate(dense.tolist())}
    for e in link_full:
        for s in (int(i[e]), int(j[e])):
            if s < 0:
                continue
            if s not in full:
                full[s] = _diag_to_real(Gd[s])
            full[s] += link_full[e]
    X: dict[int, np.ndarray] = {}
    y = np.empty((S, K), complex)
    parent = topo.parent
    for s in topo.order[::-1].tolist():
        p = int(parent[s])
        e = int(topo.parent_link[s])
        Lfull = link_full.get(e) if e >= 0 else None
        if s in full or Lfull is not None:
            G = full[s] if s in full else _diag_to_real(Gd[s])
            Lp = Lfull if Lfull is not None else (_diag_to_real(Ld[e]) if e >= 0 else np.zeros((K, K)))
            sol = np.linalg.solve(G, np.concatenate([Lp, _to_real_vec(g[s])[:, None]], axis=1))
            X[s], yr = sol[:, :K], sol[:, K]
            y[s] = _from_real_vec(yr)
            if p >= 0:
                if p not in full:
                    full[p] = _diag_to_real(Gd[p])
                full[p] -= Lp @ X[s]
                g[p] += _from_real_vec(Lp @ yr)
        else:
            Ls = Ld[e] if e >= 0 else np.zeros(K, complex)
            X[s] = Ls / Gd[s]
            y[s] = g[s] / Gd[s]
            if p >= 0:
                if p in full:
                    full[p] -= _diag_to_real(Ls * Ls / Gd[s])
                else:
                    Gd[p] -= Ls * Ls / Gd[s]
                g[p] += Ls * y[s]
    a = np.empty_like(y)
    for s in topo.order.tolist():
        p = int(parent[s])
        if p < 0:
            a[s] = y[s]
        elif X[s].ndim == 2:
            a[s] = y[s] + _from_real_vec(X[s] @ _to_real_vec(a[p]))
        else:
            a[s] = y[s] + X[s] * a[p]
    return a


def solve_mixed(Nd, Ld, dense, Ldense, i, j, g, topo: Topology | None, method: str = "auto") -> tuple[np.ndarray, str]:
    """:func:`solve_blocks` for one batch member with mixed storage (see :func:`block_sweep_mixed`).

    Same policy: sweep checked by its residual, sparse LU (on the full blocks) as the fallback.
    """
    if method not in ("auto", "sweep", "sparse"):
        raise InputError("method", method, "must be 'auto', 'sweep' or 'sparse'")
    if method == "sweep" and topo is None:
        raise InputError("method", method, "needs a tree network (this one has a loop); use 'sparse'")
    if topo is not None and method != "sparse":
        with np.errstate(all="ignore"):
            try:
                a = block_sweep_mixed(topo, Nd, Ld, dense, Ldense, i, j, g)
            except np.linalg.LinAlgError:
                a = np.full_like(g, np.nan, dtype=complex)
            res = np.linalg.norm(apply_mixed(Nd, Ld, dense, Ldense, i, j, a) - g) if np.all(np.isfinite(a)) \
                else np.inf
        if res <= RESIDUAL_LIMIT * max(np.linalg.norm(g), 1e-300) or method == "sweep":
            return a, "sweep"
    S, K = g.shape
    diag = np.arange(K)
    Nb = np.zeros((S, 1, K, K), complex)
    Nb[:, 0, diag, diag] = Nd
    L = np.zeros((len(i), 1, K, K), complex)
    L[:, 0, diag, diag] = Ld
    L[dense, 0] = Ldense
    a = solve_sparse(Nb, L, i, j, g[:, None])[:, 0]
    if not np.all(np.isfinite(a)):
        raise NumericalError("the harmonic-balance system is singular (check damping and ground links)",
                             component="periodic block solve")
    return a, "sparse"
