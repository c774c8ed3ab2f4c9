"""Backward Euler of regularised friction alone, the positions frozen: the implicit part of ``strang-friction``.

The friction acts through slips linear in the velocities, ``s = S v`` (m/s), grouped in contacts of one row (a
scalar slip: the halves' axial and rolling friction, :meth:`~cvtfem.elements.chain.halves.ChainA5.friction_slips`)
or three (a slip vector in a tangent plane: the pin-sheave contacts, :mod:`~.half_end_slips`); contact ``g`` of
normal force ``c_g`` (N) gives the forces ``-S_g^T c_g psi(|s_g|) s_g`` (:mod:`~cvtfem.elements.contact.friction`).
One step over ``h`` from ``v*`` is the minimiser of the convex
``(v - v*)^T M (v - v*) / 2 + h sum_g c_g Phi(|s_g|)`` (``Phi' = f``): :func:`friction_step`.  Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from cvtfem.elements.chain.friction_solver import SlipCholesky, _csr_times, _factor, _solve, distinct
from cvtfem.elements.contact.friction import _SMALL, POTENTIAL_LAWS, friction_gain
from cvtfem.elements.contact.kernels import LAW_CODES as KERNEL_LAW_CODES
from cvtfem.elements.contact.kernels import _gain
from cvtfem.elements.jit import njit
from cvtfem.errors import InputError, NumericalError

__all__ = ["FrictionSet", "friction_step", "FrictionRate"]


@dataclass(frozen=True)
class FrictionSet:
    """Contacts of one law: slip rows ``S`` (sparse, ``dim`` rows per contact, columns the velocities), normal
    forces ``c`` (N, one per contact), the law's ``f0``, ``v0`` (m/s) and name."""

    S: sp.csr_matrix
    c: np.ndarray
    dim: int
    f0: float
    v0: float
    law: str

    def __post_init__(self):
        if self.law not in POTENTIAL_LAWS:
            raise InputError("friction_law", self.law, f"must be one of {sorted(POTENTIAL_LAWS)} for the implicit "
                                                       "friction")

    def forces(self, s):
        """``c psi(|s|) s`` per slip row (N) for the slip rows ``s`` (m/s; numpy: the machines' explicit checks)."""
        speed = np.abs(s) if self.dim == 1 else np.sqrt((s.reshape(-1, self.dim) ** 2).sum(1))
        return np.repeat(self.c * friction_gain(speed, self.f0, self.v0, self.law), self.dim) * s


#: The compiled laws' codes (:func:`_law`).
LAW_CODES = {"linear-saturated": 0, "nonsmooth": 0, "tanh": 1, "smoothed": 2, "arctan": 3}
#: Each law's steepest slope over ``f0 / v0`` (at zero slip).
STEEPEST = {"linear-saturated": 1.0, "nonsmooth": 1.0, "tanh": 1.0, "smoothed": 1.5, "arctan": 1.0}


@njit(cache=True)
def _law(code, x):
    """``(psi, f', Phi)`` of the law ``code`` at ``x = v / v0 >= 0`` in units of ``f0/v0``, ``f0/v0``, ``f0 v0``: the
    compiled twin of :func:`~cvtfem.elements.contact.friction.friction_gain`, ``friction_slope`` and
    ``friction_potential``."""
    if code == 1:
        th = np.tanh(x)
        gain = th / x if x > _SMALL else 1.0 - x * x / 3
        return gain, 1.0 - th * th, x + np.log1p(np.exp(-2 * x)) - np.log(2.0)
    if code == 2:
        if x < 1.0:
            return 1.5 - 0.5 * x * x, 1.5 * (1.0 - x * x), 0.75 * x * x - x ** 4 / 8
        return 1.0 / x, 0.0, x - 0.375
    if code == 3:
        a = 0.5 * np.pi * x
        gain = np.arctan(a) / a if x > _SMALL else 1.0 - a * a / 3
        return gain, 1.0 / (1.0 + a * a), (2 / np.pi) ** 2 * (a * np.arctan(a) - 0.5 * np.log1p(a * a))
    if x < 1.0:
        return 1.0, 1.0, 0.5 * x * x
    return 1.0 / x, 0.0, x - 0.5


@njit(cache=True)
def _speed(s, f, d):
    acc = 0.0
    for a in range(d):
        acc += s[f + a] * s[f + a]
    return np.sqrt(acc)


