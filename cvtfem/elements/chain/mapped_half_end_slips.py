"""The pin-sheave friction of variant (e) on elastic shafts as a linear slip map at frozen positions.

The elastic twin of :mod:`~cvtfem.elements.chain.half_end_slips`: every H2 half-end contact sits in the frame of its
displaced, tilted sheave (:mod:`~cvtfem.elements.chain.mapped_contact_kernel`), whose kernel rates are ``dK P'``, linear
in the mapped rates ``P'`` (the half end, its chord, ``x3``, slope, the sheave's translation, tilt, the other sheave's
axial position) and the spin.  With the positions frozen the slip of a contact in touch is therefore ``s = G v`` (3
components: the tangent-plane relative velocity, m/s), read from the kernel itself: one evaluation per candidate with
the rates zero (its normal force, friction off; which are in touch), then, for those in touch, one per kernel rate (the
half end's 8, the spin) set to 1 (the slip's derivative in it); the mapped rates' slips (``G``'s columns) follow by
the frame map's transpose (``spread^T dK^T gather^T``), mapped to the state's velocities through the pair table, in
the orthonormal basis of the tangent plane of
:func:`~cvtfem.elements.chain.half_end_slips._plane` (2 rows a contact, as the rigid shafts' map).  The contact's
friction forces are ``-G^T (N psi(|s|) s)``, those of :func:`mapped_contact_kernel.forces`.  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.half_end_contact import _spread as _half_spread
from cvtfem.elements.chain.half_end_slips import _plane
from cvtfem.elements.chain.mapped_contact_kernel import (N_FRAME, N_KERNEL, N_PATTERN, _candidates, _frame_back,
                                                         _gather_in, _spread_in, frame_a1)
from cvtfem.elements.chain.sheave_contact_refined_kernel import refined_local_kernel
from cvtfem.elements.jit import njit

__all__ = ["slip_map"]

#: The half-end contact's kernel positions (end 2, chord 2, ``x3``, slope 2, ``z``) and its kernel rates (theirs, the
#: spin).
N_HALF = 8
N_RATE = N_HALF + 1


@njit(cache=True)
def slip_map(y, cols, coef, shaft, sheave, centres, r2, frame, ends, meridians, face, slope_factor, c, par, law,
             n2, N, indptr, indices, data):
    """The H2 half-end contacts in touch at the positions of ``y = [q, v]`` (mapped pair table ``cols``, ``coef``,
    ``shaft``, ``sheave``; the constants of :func:`mapped_contact_kernel.pack_refined` for half ends): their normal
    forces into ``N`` and ``G`` in CSR (2 rows per contact: the slip in the basis of its tangent plane; columns the
    velocities ``v`` (n2,), sorted, no duplicates) into ``indptr``, ``indices``, ``data``.  Returns ``(contacts,
    entries, first pair with its half end on the shaft axis or -1)``; ``N`` needs ``cols.shape[0]`` places,
    ``indptr`` ``2 cols.shape[0] + 1``, the entries ``2 cols.shape[0] cols.shape[1] cols.shape[2]``."""
    n_pairs, n_in, K = cols.shape[0], cols.shape[1], cols.shape[2]
    n_p = (n_in - 1) // 2
    Zall, sh, pair = np.empty((n_pairs, n_in)), np.empty(n_pairs, np.int64), np.empty(n_pairs, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, ends, Zall, sh, pair)
    Kp, dK = np.empty((m, N_KERNEL)), np.empty((m, N_PATTERN))
    P = np.empty(N_FRAME)
    for t in range(m):
        k, j = sh[t], sheave[pair[t]]
        _spread_in(Zall[t], 0, True, P)
        frame_a1(P, frame[0, k, j], centres[k, 0], centres[k, 1], frame[1, k, j], frame[2, k, j], Kp[t], dK[t])
    Yk, _, bad = _kernel(Kp, sh, np.arange(m), 0, centres, meridians, face, slope_factor, c, par, law)
    touch = np.flatnonzero(-par[3] * Yk[:, 6] > 0.0)   # the kernel's 2 (s N + F_3) at side s = -1, friction off
    Jk = _kernel(Kp, sh, touch, N_RATE, centres, meridians, face, slope_factor, c, par, law)[1]
    rows = n_p + 1                                      # each mapped rate, then the spin
    E = np.empty((rows, 3))
    Jc, Y10, F, Qp = np.empty(N_HALF), np.empty(N_KERNEL), np.empty(N_FRAME), np.empty(n_p)
    basis = np.empty((2, 3))
    ent_col, ent_val = np.empty(rows * K, np.int64), np.empty((rows * K, 2))
    n = 0
    indptr[0] = 0
    for q in range(touch.shape[0]):
        t = touch[q]
        N[q] = -par[3] * Yk[t, 6]
        J = Jk[q * N_RATE:(q + 1) * N_RATE]            # the slip of each kernel rate (8 half-end rates, spin)
        for a in range(3):                             # the slips of the mapped rates: spread^T dK^T gather^T J
            for i in range(N_HALF):
                Jc[i] = J[i, a]
            _frame_back(Jc, True, dK[t], Y10, F, Qp)
            for r in range(n_p):
                E[r, a] = Qp[r]
        E[n_p] = J[N_HALF]
        _plane(E, basis)
        i = pair[t]
        ne = 0                                         # this contact's columns, kept sorted, duplicates summed
        for r in range(rows):
            j = n_p + r if r < n_p else 2 * n_p        # the mapped rate's slot, then the spin's
            for a in range(K):
                col, w = cols[i, j, a], coef[i, j, a]
                if w == 0.0 or col < n2 or col >= 2 * n2:
                    continue
                u0 = w * (basis[0, 0] * E[r, 0] + basis[0, 1] * E[r, 1] + basis[0, 2] * E[r, 2])
                u1 = w * (basis[1, 0] * E[r, 0] + basis[1, 1] * E[r, 1] + basis[1, 2] * E[r, 2])
                p = ne
                while p > 0 and ent_col[p - 1] > col - n2:
                    p -= 1
                if p > 0 and ent_col[p - 1] == col - n2:
                    ent_val[p - 1, 0] += u0
                    ent_val[p - 1, 1] += u1
                    continue
                for b in range(ne, p, -1):
                    ent_col[b], ent_val[b, 0], ent_val[b, 1] = ent_col[b - 1], ent_val[b - 1, 0], ent_val[b - 1, 1]
                ent_col[p], ent_val[p, 0], ent_val[p, 1] = col - n2, u0, u1
                ne += 1
        for d in range(2):
            for b in range(ne):
                indices[n + b], data[n + b] = ent_col[b], ent_val[b, d]
            n += ne
            indptr[2 * q + d + 1] = n
    return touch.shape[0], n, (pair[bad] if bad >= 0 else -1)


@njit(cache=True)
def _kernel(Kp, sh, sel, units, centres, meridians, face, slope_factor, c, par, law):
    """The H2 kernel (friction off) on the candidates ``sel`` at their kernel positions ``Kp`` (m, 10): with zero
    rates (``units`` 0: one row each) or with each of the ``units`` kernel rates (the half end's 8, the spin) set to
    1 in turn (``units`` rows each).  Returns ``(outputs, slips, first bad row or -1)``."""
    rows = max(units, 1)
    kin = np.zeros((sel.shape[0] * rows, 2 * N_HALF + 1))
    shb = np.empty(sel.shape[0] * rows, np.int64)
    for q in range(sel.shape[0]):
        for r in range(rows):
            b = q * rows + r
            shb[b] = sh[sel[q]]
            _gather_in(Kp[sel[q]], True, kin[b, :N_HALF])
            if units > 0:
                kin[b, N_HALF + r] = 1.0
    Xk = np.empty((kin.shape[0], 2 * N_KERNEL + 1))
    _half_spread(kin, Xk, N_KERNEL)
    Yk = np.empty((kin.shape[0], N_KERNEL + 2))
    slip, fr = np.empty((kin.shape[0], 3)), np.empty((kin.shape[0], 3))
    bad = refined_local_kernel(Xk, shb, centres, meridians, face, True, slope_factor, c, 0.0, par[1], law, par[2],
                               Yk, slip, fr)
    return Yk, slip, bad
