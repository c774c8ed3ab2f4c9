"""The symmetric slip matrix ``C = I + h E K E`` of the implicit friction and its sparse LDL^T on a fixed pattern.

``K`` (sparse, symmetric, m x m; m/s per N here: a slip-space inverse mass ``S M^-1 S^T``) and ``E`` (block diagonal
by contact, symmetric blocks of ``sizes`` rows: the square root of the friction's slope blocks) fix ``C``, symmetric
positive definite.  :class:`SlipCholesky` does the symbolic work once per pattern of ``K`` (the fill-reducing order,
the elimination tree, where each product ``E K E`` lands in ``C``'s upper triangle) and each :meth:`SlipCholesky.factor`
only the numeric LDL^T (compiled, the up-looking algorithm of QDLDL: Stellato et al., the OSQP solver).  Units: those
of ``K`` times ``h E^2`` cancel (``C`` is dimensionless).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.elements.jit import njit
from cvtfem.errors import NumericalError

__all__ = ["SlipCholesky", "distinct", "fill_reducing_order"]


@njit(cache=True)
def _etree(Ap, Ai, Lnz, parent, work):
    """Elimination tree ``parent`` and the column counts ``Lnz`` of ``L`` from the upper triangle (CSC, diagonal
    included) of a symmetric matrix."""
    n = Lnz.shape[0]
    for i in range(n):
        work[i], Lnz[i], parent[i] = -1, 0, -1
    for j in range(n):
        work[j] = j
        for p in range(Ap[j], Ap[j + 1]):
            i = Ai[p]
            while work[i] != j:
                if parent[i] == -1:
                    parent[i] = j
                Lnz[i] += 1
                work[i] = j
                i = parent[i]


@njit(cache=True)
def _fill(Cx, tgt, i1, entry, i2, Kx, E, h, diag):
    """``C``'s upper triangle: ``h E[i1] K[entry] E[i2]`` summed into ``tgt``, plus the identity."""
    Cx[:] = 0.0
    for k in range(tgt.shape[0]):
        Cx[tgt[k]] += h * E[i1[k]] * Kx[entry[k]] * E[i2[k]]
    for i in range(diag.shape[0]):
        Cx[diag[i]] += 1.0


@njit(cache=True)
def _ldl(Ap, Ai, Ax, parent, Lp, Li, Lx, D, y, mark, stack, reach, nxt):
    """``A = L D L^T`` (``L`` unit lower, CSC without its diagonal, on ``Lp`` from :func:`_etree`).  Returns the first
    column with a pivot ``<= 0`` or -1."""
    n = D.shape[0]
    for i in range(n):
        nxt[i], mark[i], y[i] = Lp[i], False, 0.0
    for k in range(n):
        top, D[k] = 0, 0.0
        for p in range(Ap[k], Ap[k + 1]):
            i = Ai[p]
            if i == k:
                D[k] = Ax[p]
                continue
            y[i] = Ax[p]
            if mark[i]:
                continue
            depth = 0
            while i != -1 and i < k and not mark[i]:                 # the path up the tree to a marked node
                mark[i] = True
                stack[depth] = i
                depth += 1
                i = parent[i]
            while depth > 0:
                depth -= 1
                reach[top] = stack[depth]
                top += 1
        for t in range(top - 1, -1, -1):
            j = reach[t]
            yj = y[j]
            for p in range(Lp[j], nxt[j]):
                y[Li[p]] -= Lx[p] * yj
            q = nxt[j]
            Li[q], Lx[q] = k, yj / D[j]
            D[k] -= yj * Lx[q]
            nxt[j] += 1
            y[j], mark[j] = 0.0, False
        if not D[k] > 0.0:
            return k
    return -1


@njit(cache=True)
def _ldl_forward(Lp, Li, Lx, X):
    """``X <- L^-1 X`` in place, ``X`` (n, columns)."""
    n, k = X.shape
    for i in range(n):
        for p in range(Lp[i], Lp[i + 1]):
            for c in range(k):
                X[Li[p], c] -= Lx[p] * X[i, c]


@njit(cache=True)
def _ldl_forward_sparse(Lp, Li, Lx, XT):
    """``X <- L^-1 X`` in place for sparse columns, ``XT`` (columns, n) ``X``'s transpose: each column skips its
    zeros (exactly: their updates vanish)."""
    k, n = XT.shape
    for c in range(k):
        x = XT[c]
        for i in range(n):
            xi = x[i]
            if xi != 0.0:
                for p in range(Lp[i], Lp[i + 1]):
                    x[Li[p]] -= Lx[p] * xi


