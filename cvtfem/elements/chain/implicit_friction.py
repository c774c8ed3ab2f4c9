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
import scipy.sparse.linalg as spla

from cvtfem.elements.contact.friction import (POTENTIAL_LAWS, friction_gain, friction_potential, friction_slope)
from cvtfem.errors import InputError, NumericalError

__all__ = ["FrictionSet", "friction_step"]


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

    def speeds(self, s):
        """``|s_g|`` (m/s) of the contacts from their slip rows ``s``."""
        return np.abs(s) if self.dim == 1 else np.sqrt((s.reshape(-1, self.dim) ** 2).sum(1))

    def per_row(self, a):
        return a if self.dim == 1 else np.repeat(a, self.dim)

    def forces(self, s):
        """``c psi(|s|) s`` per slip row (N)."""
        return self.per_row(self.c * friction_gain(self.speeds(s), self.f0, self.v0, self.law)) * s

    def potential(self, s) -> float:
        return float(self.c @ friction_potential(self.speeds(s), self.f0, self.v0, self.law))

    def slopes(self, s, tangent: bool) -> np.ndarray:
        """The blocks ``d(c psi s)/ds`` (contacts, dim, dim) (``tangent``: ``c [psi (I - tt) + f' tt]``,
        ``t = s/|s|``) or the secant ``c psi I`` (the majoriser's)."""
        d, speed = self.dim, self.speeds(s)
        gain = self.c * friction_gain(speed, self.f0, self.v0, self.law)
        if not tangent or d == 1:
            diag = self.c * friction_slope(speed, self.f0, self.v0, self.law) if tangent else gain
            return diag[:, None, None] * np.eye(d)
        slope = self.c * friction_slope(speed, self.f0, self.v0, self.law)
        t = s.reshape(-1, d) / np.where(speed > 0, speed, 1.0)[:, None]
        return gain[:, None, None] * np.eye(d) + (slope - gain)[:, None, None] * t[:, :, None] * t[:, None, :]


