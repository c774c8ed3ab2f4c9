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

from cvtfem.elements.chain.friction_solver import SlipCholesky
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

    def roots(self, s, tangent: bool) -> np.ndarray:
        """The symmetric square roots (contacts, dim, dim) of the blocks ``d(c psi s)/ds`` (``tangent``: ``c [psi (I -
        tt) + f' tt]``, ``t = s/|s|``) or of the secant ``c psi I`` (the majoriser's); real for a convex potential
        (``f' >= 0``)."""
        d, speed = self.dim, self.speeds(s)
        gain = np.sqrt(self.c * friction_gain(speed, self.f0, self.v0, self.law))
        if not tangent or d == 1:
            diag = np.sqrt(self.c * friction_slope(speed, self.f0, self.v0, self.law)) if tangent else gain
            return diag[:, None, None] * np.eye(d)
        slope = np.sqrt(self.c * friction_slope(speed, self.f0, self.v0, self.law))
        t = s.reshape(-1, d) / np.where(speed > 0, speed, 1.0)[:, None]
        return gain[:, None, None] * np.eye(d) + (slope - gain)[:, None, None] * t[:, :, None] * t[:, None, :]


_LAST: dict = {}
_MASS: dict = {}


def _inner_mass(Mi: sp.spmatrix, border) -> tuple[np.ndarray, sp.csr_matrix, np.ndarray]:
    """``(inner, Mi_in, Mi_b)``: the mask of the velocities off the border, ``Mi`` with the border's rows and columns
    zeroed and the border's block of ``Mi`` (dense), kept for the next call with the same ``Mi`` and border."""
    border = np.zeros(0, int) if border is None else np.asarray(border)
    key = (id(Mi), border.tobytes())
    if key not in _MASS:
        inner = np.ones(Mi.shape[0], bool)
        inner[border] = False
        _MASS.clear()
        Mi_in = Mi.multiply(inner[:, None]).multiply(inner[None, :]).tocsr()
        Mi_in.eliminate_zeros()
        _MASS[key] = (Mi, inner, Mi_in,
                      Mi[~inner][:, ~inner].toarray())
    return _MASS[key][1:]


def _slip_system(K: sp.csr_matrix, sizes: np.ndarray) -> SlipCholesky:
    """The :class:`~.friction_solver.SlipCholesky` of ``K``'s pattern, kept for the next call with the same pattern
    (successive solves of a run mostly share it: the same contacts in touch)."""
    key = K.indptr.tobytes() + K.indices.tobytes() + sizes.tobytes()
    if key not in _LAST:
        _LAST.clear()
        _LAST[key] = SlipCholesky(K, sizes)
    return _LAST[key]


def friction_step(M: sp.spmatrix, Mi: sp.spmatrix, sets: list[FrictionSet], v_star: np.ndarray, h: float,
                  v_start=None, border=None, tol: float = 1e-6, max_lu: int = 100) -> tuple[np.ndarray, float, int]:
    """``v`` with ``M (v - v*) = -h S^T r(Sv)`` (``r`` the contacts' :meth:`FrictionSet.forces`) over ``h`` (s).

    Newton on the convex function of the module docstring from ``v_start`` (default ``v*``; the minimiser does not
    depend on it), its matrix ``M + h S^T D S`` inverted through the slips' ``I + h D S M^-1 S^T`` (Woodbury: the
    mass inverse ``Mi`` is block diagonal, the slips fewer than the velocities) in its symmetric form ``I + h E K E``
    (``D = E E``; :class:`~.friction_solver.SlipCholesky`, a compiled sparse LDL^T); the velocities ``border`` (indices:
    the shafts', which couple every contact on them) enter that matrix as a low-rank update (Woodbury again), so its
    LU stays sparse.  Where a Newton step does not lower the function (a saturated law's tangent sends a slip far
    off) the majorise-minimise step (secant slopes ``c psi``; lies above ``Phi`` for laws with falling ``psi``)
    instead, until a step changes every slip by less than ``tol v0``.  Returns ``(v, W, LUs)`` with the work the
    step dissipates, booked as the kinetic energy it removes ``W = (v* - v)^T M (v* + v) / 2`` (J; equal to the
    friction's work ``h r(Sv) . S (v + v*) / 2`` to the solve's tolerance), so a run's energy balance holds to
    round-off whatever that tolerance."""
    S = sp.vstack([f.S for f in sets], format="csr")
    St = S.T.tocsr()
    inner, Mi_in, Mi_b = _inner_mass(Mi, border)
    Mi_csr = Mi.tocsr()
    K = (S @ Mi_in @ St).tocsr()                             # slip-space inverse mass without the border
    K.sort_indices()
    U = np.ascontiguousarray(St[~inner].toarray().T)         # the border's slip columns (rows x r)
    Q = U @ Mi_b
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
        """``-(M + h S^T E E S)^-1 g`` by Woodbury: ``-y + h M^-1 S^T E C^-1 E S y``, ``y = M^-1 g``, ``C = I + h E
        S M^-1 S^T E`` (SPD), its border part a rank-r update (Woodbury again)."""
        E = np.concatenate([f.roots(s[p], tangent).ravel() for f, p in zip(sets, parts)])
        return system.direction(K.data, h, E, g, Mi_csr, S, St, U, Mi_b)

    def small(ds):
        return all(np.max(np.abs(ds[p]), initial=0.0) <= tol * f.v0 for f, p in zip(sets, parts))

    value = None                                             # the objective at v, once needed
    while lus < max_lu:
        g = M @ (v - v_star) + h * (St @ forces(s))
        dv, ds = step(True, g)
        lus += 1
        done = small(ds)
        if not done:
            value = objective(v, s) if value is None else value
            trial = objective(v + dv, s + ds)
            if trial > value + 1e-4 * (g @ dv):
                dv, ds = step(False, g)
                lus += 1
                trial = None
            value = trial
        v, s = v + dv, s + ds
        if done or small(ds):
            break
    else:
        raise NumericalError(f"the implicit friction step (h = {h:g} s) did not converge in {max_lu} LUs",
                             component="implicit_friction.friction_step")
    return v, float(0.5 * (v_star - v) @ (M @ (v_star + v))), lus
