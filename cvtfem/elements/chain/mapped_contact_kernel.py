"""Compiled (numba) contacts in the frames of displaced, tilted sheaves (chains on elastic shafts): broad phase, gather,
frame map, the contact kernel, the forces mapped back, scatter, and the contacts' Jacobian entries.  H2 at whole-pin
ends (variant (b)) or independent half ends (variant (e)); H1 at pin or half ends (variant (zh), A1 with H1) and at
the symmetric chain's pin ends (S2, S3, both sheaves of a shaft per end).

A contact's mapped inputs ``Z`` (``2 n_p + 1``: ``n_p`` positions, their rates, the spin rate) are the chain
positions of the kernel (mirrored frame) followed by the sheave's translation ``a`` (3), tilt ``theta`` (2) and the
other sheave's axial position.  H2: the positions spread to A1's fifteen frame inputs (A5: the half end ``x`` and its
chord ``c`` to the points ``x - c, x, x + c``), :func:`frame_a1` maps them into the sheave's frame
(``X = o + (I - theta x)(x - o - a)``, the slope as a direction, the face at ``z_ref``) with its exact derivative
``dK`` (nonzeros :data:`PATTERN`), gathered back to the contact's positions (A5: end and chord); its rates are
``dK P'`` and its position forces act back through ``dK^T``.  H1: the end ``x`` through the same map (first order in
the tilt), its reaction on the sheave's translation, tilt and (symmetric chain) the pair's mid-plane.  The numpy path
of :class:`~cvtfem.machines.chain_cvt_elastic.ElasticChainCVT` (``mapped_local``, ``_refined_frame``,
``reference=True``) is the tested twin (``tests/machines/test_chain_elastic_compiled.py``).

Arguments shared by the kernels: ``y = [q, v]``; the pair table ``cols``, ``coef`` (P, 2 n_p + 1, K), ``shaft``,
``sheave`` (P,), output rows ``rows``, ``rw`` (P, n_p + 1, K) (``ChainCVT._output_rows``); the constants of
:func:`pack_refined` or :func:`pack_point`.  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.half_end_contact import _gather as _half_gather
from cvtfem.elements.chain.half_end_contact import _spread as _half_spread
from cvtfem.elements.chain.sheave_contact_kernel import _local as _point_local
from cvtfem.elements.chain.sheave_contact_kernel import pack as _pack_point_kernel
from cvtfem.elements.chain.sheave_contact_kernel import scatter_forces, scatter_jacobian
from cvtfem.elements.chain.sheave_contact_refined_kernel import refined_local_kernel
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.contact.kernels import LAW_CODES
from cvtfem.elements.jit import njit

#: A1's frame inputs (three points 6, ``x3``, slope 2, the sheave's translation 3, tilt 2, other axial position 1)
#: and the H2 kernel's positions (three points 6, ``x3``, slope 2, ``z``).
N_FRAME, N_KERNEL = 15, 10


#: Kernel kinds: H2 at a whole-pin end (A1), H2 at an independent half's end (A5), H1 at a point (pin or half end).
REFINED, REFINED_HALF_END, POINT = 0, 1, 2


def _frame(sides, sheave_x3, face_ref) -> np.ndarray:
    """``(3, 2, 2)``: side, pivot ``x3`` (m) and face reference (m) of every (shaft, sheave)."""
    return np.ascontiguousarray(np.stack([np.asarray(a, float) for a in (sides, sheave_x3, face_ref)]))


def pack_refined(pair, sides, sheave_x3, face_ref, end_slots, half_end: bool, scale: float) -> tuple:
    """Constants of the H2 kernels: ``pair`` the :class:`~cvtfem.elements.chain.sheave_contact_refined.
    RefinedSheaveContact` (with slopes), ``sides``, ``sheave_x3`` (m), ``face_ref`` (m) (2, 2) per (shaft, sheave),
    ``end_slots`` the two mapped inputs holding the end's in-plane position (broad phase), ``half_end`` the contact
    is :class:`~cvtfem.elements.chain.half_end_contact.HalfEndContact`'s (A5), ``scale`` the share of the pair
    kernel's outputs one contact carries (0.5: one end)."""
    if not pair.slopes:
        raise ValueError("mapped_contact_kernel.pack_refined: the H2 kernel on elastic shafts has slopes")
    return (np.ascontiguousarray(pair.centres, float), float(pair.r_outer) ** 2,
            _frame(sides, sheave_x3, face_ref), np.asarray(end_slots, np.int64)[:2],
            REFINED_HALF_END if half_end else REFINED, np.ascontiguousarray(pair._meridians, float),
            pair.face, float(END_SLOPE_FACTOR), np.ascontiguousarray(pair.c, float),
            np.array([pair.f0, pair.v0, pair.eps, scale]), LAW_CODES[pair.law], np.zeros((2, 3)), False, 1.0)