@njit(cache=True)
def _contacts(s, law, tangent, r, E):
    """For slips ``s``: ``r`` the forces ``c psi(|s_g|) s_g`` per row (N) and ``E`` the symmetric square roots of the
    blocks ``d(c psi s)/ds`` (``tangent``: ``c [psi (I - tt) + f' tt]``, ``t = s/|s|``) or of the secant ``c psi I``
    (flattened by contact, row-major; real for a convex potential, ``f' >= 0``); returns ``sum_g c_g Phi(|s_g|)``
    (N m/s).  ``law``: per contact its first row, rows, block offset, ``c``, ``f0``, ``v0``, law code."""
    first, sizes, boff, c, f0, v0, code = law
    total = 0.0
    for k in range(sizes.shape[0]):
        f, d, o = first[k], sizes[k], boff[k]
        speed = _speed(s, f, d)
        gain, slope, pot = _law(code[k], speed / v0[k])
        scale = c[k] * f0[k] / v0[k]
        total += c[k] * f0[k] * v0[k] * pot
        for a in range(d):
            r[f + a] = scale * gain * s[f + a]
        root_g = np.sqrt(scale * gain)
        root_s = np.sqrt(scale * slope)
        for a in range(d):
            for b in range(d):
                E[o + a * d + b] = 0.0
            if not tangent:
                E[o + a * d + a] = root_g
            elif d == 1:
                E[o] = root_s
            else:
                E[o + a * d + a] = root_g
                if speed > 0:
                    for b in range(d):
                        E[o + a * d + b] += (root_s - root_g) * ((s[f + a] / speed) * (s[f + b] / speed))
    return total


@njit(cache=True)
def _small(ds, law, tol):
    first, sizes, v0 = law[0], law[1], law[5]
    for k in range(sizes.shape[0]):
        for a in range(sizes[k]):
            if abs(ds[first[k] + a]) > tol * v0[k]:
                return False
    return True


@njit(cache=True)
def _objective(M, dv, h, potential):
    Mdv = np.empty(dv.shape[0])
    _csr_times(M[0], M[1], M[2], dv, Mdv)
    return 0.5 * (dv @ Mdv) + h * potential


@njit(cache=True)
def _scatter(out, tgt, x, ix, y, iy):
    """``out[tgt[k]] += x[ix[k]] y[iy[k]]`` after zeroing ``out``: a sparse product on a fixed pattern."""
    out[:] = 0.0
    for k in range(tgt.shape[0]):
        out[tgt[k]] += x[ix[k]] * y[iy[k]]


#: A full Newton step that changed no slip by more than this many times the tolerance is followed by a chord step on
#: the same LDL^T (a solve, no new factorisation), which ends the iteration when it is below the tolerance.
CHORD = 10.0