@njit(cache=True)
def _ldl_backward(Lp, Li, Lx, X):
    """``X <- L^-T X`` in place, ``X`` (n, columns)."""
    n, k = X.shape
    for i in range(n - 1, -1, -1):
        for p in range(Lp[i], Lp[i + 1]):
            for c in range(k):
                X[i, c] -= Lx[p] * X[Li[p], c]


@njit(cache=True)
def _ldl_solve(Lp, Li, Lx, D, X):
    """``X <- (L D L^T)^-1 X`` in place, ``X`` (n, columns)."""
    _ldl_forward(Lp, Li, Lx, X)
    for i in range(X.shape[0]):
        for c in range(X.shape[1]):
            X[i, c] /= D[i]
    _ldl_backward(Lp, Li, Lx, X)


@njit(cache=True)
def _blocks_times(E, boff, first, sizes, X, out):
    """``out = E X``, ``E`` block diagonal (blocks flattened row-major from ``boff``), ``X`` (m, columns)."""
    for g in range(sizes.shape[0]):
        d, f, o = sizes[g], first[g], boff[g]
        for a in range(d):
            for c in range(X.shape[1]):
                acc = 0.0
                for b in range(d):
                    acc += E[o + a * d + b] * X[f + b, c]
                out[f + a, c] = acc


@njit(cache=True)
def _csr_times(indptr, indices, data, x, out):
    for r in range(indptr.shape[0] - 1):
        acc = 0.0
        for p in range(indptr[r], indptr[r + 1]):
            acc += data[p] * x[indices[p]]
        out[r] = acc


@njit(cache=True)
def _factor(sym, Lp, Li, Lx, D, work, Cx, Kx, h, E, U, Mb, YT, YD, A):
    """The LDL^T of ``C`` (:class:`SlipCholesky`'s arrays ``sym``) for ``K``'s data ``Kx``, ``h`` and blocks ``E``,
    and the border's part of the Woodbury update: ``YT`` (r, m) ``= (L^-1 P E U)^T``, ``YD = YT D^-1`` and
    ``A = I + h Mb Y^T D^-1 Y`` (r, r).  Returns the first bad pivot or -1."""
    Ap, Ai, parent, tgt, i1, entry, i2, diag, perm, sizes, first, boff = sym
    _fill(Cx, tgt, i1, entry, i2, Kx, E, h, diag)
    bad = _ldl(Ap, Ai, Cx, parent, Lp, Li, Lx, D, *work)
    if bad >= 0:
        return bad
    m, r = U.shape
    if r > 0:                                                # the border's columns: sparse (each sheave's contacts)
        EU = np.empty((m, r))
        _blocks_times(E, boff, first, sizes, U, EU)
        for i in range(m):
            for c in range(r):
                YT[c, perm[i]] = EU[i, c]
        _ldl_forward_sparse(Lp, Li, Lx, YT)
        YD[:, :] = YT / D.reshape(1, m)
        A[:, :] = np.eye(r) + (h * Mb) @ (YD @ YT.T)
    return -1


@njit(cache=True)
def _solve(sym, Lp, Li, Lx, D, h, E, g, Mi, S, St, YT, YD, A, Mb, dv, ds):
    """The Newton direction ``dv = -y + h Mi S^T E z`` (``y = Mi g``, ``(C + h EU Mb (EU)^T) z = E S y``) and ``ds = S
    dv`` on :func:`_factor`'s ``L``, ``D``, ``YT``, ``YD`` and ``A`` of the blocks ``E``.  The border by Woodbury on the forward
    half only: with ``Y = L^-1 P E U`` and ``y0 = L^-1 P E S y``, ``z = P^T L^-T D^-1 (y0 - Y x)``,
    ``A x = h Mb Y^T D^-1 y0``."""
    perm, sizes, first, boff = sym[8], sym[9], sym[10], sym[11]
    m, r = D.shape[0], YT.shape[0]
    y, sy = np.empty(g.shape[0]), np.empty((m, 1))
    _csr_times(Mi[0], Mi[1], Mi[2], g, y)
    _csr_times(S[0], S[1], S[2], y, sy[:, 0])
    Esy, w = np.empty((m, 1)), np.empty((m, 1))
    _blocks_times(E, boff, first, sizes, sy, Esy)
    for i in range(m):
        w[perm[i], 0] = Esy[i, 0]
    _ldl_forward(Lp, Li, Lx, w)
    if r > 0:
        x = np.linalg.solve(A, (h * Mb) @ (YD @ w))
        w -= YT.T @ x
    w[:, 0] /= D
    _ldl_backward(Lp, Li, Lx, w)
    z = np.empty((m, 1))
    for i in range(m):
        z[i, 0] = w[perm[i], 0]
    Ez = np.empty((m, 1))
    _blocks_times(E, boff, first, sizes, z, Ez)
    t, u = np.empty(g.shape[0]), np.empty(g.shape[0])
    _csr_times(St[0], St[1], St[2], Ez[:, 0], t)
    _csr_times(Mi[0], Mi[1], Mi[2], t, u)
    for i in range(g.shape[0]):
        dv[i] = h * u[i] - y[i]
    _csr_times(S[0], S[1], S[2], dv, ds)


