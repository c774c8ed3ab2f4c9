"""The pin-sheave friction of variant (e) on elastic shafts as a linear slip map at frozen positions.

The elastic twin of :mod:`~cvtfem.elements.chain.half_end_slips`: every H2 half-end contact sits in the frame of its
displaced, tilted sheave (:mod:`~cvtfem.elements.chain.mapped_contact_kernel`), whose kernel rates are ``dK P'``, linear
in the mapped rates ``P'`` (the half end, its chord, ``x3``, slope, the sheave's translation, tilt, the other sheave's
axial position) and the spin.  With the positions frozen the slip of a contact in touch is therefore ``s = G v`` (3
components: the tangent-plane relative velocity, m/s), read from the kernel itself: one evaluation with the rates zero (its
normal force, friction off) and one per mapped rate set to 1 (that slip is ``G``'s column), mapped to the state's
velocities through the pair table, in the orthonormal basis of the tangent plane of
:func:`~cvtfem.elements.chain.half_end_slips._plane` (2 rows a contact, as the rigid shafts' map).  The contact's
friction forces are ``-G^T (N psi(|s|) s)``, those of :func:`mapped_contact_kernel.forces`.  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.half_end_contact import _spread as _half_spread
from cvtfem.elements.chain.half_end_slips import _plane
from cvtfem.elements.chain.mapped_contact_kernel import (N_FRAME, N_KERNEL, N_PATTERN, PATTERN, _candidates,
                                                         _gather_in, _spread_in, frame_a1)
from cvtfem.elements.chain.sheave_contact_refined_kernel import refined_local_kernel
from cvtfem.elements.jit import njit

__all__ = ["slip_map"]

_PAT_ROW, _PAT_COL = PATTERN
#: The half-end contact's kernel positions (end 2, chord 2, ``x3``, slope 2, ``z``).
N_HALF = 8


@njit(cache=True)
def slip_map(y, cols, coef, shaft, sheave, centres, r2, frame, ends, meridians, face, slope_factor, c, par, law,
             n2, N, r_out, c_out, v_out):
    """The H2 half-end contacts in touch at the positions of ``y = [q, v]`` (mapped pair table ``cols``, ``coef``,
    ``shaft``, ``sheave``; the constants of :func:`mapped_contact_kernel.pack_refined` for half ends): their normal
    forces into ``N`` and the entries of ``G`` (2 rows per contact: the slip in the basis of its tangent plane;
    columns the velocities ``v`` (n2,); duplicates to be summed) into ``r_out``, ``c_out``, ``v_out``.  Returns
    ``(contacts, entries, first pair with its half end on the shaft axis or -1)``; ``N`` needs ``cols.shape[0]``
    places, the entries ``2 cols.shape[0] cols.shape[1] cols.shape[2]``."""
    n_pairs, n_in, K = cols.shape[0], cols.shape[1], cols.shape[2]
    n_p = (n_in - 1) // 2
    Zall, sh, pair = np.empty((n_pairs, n_in)), np.empty(n_pairs, np.int64), np.empty(n_pairs, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, ends, Zall, sh, pair)
    rows = n_p + 2                                   # rates zero, then each mapped rate and the spin set to 1
    kin = np.zeros((m * rows, 2 * N_HALF + 1))
    shb = np.empty(m * rows, np.int64)
    P, V, Kp, Kd, dK = np.empty(N_FRAME), np.zeros(N_FRAME), np.empty(N_KERNEL), np.empty(N_KERNEL), np.empty(N_PATTERN)
    Zr = np.empty(n_in)
    for t in range(m):
        k, j = sh[t], sheave[pair[t]]
        _spread_in(Zall[t], 0, True, P)
        frame_a1(P, frame[0, k, j], centres[k, 0], centres[k, 1], frame[1, k, j], frame[2, k, j], Kp, dK)
        for r in range(rows):
            b = t * rows + r
            shb[b] = k
            _gather_in(Kp, True, kin[b, :N_HALF])
            for i in range(n_in):
                Zr[i] = 0.0
            if 0 < r <= n_p:
                Zr[n_p + r - 1] = 1.0
            _spread_in(Zr, n_p, True, V)
            for i in range(N_KERNEL):
                Kd[i] = 0.0
            for e in range(N_PATTERN):
                Kd[_PAT_ROW[e]] += dK[e] * V[_PAT_COL[e]]
            _gather_in(Kd, True, kin[b, N_HALF:2 * N_HALF])
            kin[b, 2 * N_HALF] = 1.0 if r == rows - 1 else 0.0
    Xk = np.empty((m * rows, 2 * N_KERNEL + 1))
    _half_spread(kin, Xk, N_KERNEL)
    Yk = np.empty((m * rows, N_KERNEL + 2))
    slip, fr = np.empty((m * rows, 3)), np.empty((m * rows, 3))
    bad = refined_local_kernel(Xk, shb, centres, meridians, face, True, slope_factor, c, 0.0, par[1], law, par[2],
                               Yk, slip, fr)
    k_out = n = 0
    basis = np.empty((2, 3))
    for t in range(m):
        normal = -par[3] * Yk[t * rows, 6]              # the kernel's 2 (s N + F_3) at side s = -1, friction off, scaled
        if not normal > 0.0:
            continue
        N[k_out] = normal
        _plane(slip[t * rows + 1:(t + 1) * rows], basis)
        i = pair[t]
        for r in range(1, rows):
            j = n_p + r - 1 if r <= n_p else 2 * n_p      # the mapped rate's slot, then the spin's
            e = slip[t * rows + r]
            for a in range(K):
                col, w = cols[i, j, a], coef[i, j, a]
                if w == 0.0 or col < n2 or col >= 2 * n2:
                    continue
                for d in range(2):
                    r_out[n], c_out[n] = 2 * k_out + d, col - n2
                    v_out[n] = w * (basis[d, 0] * e[0] + basis[d, 1] * e[1] + basis[d, 2] * e[2])
                    n += 1
        k_out += 1
    return k_out, n, (pair[bad // rows] if bad >= 0 else -1)