def pack_point(pair, sides, sheave_x3, face_ref, scale: float, share: float, axial_relative: bool) -> tuple:
    """Constants of the H1 kernel: ``pair`` the :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact`,
    ``scale`` the share of its outputs the contact object passes on (0.5 inside ``EndContact``, 1 alone), ``share``
    the share one mapped evaluation carries (``kernel_share``), ``axial_relative`` the sheave's axial motion counts
    from the pair's mid-plane (symmetric chain); the rest as :func:`pack_refined`'s."""
    centres, r2, prof, c, par, law = _pack_point_kernel(pair, scale)
    return (centres, r2, _frame(sides, sheave_x3, face_ref), np.array([0, 1], np.int64), POINT, np.zeros((2, 4)),
            np.array([1.0, 0.0]), 1.0, c, par, law, prof, bool(axial_relative), float(share))


def _frame_pattern() -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the nonzeros of A1's frame derivative ``dK`` (10, 15), in :func:`frame_a1`'s order."""
    rows, cols = [], []
    for i in range(3):
        rows += [2 * i] * 5 + [2 * i + 1] * 5
        cols += [2 * i, 6, 9, 11, 13, 2 * i + 1, 6, 10, 11, 12]
    rows += [6] * 8 + [7] * 4 + [8] * 4
    cols += [2, 3, 6, 9, 10, 11, 12, 13] + [7, 8, 12, 13] * 2
    return np.array(rows, np.int64), np.array(cols, np.int64)


#: ``(rows, cols)`` of the nonzeros of the frame derivative (46): ``dK[PATTERN[0][e], PATTERN[1][e]] = dKc[e]``.
PATTERN = _frame_pattern()
N_PATTERN = len(PATTERN[0])
_PAT_ROW, _PAT_COL = PATTERN


@njit(cache=True, inline="always")
def frame_a1(P, s, c0, c1, o3, zf, K, dKc):
    """A1's H2 frame map (``ElasticChainACVT._refined_frame``) of one contact: kernel positions ``K`` (10,) and the
    nonzeros ``dKc`` (46,) of their exact derivative in the frame inputs ``P`` (15,) (:data:`PATTERN`), on the
    sheave of side ``s`` with centre ``(c0, c1)``, pivot ``o3`` and face reference ``zf`` (m)."""
    a0, a1, a2, t1, t2 = P[9], P[10], P[11], P[12], P[13]
    d3 = s * P[6] - o3 - a2
    for i in range(3):
        d1, d2 = P[2 * i] - c0 - a0, P[2 * i + 1] - c1 - a1
        K[2 * i] = c0 + d1 - t2 * d3
        K[2 * i + 1] = c1 + d2 + t1 * d3
        e = 10 * i
        dKc[e], dKc[e + 1], dKc[e + 2], dKc[e + 3], dKc[e + 4] = 1.0, -s * t2, -1.0, t2, -d3
        dKc[e + 5], dKc[e + 6], dKc[e + 7], dKc[e + 8], dKc[e + 9] = 1.0, s * t1, -1.0, -t1, d3
        if i == 1:
            K[6] = s * (o3 + d3 - t1 * d2 + t2 * d1)
            dKc[30], dKc[31], dKc[32], dKc[33] = s * t2, -s * t1, s * s, -s * t2
            dKc[34], dKc[35], dKc[36], dKc[37] = s * t1, -s, -s * d2, s * d1
    e = END_SLOPE_FACTOR
    g = s * e
    sg1, sg2 = P[7], P[8]
    n1, n2 = sg1 - s * t2 / e, sg2 + s * t1 / e
    den = 1.0 + g * (t2 * sg1 - t1 * sg2)
    K[7], K[8] = n1 / den, n2 / den
    dd7, dd8, dd12, dd13 = g * t2, -g * t1, -g * sg2, g * sg1
    dKc[38] = (1.0 - n1 * dd7 / den) / den
    dKc[39] = (0.0 - n1 * dd8 / den) / den
    dKc[40] = (0.0 - n1 * dd12 / den) / den
    dKc[41] = (-s / e - n1 * dd13 / den) / den
    dKc[42] = (0.0 - n2 * dd7 / den) / den
    dKc[43] = (1.0 - n2 * dd8 / den) / den
    dKc[44] = (s / e - n2 * dd12 / den) / den
    dKc[45] = (0.0 - n2 * dd13 / den) / den
    K[9] = zf


@njit(cache=True, inline="always")
def _spread_in(Z, off, half_end, P):
    """A1's frame inputs ``P`` (15,) from the mapped positions ``Z[off:off + n_p]``: A5 (``half_end``) the points
    ``x - c, x, x + c`` of the half end ``x`` and its chord ``c``, then ``x3``, slope, the sheave's six
    (``chain_halves_elastic_cvt.SPREAD``); A1 the same fifteen."""
    if half_end:
        P[0], P[1] = Z[off] - Z[off + 2], Z[off + 1] - Z[off + 3]
        P[2], P[3] = Z[off], Z[off + 1]
        P[4], P[5] = Z[off] + Z[off + 2], Z[off + 1] + Z[off + 3]
        for i in range(9):
            P[6 + i] = Z[off + 4 + i]
    else:
        for i in range(N_FRAME):
            P[i] = Z[off + i]


@njit(cache=True, inline="always")
def _spread_back(F, half_end, Qp):
    """Transpose of :func:`_spread_in`: the forces ``Qp`` (n_p,) on the mapped positions from those ``F`` (15,)."""
    if half_end:
        Qp[0], Qp[1] = F[0] + F[2] + F[4], F[1] + F[3] + F[5]
        Qp[2], Qp[3] = F[4] - F[0], F[5] - F[1]
        for i in range(9):
            Qp[4 + i] = F[6 + i]
    else:
        for i in range(N_FRAME):
            Qp[i] = F[i]


@njit(cache=True, inline="always")
def _frame_back(Y, half_end, dK, Y10, F, Qp):
    """The mapped contact's outputs ``Qp`` (n_p,) on the mapped positions from the kernel's ``Y`` (its outputs, or a
    slip component): :func:`_gather_back`, the frame map's transpose ``dK^T`` on :data:`PATTERN` (``dK`` (46,) of the
    contact), :func:`_spread_back`; ``Y10`` (10,) and ``F`` (15,) scratch."""
    _gather_back(Y, half_end, Y10)
    for b in range(N_FRAME):
        F[b] = 0.0
    for e in range(N_PATTERN):
        F[_PAT_COL[e]] += dK[e] * Y10[_PAT_ROW[e]]
    _spread_back(F, half_end, Qp)


@njit(cache=True, inline="always")
def _gather_in(K, half_end, out):
    """The contact's positions ``out`` from the ten mapped kernel positions ``K``: A5 the end, half the front less
    the rear point (the chord), ``x3``, slope, ``z`` (``chain_halves_elastic_cvt.GATHER``); A1 the ten."""
    if half_end:
        out[0], out[1] = K[2], K[3]
        out[2], out[3] = -0.5 * K[0] + 0.5 * K[4], -0.5 * K[1] + 0.5 * K[5]
        for i in range(4):
            out[4 + i] = K[6 + i]
    else:
        for i in range(N_KERNEL):
            out[i] = K[i]


@njit(cache=True, inline="always")
def _gather_back(Y, half_end, Y10):
    """Transpose of :func:`_gather_in`: the forces ``Y10`` (10,) on the mapped kernel positions from the contact's."""
    if half_end:
        Y10[0], Y10[1] = -0.5 * Y[2], -0.5 * Y[3]
        Y10[2], Y10[3] = Y[0], Y[1]
        Y10[4], Y10[5] = 0.5 * Y[2], 0.5 * Y[3]
        for i in range(4):
            Y10[6 + i] = Y[4 + i]
    else:
        for i in range(N_KERNEL):
            Y10[i] = Y[i]