@njit(cache=True)
def _newton(v, v_star, h, tol, max_lu, M, Mi, Mi_in, Mb, S, St, kmap, umap, law, sym, Lp, Li, Lx, D, work, Cx):
    """:func:`friction_step`'s iteration on ``v`` in place; returns ``(LUs, W)``, LUs ``-1 - k`` for a bad pivot
    ``k`` or ``max_lu + 1`` without convergence.  ``M``, ``Mi``, ``Mi_in``, ``S`` CSR triples, ``St`` ``S^T``'s
    pattern and permutation of ``S``'s data, ``kmap`` and ``umap`` :class:`_Plan`'s maps of ``K`` and ``U``, ``law``
    :func:`_contacts`', the rest :class:`~.friction_solver.SlipCholesky`'s arrays."""
    n, m = v.shape[0], S[0].shape[0] - 1
    St = (St[0], St[1], S[2][St[2]])
    tgtT, pS, q, Tx, tgtK, tt, sK, Kx = kmap
    _scatter(Tx, tgtT, S[2], pS, Mi_in, q)
    _scatter(Kx, tgtK, Tx, tt, S[2], sK)
    Urow, Ucol, Upos = umap
    U = np.zeros((m, Mb.shape[0]))
    for k in range(Urow.shape[0]):
        U[Urow[k], Ucol[k]] = S[2][Upos[k]]
    s, r, t, g = np.empty(m), np.empty(m), np.empty(n), np.empty(n)
    size = 0
    for d in law[1]:
        size += d * d
    E, Etrial = np.empty(size), np.empty(size)
    rtrial = np.empty(m)
    dv, ds = np.empty(n), np.empty(m)
    r_b = Mb.shape[0]
    YT, YD, A, Ef = np.empty((r_b, m)), np.empty((r_b, m)), np.empty((r_b, r_b)), np.empty(size)
    _csr_times(S[0], S[1], S[2], v, s)
    lus, value, known, near = 0, 0.0, False, False
    while lus < max_lu:
        potential = _contacts(s, law, True, r, E)
        _csr_times(St[0], St[1], St[2], r, t)
        _csr_times(M[0], M[1], M[2], v - v_star, g)
        g += h * t
        if near:                     # a chord step on the last LDL^T: ends the iteration when it is small
            _solve(sym, Lp, Li, Lx, D, h, Ef, g, Mi, S, St, YT, YD, A, Mb, dv, ds)
            if _small(ds, law, tol):
                v += dv
                _csr_times(M[0], M[1], M[2], v_star + v, t)
                return lus, 0.5 * ((v_star - v) @ t)
        bad = _factor(sym, Lp, Li, Lx, D, work, Cx, Kx, h, E, U, Mb, YT, YD, A)
        if bad >= 0:
            return -1 - bad, 0.0
        Ef[:] = E
        _solve(sym, Lp, Li, Lx, D, h, E, g, Mi, S, St, YT, YD, A, Mb, dv, ds)
        lus += 1
        done = _small(ds, law, tol)
        near = False
        if not done:
            if not known:
                value = _objective(M, v - v_star, h, potential)
            trial = _objective(M, v + dv - v_star, h, _contacts(s + ds, law, False, rtrial, Etrial))
            if trial > value + 1e-4 * (g @ dv):
                _contacts(s, law, False, r, E)
                bad = _factor(sym, Lp, Li, Lx, D, work, Cx, Kx, h, E, U, Mb, YT, YD, A)
                if bad >= 0:
                    return -1 - bad, 0.0
                Ef[:] = E
                _solve(sym, Lp, Li, Lx, D, h, E, g, Mi, S, St, YT, YD, A, Mb, dv, ds)
                lus += 1
                known = False
            else:
                value, known = trial, True
                near = _small(ds, law, CHORD * tol)
        v += dv
        s += ds
        if done or _small(ds, law, tol):
            _csr_times(M[0], M[1], M[2], v_star + v, t)
            return lus, 0.5 * ((v_star - v) @ t)
    return max_lu + 1, 0.0


_PLAN: dict = {}
_MASS: dict = {}


def _inner_mass(M, Mi: sp.spmatrix, border) -> tuple:
    """``(M, Mi, Mi_in, Mi_b, border)``: ``M`` and ``Mi`` as CSR, ``Mi`` with the border's rows and columns zeroed and
    the border's block of ``Mi`` (dense), kept for the next call with the same ``M``, ``Mi`` and border."""
    border = np.zeros(0, np.int64) if border is None else np.asarray(border, np.int64)
    key = (id(M), id(Mi), border.tobytes())
    if key not in _MASS:
        inner = np.ones(Mi.shape[0], bool)
        inner[border] = False
        _MASS.clear()
        Mi_in = Mi.multiply(inner[:, None]).multiply(inner[None, :]).tocsr()
        Mi_in.eliminate_zeros()
        Mi_in.sort_indices()
        _MASS[key] = (M, Mi, (sp.csr_matrix(M), sp.csr_matrix(Mi), Mi_in,
                              np.ascontiguousarray(Mi[border][:, border].toarray()), border))
    return _MASS[key][2]