@njit(cache=True)
def _direction(sym, Lp, Li, Lx, D, work, Cx, Kx, h, E, g, Mi, S, St, U, Mb, dv, ds):
    """:func:`_factor` then :func:`_solve`: the Newton direction ``dv`` and ``ds = S dv`` on a new LDL^T; returns the
    first bad pivot or -1."""
    r = U.shape[1]
    YT, YD, A = np.empty((r, D.shape[0])), np.empty((r, D.shape[0])), np.empty((r, r))
    bad = _factor(sym, Lp, Li, Lx, D, work, Cx, Kx, h, E, U, Mb, YT, YD, A)
    if bad < 0:
        _solve(sym, Lp, Li, Lx, D, h, E, g, Mi, S, St, YT, YD, A, Mb, dv, ds)
    return bad


def distinct(keys: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """``(sorted distinct keys, each key's index among them)`` for integer keys in ``[0, size)``: a dense marker, no
    sort (the patterns here are small: ``size`` is m^2 for m of about a thousand)."""
    mark = np.zeros(size, bool)
    mark[keys] = True
    u = np.flatnonzero(mark)
    where = np.empty(size, np.int64)
    where[u] = np.arange(u.size)
    return u, where[keys]


def fill_reducing_order(r: np.ndarray, c: np.ndarray, m: int) -> np.ndarray:
    """SuperLU's minimum-degree column order (``MMD_AT_PLUS_A``) of the m x m pattern with entries ``(r, c)``
    (repeats allowed) and the diagonal: old index -> new.  The order depends on the pattern alone; the values given
    to SuperLU make the matrix strictly diagonally dominant, so its factorisation never meets a zero pivot (ones with
    the repeats summed can be exactly singular)."""
    u, _ = distinct(np.concatenate([c * m + r, np.arange(m) * (m + 1)]), m * m)   # column-major: CSC order
    rows, cols = u % m, u // m
    count = np.bincount(cols, minlength=m)
    data = np.where(rows == cols, (count + 1.0)[cols], 1.0)                       # each column's off-diagonals < 1
    pattern = sp.csc_matrix((data, rows, np.concatenate([[0], np.cumsum(count)])), shape=(m, m))
    return spla.splu(pattern, permc_spec="MMD_AT_PLUS_A").perm_c


class SlipCholesky:
    """``C = I + h E K E`` on the pattern of ``K`` (CSR, symmetric pattern, sorted indices) and contacts of ``sizes``
    rows: the symbolic work in the constructor, :meth:`factor` per new ``(K data, h, E)``, :meth:`solve` after it.
    ``E`` is flattened by contact, each block row-major (``sizes**2`` values each)."""

    def __init__(self, K: sp.csr_matrix, sizes: np.ndarray):
        m = K.shape[0]
        sizes = np.asarray(sizes, np.int64)
        gid = np.repeat(np.arange(len(sizes)), sizes)
        first = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        boff = np.concatenate([[0], np.cumsum(sizes ** 2)[:-1]])
        rows = np.repeat(np.arange(m), np.diff(K.indptr))
        cols = K.indices
        g, f = gid[rows], gid[cols]
        dg, df = sizes[g], sizes[f]
        count = dg * df                                                  # each K entry feeds a dg x df block of C
        entry = np.repeat(np.arange(K.nnz), count)
        j = np.arange(entry.size) - np.repeat(np.cumsum(count) - count, count)
        a, b = j // df[entry], j % df[entry]
        ge, fe = g[entry], f[entry]
        r, c = first[ge] + a, first[fe] + b                              # C[r, c] += E_g[a, .] K E_f[., b]
        i1 = boff[ge] + a * dg[entry] + rows[entry] - first[ge]
        i2 = boff[fe] + (cols[entry] - first[fe]) * df[entry] + b
        self.perm = fill_reducing_order(r, c, m)                         # old index -> new
        pr, pc = self.perm[r], self.perm[c]
        up = pr <= pc
        nu = int(np.count_nonzero(up))
        key, where = distinct(np.concatenate([pc[up] * m + pr[up], np.arange(m) * (m + 1)]), m * m)
        self.Ap = np.concatenate([[0], np.cumsum(np.bincount(key // m, minlength=m))])
        self.Ai = key % m
        self.tgt, self.diag = where[:nu], where[nu:]
        self.i1, self.entry, self.i2 = i1[up], entry[up], i2[up]
        Lnz, self.parent, work = np.empty(m, np.int64), np.empty(m, np.int64), np.empty(m, np.int64)
        _etree(self.Ap, self.Ai, Lnz, self.parent, work)
        self.Lp = np.concatenate([[0], np.cumsum(Lnz)])
        self.Li, self.Lx = np.empty(self.Lp[-1], np.int64), np.empty(self.Lp[-1])
        self.D, self.Cx = np.empty(m), np.empty(key.size)
        self.sizes, self.first, self.boff = sizes, first, boff
        self._work = (np.empty(m), np.empty(m, np.bool_), np.empty(m, np.int64), np.empty(m, np.int64),
                      np.empty(m, np.int64))
        self.sym = (self.Ap, self.Ai, self.parent, self.tgt, self.i1, self.entry, self.i2, self.diag, self.perm,
                    sizes, first, boff)

    def matrix(self, Kx, h: float, E) -> sp.csc_matrix:
        """``C``'s upper triangle in the solver's order (checks)."""
        _fill(self.Cx, self.tgt, self.i1, self.entry, self.i2, Kx, E, h, self.diag)
        m = self.D.size
        return sp.csc_matrix((self.Cx.copy(), self.Ai, self.Ap), shape=(m, m))

    def factor(self, Kx, h: float, E) -> None:
        """The LDL^T of ``C`` for ``K``'s data ``Kx`` (the pattern's), step ``h`` and blocks ``E``."""
        _fill(self.Cx, self.tgt, self.i1, self.entry, self.i2, Kx, E, h, self.diag)
        y, mark, stack, reach, nxt = self._work
        bad = _ldl(self.Ap, self.Ai, self.Cx, self.parent, self.Lp, self.Li, self.Lx, self.D, y, mark, stack, reach,
                   nxt)
        if bad >= 0:
            raise NumericalError(f"the slip matrix I + h E K E is not positive definite (pivot {bad})",
                                 component="friction_solver.SlipCholesky")

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``C^-1 b`` (``b`` (m,) or (m, k))."""
        X = np.empty((b.shape[0], b[0].size))
        X[self.perm] = b.reshape(X.shape)
        _ldl_solve(self.Lp, self.Li, self.Lx, self.D, X)
        return X[self.perm].reshape(b.shape)

    def direction(self, Kx, h: float, E, g, Mi: sp.csr_matrix, S: sp.csr_matrix, St: sp.csr_matrix, U, Mb):
        """``(dv, S dv)``: ``dv = -(M + h S^T E E S)^-1 g`` by Woodbury, ``C`` of ``Kx`` (``K = S Mi_in S^T``, ``Mi_in``
        ``Mi`` without the border) factored here; ``U`` (m, r) the border's slip columns, ``Mb`` ``Mi``'s border block
        (dense r x r; one compiled call: :func:`_direction`)."""
        sym = self.sym
        dv, ds = np.empty(g.shape[0]), np.empty(S.shape[0])
        bad = _direction(sym, self.Lp, self.Li, self.Lx, self.D, self._work, self.Cx, Kx, h, E, g,
                         (Mi.indptr, Mi.indices, Mi.data), (S.indptr, S.indices, S.data),
                         (St.indptr, St.indices, St.data), U, Mb, dv, ds)
        if bad >= 0:
            raise NumericalError(f"the slip matrix I + h E K E is not positive definite (pivot {bad})",
                                 component="friction_solver.SlipCholesky")
        return dv, ds