@njit(cache=True)
def _refined_outputs(Z, sh, sv, centres, frame, kind, meridians, face, slope_factor, c, par, law, R, dK):
    """:func:`mapped_outputs` of H2 contacts (``ElasticChainACVT.mapped_local``)."""
    m, n_p = Z.shape[0], (Z.shape[1] - 1) // 2
    half_end = kind == REFINED_HALF_END
    n_c = 8 if half_end else N_KERNEL
    P, V, K, Kd = np.empty(N_FRAME), np.empty(N_FRAME), np.empty(N_KERNEL), np.empty(N_KERNEL)
    kin = np.empty((m, 2 * n_c + 1))
    for t in range(m):
        k, j = sh[t], sv[t]
        _spread_in(Z[t], 0, half_end, P)
        _spread_in(Z[t], n_p, half_end, V)
        frame_a1(P, frame[0, k, j], centres[k, 0], centres[k, 1], frame[1, k, j], frame[2, k, j], K, dK[t])
        for i in range(N_KERNEL):
            Kd[i] = 0.0
        for e in range(N_PATTERN):
            Kd[_PAT_ROW[e]] += dK[t, e] * V[_PAT_COL[e]]
        _gather_in(K, half_end, kin[t, :n_c])
        _gather_in(Kd, half_end, kin[t, n_c:2 * n_c])
        kin[t, 2 * n_c] = Z[t, 2 * n_p]
    Yk = np.empty((m, N_KERNEL + 2))
    slip, fr = np.empty((m, 3)), np.empty((m, 3))
    if half_end:
        Xk = np.empty((m, 2 * N_KERNEL + 1))
        _half_spread(kin, Xk, N_KERNEL)
        bad = refined_local_kernel(Xk, sh, centres, meridians, face, True, slope_factor, c, par[0], par[1],
                                   law, par[2], Yk, slip, fr)
        Y = np.empty((m, n_c + 2))
        _half_gather(Yk, Y)
    else:
        bad = refined_local_kernel(kin, sh, centres, meridians, face, True, slope_factor, c, par[0], par[1],
                                   law, par[2], Yk, slip, fr)
        Y = Yk
    Y10, F = np.empty(N_KERNEL), np.empty(N_FRAME)
    Qp = np.empty(n_p)
    for t in range(m):
        _frame_back(Y[t], half_end, dK[t], Y10, F, Qp)
        for o in range(n_p):
            R[t, o] = par[3] * Qp[o]
        R[t, n_p] = par[3] * Y[t, n_c]
        R[t, n_p + 1] = par[3] * Y[t, n_c + 1]
    return bad


