"""The pin-sheave friction of variant (e) (H2 at the pin-half ends) as a linear slip map at frozen positions.

With the positions frozen, the slip of every H2 contact is linear in the velocities, ``s_k = G_k v`` (2 rows per
contact: the relative velocity at the contact point projected on its tangent plane, m/s, in an orthonormal basis of
that plane), its normal force ``N_k`` (N) is fixed, and the friction forces are ``Q = -G^T (N psi(|s|) s)`` per contact
(the friction power ``F . s`` the contact kernel books): the friction of
:func:`~cvtfem.elements.chain.half_end_contact_kernel.forces` exactly.  :func:`slip_map` reads ``G`` from the contact
kernel itself (no copy of its geometry),
:func:`~cvtfem.elements.chain.sheave_contact_refined_kernel.refined_local_kernel`: on the candidate contacts with zero
velocities (their normal forces, friction off), then on those in touch with each velocity input set to 1 in turn (the
slip is linear in them: that slip is ``G``'s column).
Arguments as :func:`half_end_contact_kernel.forces`'.  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.half_end_contact import N_POS, _spread
from cvtfem.elements.chain.half_end_contact_kernel import N_IN, N_OUT, _candidates
from cvtfem.elements.chain.sheave_contact_refined_kernel import refined_local_kernel
from cvtfem.elements.contact.kernels import _cross
from cvtfem.elements.jit import njit

__all__ = ["slip_map"]

#: Relative tolerance of a tie in :func:`_plane`'s choices.
TIE = 1e-9
#: Velocity inputs of a pair (its 8 coordinate rates and the shaft speed), the columns of its local slip map.
N_VEL = N_IN - N_POS


@njit(cache=True)
def slip_map(y, cols, coef, shaft, centres, r2, meridians, face_radius, slope_factor, c, par, law, n2,
             N, r_out, c_out, v_out):
    """The contacts in touch at the positions of ``y = [q, v, constants]``: their normal forces into ``N`` and the
    entries of ``G`` (2 rows per contact: the tangent-plane slip in the basis of :func:`_plane`; columns the
    velocities ``v`` (n2,); duplicates to be summed) into ``r_out``, ``c_out``, ``v_out``.  Returns ``(contacts,
    entries, first pair with its half end on the shaft axis or -1)``; ``N`` needs ``cols.shape[0]`` places, the
    entries ``2 cols.shape[0] * N_VEL * cols.shape[2]``."""
    P = cols.shape[0]
    X, sh, pair = np.empty((P, N_IN)), np.empty(P, np.int64), np.empty(P, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, X, sh, pair)
    Y0, _, bad = _local(X, sh, np.arange(m), -1, centres, meridians, face_radius, slope_factor, c, par, law)
    if bad >= 0:
        return 0, 0, pair[bad]
    touch = np.flatnonzero(-0.5 * Y0[:, 6] > 0.0)   # the kernel's 2 (s N + F_3) at side s = -1, friction off
    _, slip, bad = _local(X, sh, touch, N_VEL, centres, meridians, face_radius, slope_factor, c, par, law)
    if bad >= 0:
        return 0, 0, pair[touch[bad // N_VEL]]
    n = 0
    basis = np.empty((2, 3))
    for k in range(touch.shape[0]):
        t = touch[k]
        N[k] = -0.5 * Y0[t, 6]
        _plane(slip[k * N_VEL:(k + 1) * N_VEL], basis)
        i = pair[t]
        for r in range(N_VEL):
            j = N_POS + r
            e = slip[k * N_VEL + r]
            for a in range(cols.shape[2]):
                col, w = cols[i, j, a], coef[i, j, a]
                if w == 0.0 or col < n2 or col >= 2 * n2:
                    continue                      # a constant (the fixed sheave's rate, zero)
                for d in range(2):
                    r_out[n], c_out[n] = 2 * k + d, col - n2
                    v_out[n] = w * (basis[d, 0] * e[0] + basis[d, 1] * e[1] + basis[d, 2] * e[2])
                    n += 1
    return touch.shape[0], n, -1


@njit(cache=True)
def _local(X, sh, sel, units, centres, meridians, face_radius, slope_factor, c, par, law):
    """The H2 kernel on the candidates ``sel`` at their positions: with zero velocities, friction off (``units``
    -1: one row each, its outputs ``Y``), or with each of the ``units`` velocity inputs set to 1 in turn (the slips,
    ``units`` rows each).  Returns ``(Y, slip, first bad row or -1)``."""
    rows = max(units, 1)
    Xb, shb = np.zeros((sel.shape[0] * rows, N_IN)), np.empty(sel.shape[0] * rows, np.int64)
    for t in range(sel.shape[0]):
        for r in range(rows):
            b = t * rows + r
            Xb[b, :N_POS] = X[sel[t], :N_POS]
            if units > 0:
                Xb[b, N_POS + r] = 1.0
            shb[b] = sh[sel[t]]
    Xk, Yk = np.empty((Xb.shape[0], 2 * (N_POS + 2) + 1)), np.empty((Xb.shape[0], N_OUT + 2))
    slip, fr = np.empty((Xb.shape[0], 3)), np.empty((Xb.shape[0], 3))
    _spread(Xb, Xk, N_POS + 2)
    bad = refined_local_kernel(Xk, shb, centres, meridians, face_radius, True, slope_factor, c, 0.0, par[1], law,
                               par[2], Yk, slip, fr)
    return Yk, slip, bad


@njit(cache=True)
def _plane(vectors, basis):
    """An orthonormal ``basis`` (2, 3) of a plane holding all ``vectors`` (rows; slips in one tangent plane): the
    first longest one's direction and, normal to it in the plane, the direction of the first largest cross product
    with it ("first" to :data:`TIE`: a tie of two vectors, e.g. a rate and its sheave's opposite one, does not hang
    on round-off)."""
    best = 0.0
    for r in range(vectors.shape[0]):
        best = max(best, vectors[r, 0] ** 2 + vectors[r, 1] ** 2 + vectors[r, 2] ** 2)
    a = 0
    while vectors[a, 0] ** 2 + vectors[a, 1] ** 2 + vectors[a, 2] ** 2 < (1.0 - TIE) * best:
        a += 1
    t0, t1, t2 = 1.0, 0.0, 0.0
    if best > 0.0:
        root = np.sqrt(vectors[a, 0] ** 2 + vectors[a, 1] ** 2 + vectors[a, 2] ** 2)
        t0, t1, t2 = vectors[a, 0] / root, vectors[a, 1] / root, vectors[a, 2] / root
    big = 0.0
    for r in range(vectors.shape[0]):
        c0, c1, c2 = _cross(t0, t1, t2, vectors[r, 0], vectors[r, 1], vectors[r, 2])
        big = max(big, c0 ** 2 + c1 ** 2 + c2 ** 2)
    n0 = n1 = n2 = q = 0.0
    for r in range(vectors.shape[0]):
        c0, c1, c2 = _cross(t0, t1, t2, vectors[r, 0], vectors[r, 1], vectors[r, 2])
        q = c0 ** 2 + c1 ** 2 + c2 ** 2
        if big > 0.0 and q >= (1.0 - TIE) * big:
            n0, n1, n2 = c0, c1, c2
            break
    if not big > 1e-24 * max(best, 1e-300):         # all along t1 (or zero): any plane through t1
        k = 0
        if abs(t1) < abs(t0):
            k = 1
        if abs(t2) < min(abs(t0), abs(t1)):
            k = 2
        e = (1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0, 1.0 if k == 2 else 0.0)
        n0, n1, n2 = _cross(t0, t1, t2, e[0], e[1], e[2])
        q = 1.0 - (t0, t1, t2)[k] ** 2
    root = np.sqrt(q)
    n0, n1, n2 = n0 / root, n1 / root, n2 / root
    basis[0, 0], basis[0, 1], basis[0, 2] = t0, t1, t2
    basis[1, 0], basis[1, 1], basis[1, 2] = _cross(n0, n1, n2, t0, t1, t2)