class _Plan:
    """What depends only on the slip rows' pattern (the sets' ``S`` ``indptr``, ``indices``, dims, laws and contact
    counts), the inner mass ``Mi_in`` and the border: the stacked pattern, ``S^T``'s pattern and permutation, the maps
    of ``K = S Mi_in S^T`` (through ``T = S Mi_in``; only the entries ``C`` reads) into fixed CSR data arrays, the
    border's slip columns' positions, the per-contact law arrays and the :class:`~.friction_solver.SlipCholesky` of
    ``K``'s pattern."""

    def __init__(self, sets, n: int, Mi_in: sp.csr_matrix, border):
        self.sets = [(f.dim, f.f0, f.v0, f.law, len(f.c), f.S.shape, f.S.indptr.copy(), f.S.indices.copy())
                     for f in sets]
        self.Mi_in, self.border = Mi_in, border.copy()
        offsets = np.cumsum([0] + [f.S.nnz for f in sets])
        indptr = np.concatenate([f.S.indptr[:-1] + o for f, o in zip(sets, offsets)] + [offsets[-1:]])
        indptr, indices = indptr.astype(np.int64), np.concatenate([f.S.indices for f in sets]).astype(np.int64)
        counts = [len(f.c) for f in sets]
        sizes = np.repeat([f.dim for f in sets], counts).astype(np.int64)
        m, nnz = indptr.size - 1, indices.size
        St = sp.csr_matrix((np.arange(nnz, dtype=float), indices, indptr), shape=(m, n)).T.tocsr()
        Stp, Stj, tperm = St.indptr.astype(np.int64), St.indices.astype(np.int64), St.data.astype(np.int64)
        self.S, self.St = (indptr, indices), (Stp, Stj, tperm)
        rows = np.repeat(np.arange(m), np.diff(indptr))
        pS, q, keyT = _pairs(indices, Mi_in.indptr, rows, Mi_in.indices, n)
        uT, tgtT = distinct(keyT, m * n)
        Trow, Tcol = uT // n, uT % n
        tt, r, keyK = _pairs(Tcol, Stp, Trow, Stj, m)
        uK, tgtK = distinct(keyK, m * m)
        K = sp.csr_matrix((np.ones(uK.size), uK % m, np.searchsorted(uK // m, np.arange(m + 1))), shape=(m, m))
        self.system = SlipCholesky(K, sizes)
        read = np.zeros(uK.size, bool)
        read[self.system.entry] = True
        read = read[tgtK]                                            # the K entries that C's upper triangle reads
        self.kmap = (tgtT, pS, q, np.empty(uT.size), tgtK[read], tt[read], tperm[r[read]], np.zeros(uK.size))
        pos = np.concatenate([np.arange(Stp[b], Stp[b + 1]) for b in border] + [np.zeros(0, np.int64)])
        self.umap = (Stj[pos], np.repeat(np.arange(border.size), np.diff(Stp)[border]), tperm[pos])
        per = lambda a: np.repeat(a, counts)  # noqa: E731
        system = self.system
        self.law = (system.first, system.sizes, system.boff, per([float(f.f0) for f in sets]),
                    per([float(f.v0) for f in sets]), per([LAW_CODES[f.law] for f in sets]).astype(np.int64))

    def fits(self, sets, Mi_in, border) -> bool:
        """Whether this plan is the one of these sets, ``Mi_in`` and border."""
        return (Mi_in is self.Mi_in and np.array_equal(border, self.border) and len(sets) == len(self.sets)
                and all((f.dim, f.f0, f.v0, f.law, len(f.c), f.S.shape) == k[:6] and np.array_equal(f.S.indptr, k[6])
                        and np.array_equal(f.S.indices, k[7]) for f, k in zip(sets, self.sets)))


def _pairs(cols, Bp, rows, Bj, width):
    """For each entry ``p`` of a sparse ``A`` (``rows``, ``cols``) each entry ``q`` of ``B``'s row ``cols[p]``:
    ``(p, q, key)`` with ``key = row * width + B's column`` (the product ``A B``'s entry it feeds)."""
    count = Bp[cols + 1] - Bp[cols]
    p = np.repeat(np.arange(cols.size), count)
    q = Bp[cols][p] + np.arange(p.size) - np.repeat(np.cumsum(count) - count, count)
    return p, q, rows[p] * width + Bj[q]


def _plan(sets, n, Mi_in, border) -> _Plan:
    """The :class:`_Plan` of these sets, kept for the next call with the same pattern (successive solves of a run
    mostly share it: the same contacts in touch)."""
    plan = _PLAN.get("last")
    if plan is None or not plan.fits(sets, Mi_in, border):
        plan = _PLAN["last"] = _Plan(sets, n, Mi_in, border)
    return plan


@njit(cache=True)
def _slip_forces(v, S, law, Q):
    """``Q = S^T r(S v)`` (the friction forces on the velocities, with the sign of ``r``), row by row of ``S``: each
    contact's slips, its law, and its rows scattered back at once."""
    indptr, indices, data = S
    first, sizes, c, f0, v0, code = law
    s = np.zeros(3)
    Q[:] = 0.0
    for k in range(sizes.shape[0]):
        f, d = first[k], sizes[k]
        for a in range(d):
            acc = 0.0
            for p in range(indptr[f + a], indptr[f + a + 1]):
                acc += data[p] * v[indices[p]]
            s[a] = acc
        g = c[k] * _gain(_speed(s, 0, d), f0[k], v0[k], code[k], 0.1)
        for a in range(d):
            r = g * s[a]
            for p in range(indptr[f + a], indptr[f + a + 1]):
                Q[indices[p]] += r * data[p]


@njit(cache=True)
def _rate(v, S, Mi, law, Q, out):
    """``out = -M^-1 S^T r(S v)``: the friction's accelerations at the velocities ``v``; ``law`` per contact its first
    row, rows, ``c``, ``f0``, ``v0`` and law code (:data:`~cvtfem.elements.contact.kernels.LAW_CODES`)."""
    _slip_forces(v, S, law, Q)
    _csr_times(*Mi, Q, out)
    for i in range(out.shape[0]):
        out[i] = -out[i]


@njit(cache=True)
def _chebyshev(v, a, eta, mu, nu, mu_t, S, Mi, law, Q, g, u, u_prev, u_next):
    """``u(eta)`` of ``u' = a + rate(u)``, ``u(0) = v``, by the Chebyshev stages ``(mu, nu, mu_t)`` into ``u``."""
    n = v.shape[0]
    _rate(v, S, Mi, law, Q, g)
    for i in range(n):
        u_prev[i] = v[i]
        u[i] = v[i] + mu_t[1] * eta * (a[i] + g[i])
    for j in range(2, mu.shape[0]):
        _rate(u, S, Mi, law, Q, g)
        for i in range(n):
            u_next[i] = mu[j] * u[i] + nu[j] * u_prev[i] + mu_t[j] * eta * (a[i] + g[i])
        for i in range(n):
            u_prev[i] = u[i]
            u[i] = u_next[i]


@njit(cache=True)
def _power(z, iterations, S, Mi, law, Q):
    """``iterations`` power iterations of ``M^-1 S^T D S`` on ``z`` (in place), ``D`` the slopes ``c f0 / v0`` of
    ``law`` (the linear law, each contact's steepest slope factor folded into its ``c``), on slips kept far inside its
    linear part; returns the last norm ratio."""
    radius, small = 0.0, 1e-6 * law[4].min()                             # slips well inside the linear part
    for _ in range(iterations):
        norm = np.sqrt(np.sum(z * z)) / small
        for i in range(z.shape[0]):
            z[i] /= norm
        _slip_forces(z, S, law, Q)
        _csr_times(*Mi, Q, z)
        radius = np.sqrt(np.sum(z * z)) / small
    return radius


class FrictionRate:
    """The accelerations ``-M^-1 S^T r(S v)`` of the contacts ``sets`` (:class:`FrictionSet`, the positions frozen) at
    velocities ``v`` (compiled :func:`_rate`); ``Mi``: ``M^-1`` as the arrays ``(indptr, indices, data)`` of a CSR
    matrix (int64, int64, float).  The stiff part of multirate-rk4 (:mod:`cvtfem.integrate.imex`)."""

    def __init__(self, Mi: tuple, sets: list[FrictionSet]) -> None:
        counts = [len(f.c) for f in sets]
        sizes = np.repeat([f.dim for f in sets], counts).astype(np.int64)
        first = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        c = np.concatenate([f.c for f in sets]).astype(float)
        f0, v0 = (np.repeat([float(getattr(f, k)) for f in sets], counts) for k in ("f0", "v0"))
        codes = np.repeat([KERNEL_LAW_CODES[f.law] for f in sets], counts).astype(np.int64)
        self.law = (first, sizes, c, f0, v0, codes)
        steep = c * np.repeat([STEEPEST[f.law] for f in sets], counts)      # the linear law at these slopes
        self._steep = (first, sizes, steep, f0, v0, np.zeros(len(c), np.int64))
        indptr = [np.zeros(1, np.int64)]
        for f in sets:
            indptr.append(f.S.indptr[1:].astype(np.int64) + indptr[-1][-1])
        self.S = (np.concatenate(indptr), np.concatenate([f.S.indices for f in sets]).astype(np.int64),
                  np.concatenate([f.S.data for f in sets]).astype(float))
        self.Mi = Mi
        self._stages = tuple(np.empty(Mi[0].shape[0] - 1) for _ in range(5))

    def __call__(self, v, out) -> None:
        """Write the accelerations at the velocities ``v`` (n,) into ``out`` (n,)."""
        _rate(v, self.S, self.Mi, self.law, self._stages[0], out)

    def advance(self, v, a, eta: float, coefficients: tuple) -> np.ndarray:
        """``u(eta)`` (n,) of ``u' = a + rate(u)`` from ``u(0) = v`` by the s-stage Chebyshev method of ``coefficients``
        ``(mu, nu, mu_t)`` (:func:`~cvtfem.integrate.stabilized.rkc1_coefficients`), compiled (:func:`_chebyshev`)."""
        Q, g, u, u_prev, u_next = self._stages
        _chebyshev(np.ascontiguousarray(v), np.ascontiguousarray(a), float(eta), *coefficients, self.S, self.Mi,
                   self.law, Q, g, u, u_prev, u_next)
        return u.copy()

    def bound(self, z, iterations: int) -> tuple[float, np.ndarray]:
        """``(radius, z)``: the spectral radius (1/s) of ``M^-1 S^T D S`` with every slip at its law's steepest slope
        (:data:`STEEPEST`; at least that of the rate's velocity Jacobian) by power iteration from the velocities ``z``
        (None: a seeded random vector), and the last iterate."""
        n = self._stages[0].shape[0]
        z = np.random.default_rng(1).standard_normal(n) if z is None else np.array(z, float)
        if not self.law[1].shape[0]:                                    # no contact in touch: nothing stiff
            return 0.0, z
        return _power(z, iterations, self.S, self.Mi, self._steep, self._stages[0]), z


def friction_step(M: sp.spmatrix, Mi: sp.spmatrix, sets: list[FrictionSet], v_star: np.ndarray, h: float,
                  v_start=None, border=None, tol: float = 1e-6, max_lu: int = 100) -> tuple[np.ndarray, float, int]:
    """``v`` with ``M (v - v*) = -h S^T r(Sv)`` (``r`` the contacts' forces ``c psi(|s_g|) s_g``) over ``h`` (s).

    Newton on the convex function of the module docstring from ``v_start`` (default ``v*``; the minimiser does not
    depend on it), its matrix ``M + h S^T D S`` inverted through the slips' ``I + h D S M^-1 S^T`` (Woodbury: the
    mass inverse ``Mi`` is block diagonal, the slips fewer than the velocities) in its symmetric form ``I + h E K E``
    (``D = E E``; :class:`~.friction_solver.SlipCholesky`, a compiled sparse LDL^T); the velocities ``border`` (indices:
    the shafts', which couple every contact on them) enter that matrix as a low-rank update (Woodbury again), so its
    LU stays sparse.  Where a Newton step does not lower the function (a saturated law's tangent sends a slip far
    off) the majorise-minimise step (secant slopes ``c psi``; lies above ``Phi`` for laws with falling ``psi``)
    instead, until a step changes every slip by less than ``tol v0``; after a Newton step of less than :data:`CHORD`
    times that, the next step is first tried as a chord step on the same LDL^T (a solve instead of a factorisation),
    which ends the iteration when it is below ``tol v0``.  The whole iteration is compiled
    (:func:`_newton`), what depends only on the slips' pattern kept from call to call (:class:`_Plan`).  Returns
    ``(v, W, LUs)`` with the work the step dissipates, booked as the kinetic energy it removes ``W = (v* - v)^T M (v*
    + v) / 2`` (J; equal to the friction's work ``h r(Sv) . S (v + v*) / 2`` to the solve's tolerance), so a run's
    energy balance holds to round-off whatever that tolerance."""
    Mc, Mic, Mi_in, Mb, border_ = _inner_mass(M, Mi, border)
    if sum(f.S.shape[0] for f in sets) == 0:                    # no contact in touch: the minimiser is v*
        return np.array(v_star, float), 0.0, 0
    plan = _plan(sets, Mc.shape[0], Mi_in, border_)
    Sx = np.concatenate([f.S.data for f in sets]).astype(float)
    law = plan.law[:3] + (np.concatenate([f.c for f in sets]).astype(float),) + plan.law[3:]
    v = np.array(v_star if v_start is None else v_start, float)
    system = plan.system
    lus, W = _newton(v, np.asarray(v_star, float), float(h), float(tol), int(max_lu), (Mc.indptr, Mc.indices, Mc.data),
                     (Mic.indptr, Mic.indices, Mic.data), Mi_in.data, Mb, plan.S + (Sx,), plan.St, plan.kmap,
                     plan.umap, law, system.sym, system.Lp, system.Li, system.Lx, system.D, system._work, system.Cx)
    if lus < 0:
        raise NumericalError(f"the slip matrix I + h E K E is not positive definite (pivot {-1 - lus})",
                             component="implicit_friction.friction_step")
    if lus > max_lu:
        raise NumericalError(f"the implicit friction step (h = {h:g} s) did not converge in {max_lu} LUs",
                             component="implicit_friction.friction_step")
    return v, W, lus