@njit(cache=True)
def _point_outputs(Z, sh, sv, centres, frame, c, par, law, prof, axial_relative, share, R):
    """:func:`mapped_outputs` of H1 contacts (``ElasticChainCVT.mapped_local``): the end ``x`` (mirrored,
    ``x3 -> s x3``) mapped to ``X = o + (I - theta x)(x - o - a)``, the kernel's force ``F`` back through
    ``(I - theta x)^T`` on the end, minus it on the sheave's translation, ``-(d x F)`` on its tilt."""
    Zk, Yk = np.zeros(9), np.zeros(6)
    for t in range(Z.shape[0]):
        k, j = sh[t], sv[t]
        s, o0, o1, o2 = frame[0, k, j], centres[k, 0], centres[k, 1], frame[1, k, j]
        t1, t2 = Z[t, 6], Z[t, 7]
        a2, va2 = Z[t, 5], Z[t, 14]
        if axial_relative:                                   # from the pair's mid-plane
            a2, va2 = 0.5 * (Z[t, 5] - Z[t, 8]), 0.5 * (Z[t, 14] - Z[t, 17])
        d0, d1, d2 = Z[t, 0] - o0 - Z[t, 3], Z[t, 1] - o1 - Z[t, 4], s * Z[t, 2] - o2 - a2
        e0, e1, e2 = Z[t, 9] - Z[t, 12], Z[t, 10] - Z[t, 13], s * Z[t, 11] - va2
        w1, w2 = Z[t, 15], Z[t, 16]
        Zk[0] = o0 + d0 - t2 * d2
        Zk[1] = o1 + d1 + t1 * d2
        Zk[2] = s * (o2 + d2 - (t1 * d1 - t2 * d0))
        Zk[3] = frame[2, k, j]
        Zk[4] = e0 - t2 * e2 - w2 * d2
        Zk[5] = e1 + t1 * e2 + w1 * d2
        Zk[6] = s * (e2 - (t1 * e1 - t2 * e0) - (w1 * d1 - w2 * d0))
        Zk[7], Zk[8] = 0.0, Z[t, 18]
        _point_local(Zk, k, centres, prof, c, par, law, Yk)
        F0, F1, F2 = share * Yk[0], share * Yk[1], s * share * Yk[2]
        Q0, Q1, Q2 = F0 + t2 * F2, F1 - t1 * F2, F2 + t1 * F1 - t2 * F0
        R[t, 0], R[t, 1], R[t, 2] = Q0, Q1, s * Q2
        R[t, 3], R[t, 4], R[t, 5] = -Q0, -Q1, -Q2
        R[t, 8] = 0.0
        if axial_relative:
            R[t, 5] = -0.5 * Q2
            R[t, 8] = 0.5 * Q2
        R[t, 6] = -(d1 * F2 - d2 * F1)
        R[t, 7] = -(d2 * F0 - d0 * F2)
        R[t, 9], R[t, 10] = share * Yk[4], share * Yk[5]
    return -1