class _SlipSystem:
    """``A = I + h D K`` (``K = S M^-1 S^T`` over the inner velocities, ``D`` block diagonal by contact) on a pattern
    built once per pattern of ``K`` (:func:`_slip_system`): the rows of a contact share the union of their ``K`` rows'
    columns, and ``A``'s data is one weighted ``bincount`` of ``K``'s per iteration; factored as the CSC of ``A^T``
    (the CSR arrays as they are)."""

    def __init__(self, K: sp.csr_matrix, sizes: np.ndarray):
        m = K.shape[0]
        gid = np.repeat(np.arange(len(sizes)), sizes)                   # each row's contact
        first = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        rows = np.repeat(np.arange(m), np.diff(K.indptr))
        key = np.unique(np.concatenate([gid[rows] * m + K.indices, gid * m + np.arange(m)]))
        start = np.searchsorted(key // m, np.arange(len(sizes)))       # each contact's first pattern column
        width = np.diff(np.append(start, len(key)))[gid]                # pattern columns of each row
        self.indptr = np.concatenate([[0], np.cumsum(width)])
        self.indices = key[np.repeat(start[gid] - self.indptr[:-1], width) + np.arange(self.indptr[-1])] % m
        rank = np.searchsorted(key, gid[rows] * m + K.indices) - start[gid[rows]]
        d = sizes[gid[rows]]                                            # each K entry feeds the d rows of its contact
        self.entry = np.repeat(np.arange(K.nnz), d)
        e = self.entry
        r = first[gid[rows[e]]] + (np.arange(e.size) - np.repeat(np.cumsum(d) - d, d))       # the target row
        self.tgt = self.indptr[r] + rank[e]
        boff = np.concatenate([[0], np.cumsum(sizes ** 2)[:-1]])        # blocks flattened by contact
        g = gid[r]
        self.block = boff[g] + (r - first[g]) * sizes[g] + (rows[e] - first[g])
        self.diag = self.indptr[:-1] + np.searchsorted(key, gid * m + np.arange(m)) - start[gid]

    def factor(self, K: sp.csr_matrix, h: float, blocks: np.ndarray):
        data = np.bincount(self.tgt, h * blocks[self.block] * K.data[self.entry], minlength=self.indptr[-1])
        data[self.diag] += 1.0
        m = len(self.indptr) - 1
        return spla.splu(sp.csc_matrix((data, self.indices, self.indptr), shape=(m, m)))


_LAST: dict = {}
_MASS: dict = {}


def _inner_mass(Mi: sp.spmatrix, border) -> tuple[np.ndarray, sp.csr_matrix]:
    """``(inner, Mi_in)``: the mask of the velocities off the border and ``Mi`` with the border's rows and columns
    zeroed, kept for the next call with the same ``Mi`` and border."""
    border = np.zeros(0, int) if border is None else np.asarray(border)
    key = (id(Mi), border.tobytes())
    if key not in _MASS:
        inner = np.ones(Mi.shape[0], bool)
        inner[border] = False
        _MASS.clear()
        _MASS[key] = (Mi, inner, Mi.multiply(inner[:, None]).multiply(inner[None, :]).tocsr())
    return _MASS[key][1:]


def _slip_system(K: sp.csr_matrix, sizes: np.ndarray) -> _SlipSystem:
    """The :class:`_SlipSystem` of ``K``'s pattern, kept for the next call with the same pattern (successive solves
    of a run mostly share it: the same contacts in touch)."""
    key = K.indptr.tobytes() + K.indices.tobytes() + sizes.tobytes()
    if key not in _LAST:
        _LAST.clear()
        _LAST[key] = _SlipSystem(K, sizes)
    return _LAST[key]


def friction_step(M: sp.spmatrix, Mi: sp.spmatrix, sets: list[FrictionSet], v_star: np.ndarray, h: float,
                  v_start=None, border=None, tol: float = 1e-6, max_lu: int = 100) -> tuple[np.ndarray, float, int]:
    """``v`` with ``M (v - v*) = -h S^T r(Sv)`` (``r`` the contacts' :meth:`FrictionSet.forces`) over ``h`` (s).

    Newton on the convex function of the module docstring from ``v_start`` (default ``v*``; the minimiser does not
    depend on it), its matrix ``M + h S^T D S`` inverted through the slips' ``I + h D S M^-1 S^T`` (Woodbury: the
    mass inverse ``Mi`` is block diagonal, the slips fewer than the velocities); the velocities ``border`` (indices:
    the shafts', which couple every contact on them) enter that matrix as a low-rank update (Woodbury again), so its
    LU stays sparse.  Where a Newton step does not lower the function (a saturated law's tangent sends a slip far
    off) the majorise-minimise step (secant slopes ``c psi``; lies above ``Phi`` for laws with falling ``psi``)
    instead, until a step changes every slip by less than ``tol v0``.  Returns ``(v, W, LUs)`` with the work the
    step dissipates, booked as the kinetic energy it removes ``W = (v* - v)^T M (v* + v) / 2`` (J; equal to the
    friction's work ``h r(Sv) . S (v + v*) / 2`` to the solve's tolerance), so a run's energy balance holds to
    round-off whatever that tolerance."""
    S = sp.vstack([f.S for f in sets], format="csr")
    St = S.T.tocsr()
    inner, Mi_in = _inner_mass(Mi, border)
    K = (S @ Mi_in @ St).tocsr()                             # slip-space inverse mass without the border
    K.sort_indices()
    U = S[:, ~inner].toarray()                               # the border's slip columns (rows x r)
    Q = U @ Mi[~inner][:, ~inner].toarray()
    bounds = np.cumsum([0] + [f.S.shape[0] for f in sets])
    parts = [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:])]
    system = _slip_system(K, np.concatenate([np.full(len(f.c), f.dim) for f in sets]))
    v = np.array(v_star if v_start is None else v_start, float)
    s, lus = S @ v, 0

    def forces(s_):
        return np.concatenate([f.forces(s_[p]) for f, p in zip(sets, parts)])

    def objective(v_, s_):
        dv_ = v_ - v_star
        return 0.5 * dv_ @ (M @ dv_) + h * sum(f.potential(s_[p]) for f, p in zip(sets, parts))

    def step(tangent, g):
        """``-(M + h S^T D S)^-1 g``."""
        blocks = [f.slopes(s[p], tangent) for f, p in zip(sets, parts)]

        def D(x):                                            # the block-diagonal D times x (rows, ...)
            return np.concatenate([np.einsum("gij,gj...->gi...", b, x[p].reshape(len(b), b.shape[1], *x.shape[1:]))
                                   .reshape(x[p].shape) for b, p in zip(blocks, parts)])

        lu = system.factor(K, h, np.concatenate([b.ravel() for b in blocks]))
        y = Mi @ g
        w = lu.solve(D(S @ y), trans="T")
        if U.shape[1]:
            Z = lu.solve(h * D(U), trans="T")                # A = A_c + (h D U) Q^T
            w -= Z @ np.linalg.solve(np.eye(U.shape[1]) + Q.T @ Z, Q.T @ w)
        dv = h * (Mi @ (St @ w)) - y
        return dv, S @ dv

    def small(ds):
        return all(np.max(np.abs(ds[p]), initial=0.0) <= tol * f.v0 for f, p in zip(sets, parts))

    while lus < max_lu:
        g = M @ (v - v_star) + h * (St @ forces(s))
        dv, ds = step(True, g)
        lus += 1
        done = small(ds)
        if not done and objective(v + dv, s + ds) > objective(v, s) + 1e-4 * (g @ dv):
            dv, ds = step(False, g)
            lus += 1
        v, s = v + dv, s + ds
        if done or small(ds):
            break
    else:
        raise NumericalError(f"the implicit friction step (h = {h:g} s) did not converge in {max_lu} LUs",
                             component="implicit_friction.friction_step")
    return v, float(0.5 * (v_star - v) @ (M @ (v_star + v))), lus