@njit(cache=True)
def mapped_outputs(Z, sh, sv, centres, frame, kind, meridians, face, slope_factor, c, par, law, prof,
                   axial_relative, share, R, dK):
    """Outputs ``R`` (m, n_p + 2) of the mapped contacts with inputs ``Z`` (m, 2 n_p + 1) on shafts ``sh``, sheaves
    ``sv``: the generalized forces on the ``n_p`` mapped positions, on the spin, the friction power (W), as
    ``ElasticChainCVT.mapped_local``; ``dK`` (m, 46) scratch for H2's frame derivatives.  Returns the first contact
    with its end on the shaft axis (H2), or -1."""
    if kind == POINT:
        return _point_outputs(Z, sh, sv, centres, frame, c, par, law, prof, axial_relative, share, R)
    return _refined_outputs(Z, sh, sv, centres, frame, kind, meridians, face, slope_factor, c, par, law, R, dK)


@njit(cache=True)
def _candidates(y, cols, coef, shaft, centres, r2, ends, Zall, sh, pair):
    """Broad phase and gather: the inputs ``Zall[:m]``, shafts ``sh[:m]`` and pair indices ``pair[:m]`` of the ``m``
    (returned) pairs whose end (mapped inputs ``ends``) lies within the outer radius of its shaft."""
    m = 0
    K = cols.shape[2]
    for i in range(cols.shape[0]):
        k = shaft[i]
        d0 = -centres[k, 0]
        d1 = -centres[k, 1]
        for a in range(K):
            d0 += coef[i, ends[0], a] * y[cols[i, ends[0], a]]
            d1 += coef[i, ends[1], a] * y[cols[i, ends[1], a]]
        if not d0 * d0 + d1 * d1 < r2:
            continue
        for j in range(cols.shape[1]):
            acc = 0.0
            for a in range(K):
                acc += coef[i, j, a] * y[cols[i, j, a]]
            Zall[m, j] = acc
        sh[m], pair[m] = k, i
        m += 1
    return m


@njit(cache=True)
def forces(y, cols, coef, shaft, sheave, rows, rw, centres, r2, frame, ends, kind, meridians, face,
           slope_factor, c, par, law, prof, axial_relative, share, Q):
    """Add the mapped contacts' generalized forces to ``Q`` (n2,); returns ``(friction power (W, <= 0), first pair
    with its end on the shaft axis or -1)``."""
    n_pairs, n_in = cols.shape[0], cols.shape[1]
    Zall, sh, pair = np.empty((n_pairs, n_in)), np.empty(n_pairs, np.int64), np.empty(n_pairs, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, ends, Zall, sh, pair)
    sv = sheave[pair[:m]]
    n_out = rows.shape[1] + 1
    R, dK = np.empty((m, n_out)), np.empty((m, N_PATTERN))
    bad = mapped_outputs(Zall[:m], sh[:m], sv, centres, frame, kind, meridians, face, slope_factor, c,
                         par, law, prof, axial_relative, share, R, dK)
    return scatter_forces(pair[:m], R, rows, rw, Q), (pair[bad] if bad >= 0 else -1)


@njit(cache=True)
def jacobian(y, cols, coef, shaft, sheave, rows, rw, centres, r2, frame, ends, kind, meridians, face,
             slope_factor, c, par, law, prof, axial_relative, share, steps, n_state, r_out, c_out, v_out, dD):
    """Entries of ``dQ/dy`` of :func:`forces` (over ``y[:n_state]``) into ``r_out``, ``c_out``, ``v_out`` (their count
    returned) and ``-d(friction power)/dy`` added to ``dD``: the mapped contacts' local Jacobians by central
    differences with ``steps`` (one perturbed input column for all candidates at once, as
    ``central_local_jacobian``), mapped on both sides ``R^T (dY/dZ) P``.  Returns ``(count, bad pair or -1)``."""
    n_pairs, n_in = cols.shape[0], cols.shape[1]
    Zall, sh, pair = np.empty((n_pairs, n_in)), np.empty(n_pairs, np.int64), np.empty(n_pairs, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, ends, Zall, sh, pair)
    Z0, sh = Zall[:m], sh[:m]
    sv = sheave[pair[:m]]
    n_out = rows.shape[1] + 1
    Zs, Rp, Rm = Z0.copy(), np.empty((m, n_out)), np.empty((m, n_out))
    dK = np.empty((m, N_PATTERN))
    Jl = np.empty((m, n_out, n_in))
    bad = -1
    for j in range(n_in):
        for t in range(m):
            Zs[t, j] = Z0[t, j] + steps[j]
        b1 = mapped_outputs(Zs, sh, sv, centres, frame, kind, meridians, face, slope_factor, c, par,
                            law, prof, axial_relative, share, Rp, dK)
        for t in range(m):
            Zs[t, j] = Z0[t, j] - steps[j]
        b2 = mapped_outputs(Zs, sh, sv, centres, frame, kind, meridians, face, slope_factor, c, par,
                            law, prof, axial_relative, share, Rm, dK)
        for t in range(m):
            Zs[t, j] = Z0[t, j]
        if bad < 0 and max(b1, b2) >= 0:
            bad = pair[max(b1, b2)]
        for t in range(m):
            for o in range(n_out):
                Jl[t, o, j] = (Rp[t, o] - Rm[t, o]) / (2 * steps[j])
    n = scatter_jacobian(pair[:m], Jl, cols, coef, rows, rw, n_state, dD, r_out, c_out, v_out)
    return n, bad


__all__ = ["N_FRAME", "N_KERNEL", "PATTERN", "POINT", "REFINED", "REFINED_HALF_END", "forces", "frame_a1", "jacobian",
           "mapped_outputs", "pack_point", "pack_refined"]
