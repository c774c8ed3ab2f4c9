"""Compiled force pass and Jacobian (numba) of the A5 chain with independent pin halves, element by element.

The pass is a sum of link elements (:func:`_link`: plates at the variable stations (1.211)-(1.212) through the
virtual-pin map and the per-plate law of :mod:`plates_kernel`, twist (1.146), (1.217)) and pin elements
(:func:`_pin`: half axial and bending (1.214), (1.216), the three arc contacts with damping, tie and rolling
friction, stoppers, axial friction (1.221), joint damping (1.80)), gathered and scattered through index tables.
:func:`forces` sums them; :func:`jacobian` differentiates each element alone (exact link velocity blocks,
differences of one link or one pin) into the CSR data of the Jacobian pattern.  The numpy methods of
:class:`~cvtfem.elements.chain.halves.ChainA5` are the reference twin (``tests/elements/chain/test_halves_kernel.py``).
Arguments: state ``q`` and velocity ``v`` (21 n, layout of ``ChainA5``) and the constant tuple of :func:`pack`.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.plates_kernel import _plate_law, _strain_rates
from cvtfem.elements.contact.kernels import LAW_CODES, _gain
from cvtfem.elements.jit import HAVE_NUMBA, njit

#: ``friction_gain``'s default blend width of the ``smooth`` law, as the numpy twin calls it.
SMOOTH_EPS = 0.1
_G = 1.0 / np.sqrt(3.0)


def pack(ch, contacts) -> tuple:
    """Kernel constants of a :class:`ChainA5` with its ``contacts`` table (built once per family).

    Index tables ``gl (n, 22)`` (each link's local coordinates in ``q``) and ``gp (n, 29)`` (each pin's, see
    :func:`_pin`); per contact one row ``arc = (offset of A's centre along tau, n; R_A; offset of B's; R_B;
    rho_0; k)``.
    """
    n, di, al = ch.n_pins, ch.dof_index, ch.axis_link
    nx = (np.arange(n) + 1) % n
    gl = np.concatenate([di[:, :10], di[nx, 10:20], di[:, 20:], di[nx, 20:]], 1)
    gp = np.concatenate([di, di[al[0], :2], di[nx[al[0]], 10:12], di[al[1], :2], di[nx[al[1]], 10:12]], 1)
    arcs = [ch._arcs[c[0]] for c in contacts]
    arc = np.array([[a[0][0], a[0][1], a[1], a[2][0], a[2][1], a[3], a[4], a[5]] for a in arcs])
    idx = np.array([[c[1], c[2]] for c in contacts], np.int64)
    sig = np.array([c[3] for c in contacts])
    cw = np.stack([ch._contact_w[c[0]] for c in contacts])
    par = np.array([ch.l, ch.c_half, ch.b_half, ch.A_tau, ch.A_n, ch.beta_bend, ch.beta_ext, ch.beta_shear,
                    ch.beta_twist, ch.b_roll, ch.k_tie, ch.k_stop, ch.d_stop, ch.f0, ch.v0, ch.plate_h])
    ints = np.array([LAW_CODES[ch.law], ch._kmodel], np.int64)
    return tuple(np.ascontiguousarray(a) for a in (gl, gp, ch.L, ch.c_twist, ch.b_joint, ch._cs, ch.plate_w,
                                                   ch.plate_d, ch.plate_c, ch.plate_c1, ch.plate_c2, arc, idx,
                                                   sig, cw, par, ints))


def positions(args: tuple, dof_index: np.ndarray, pattern) -> tuple[np.ndarray, ...]:
    """Positions in the data of the sorted CSR ``pattern`` of the link blocks ``(n, 22, 22)``, the pin blocks
    ``(n, 29, 29)`` and the axial-friction rows against the tensions' link coordinates ``(n, 2, 3, 22)``, and
    ``first (n, 29)``: the first local copy of each pin coordinate (the link ends repeat pin coordinates).

    Entries outside the pattern (only the absent link of an open segment, whose terms are all zero) point to
    the spare slot ``pattern.nnz``: the data arrays have ``nnz + 1`` entries.
    """
    gl, gp, link_w = args[0], args[1], args[6].any(1) | (args[3] != 0)
    n = gl.shape[0]
    lut = np.full(pattern.shape, pattern.nnz, np.int64)
    rows = np.repeat(np.arange(pattern.shape[0]), np.diff(pattern.indptr))
    lut[rows, pattern.indices] = np.arange(pattern.nnz)
    pos_l = lut[gl[:, :, None], gl[:, None, :]]
    pos_p = lut[gp[:, :, None], gp[:, None, :]]
    links = np.stack([np.arange(n), (np.arange(n) - 1) % n], 1)               # tension of (p, p+1), (p-1, p)
    fr = dof_index[:, [8, 18, 20]]                                            # w_0-, w_0+, q_p
    pos_t = lut[fr[:, None, :, None], gl[links][:, :, None, :]]
    if max(pos_l[link_w].max(), pos_p.max(), pos_t[link_w[links]].max()) == pattern.nnz:
        raise AssertionError("halves_kernel.positions: an element block reaches outside the Jacobian pattern")
    first = np.argmax(gp[:, :, None] == gp[:, None, :], axis=2)
    return pos_l, pos_p, pos_t, first


@njit(cache=True)
def _shape(xi, l, H, Hp, Hpp):
    """``h_i``, ``h_i'``, ``h_i''`` of (1.132) at ``xi`` into ``H``, ``Hp``, ``Hpp`` (4,)."""
    l8 = l / 8.0
    H[0], H[1], H[2], H[3] = 1.0, xi, l8 * (1 - xi) ** 2 * (1 + xi), l8 * (xi - 1) * (1 + xi) ** 2
    Hp[0], Hp[1], Hp[2], Hp[3] = 0.0, 1.0, l8 * (-1 - 2 * xi + 3 * xi * xi), l8 * (-1 + 2 * xi + 3 * xi * xi)
    Hpp[0], Hpp[1], Hpp[2], Hpp[3] = 0.0, 0.0, l8 * (6 * xi - 2), l8 * (6 * xi + 2)


# ---------------------------------------------------------------------------------------------- links
@njit(cache=True)
def _link_work():
    """Scratch arrays of :func:`_link` (``J`` zero: :func:`_virtual_strains` writes only its nonzero columns); the
    last accumulates the power of the link damping forces (W)."""
    return (np.zeros(20), np.zeros(20), np.zeros(20), np.zeros((3, 4)), np.zeros((3, 4)), np.zeros((3, 20)),
            np.zeros((3, 3)), np.zeros(3), np.zeros((2, 3)), np.zeros(3), np.zeros(3), np.zeros(10), np.zeros(22),
            np.zeros(20), np.zeros((3, 22)), np.zeros(1))


@njit(cache=True)
def _virtual_pin(x, xd, b, d, l, qv, qvd, Hm):
    """End ``b`` of a plate at offset ``d`` as a virtual whole pin at ``xi = 0`` (``qv``, ``qvd`` entries
    ``10 b .. 10 b + 9``): ``u_0 = U_perp(xi_b)``, ``u_1 = dU_perp/dxi``, ``u_2 = u_3 = 0``, ``w_0 = U_par(xi_b)``,
    ``w_1``, the same strains as the half's axis (1.211)-(1.212).  ``Hm`` (3, 4) gets ``h, h', h''``; returns
    ``xi_b``."""
    o = 10 * b
    xi = 2.0 / l * (x[20 + b] - x[o + 8] + d)
    xid = 2.0 / l * (xd[20 + b] - xd[o + 8])
    _shape(xi, l, Hm[0], Hm[1], Hm[2])
    for c in range(2):
        U, u1, du1, Ud, u1d = 0.0, 0.0, 0.0, 0.0, 0.0
        for i in range(4):
            U += Hm[0, i] * x[o + 2 * i + c]
            u1 += Hm[1, i] * x[o + 2 * i + c]
            du1 += Hm[2, i] * x[o + 2 * i + c]
            Ud += Hm[0, i] * xd[o + 2 * i + c]
            u1d += Hm[1, i] * xd[o + 2 * i + c]
        qv[o + c], qv[o + 2 + c], qv[o + 4 + c], qv[o + 6 + c] = U, u1, 0.0, 0.0
        qvd[o + c], qvd[o + 2 + c], qvd[o + 4 + c], qvd[o + 6 + c] = Ud + u1 * xid, u1d + du1 * xid, 0.0, 0.0
    qv[o + 8], qv[o + 9] = x[o + 8] + x[o + 9] * xi, x[o + 9]
    qvd[o + 8], qvd[o + 9] = xd[o + 8] + xd[o + 9] * xi + x[o + 9] * xid, xd[o + 9]
    return xi


@njit(cache=True)
def _virtual_strains(qv, l, L, J, tau, e):
    """``(psi_1, psi_2, Delta)`` of a plate between two virtual pins (``xi = 0``, ``u_2 = u_3 = 0``): the strains
    (1.186)-(1.189) of ``plates_kernel._strains`` there, ``V = u_0+ - u_0-``, ``t_a = (2/l u_1, 1)``.  Fills the
    columns ``u_0``, ``u_1``, ``w_0`` of ``J`` (3, 20); the others (``u_2``, ``u_3``, ``w_1``) stay zero."""
    V0, V1, V2 = qv[10] - qv[0], qv[11] - qv[1], qv[18] - qv[8]
    Lt = np.sqrt(V0 * V0 + V1 * V1 + V2 * V2)
    tau[0], tau[1], tau[2] = V0 / Lt, V1 / Lt, V2 / Lt
    psi = (tau[0] * 2.0 / l * qv[2] + tau[1] * 2.0 / l * qv[3] + tau[2],
           tau[0] * 2.0 / l * qv[12] + tau[1] * 2.0 / l * qv[13] + tau[2])
    for a in range(2):
        o = 10 * a
        e[a, 0] = (2.0 / l * qv[o + 2] - tau[0] * psi[a]) / Lt
        e[a, 1] = (2.0 / l * qv[o + 3] - tau[1] * psi[a]) / Lt
        e[a, 2] = (1.0 - tau[2] * psi[a]) / Lt
    for b in range(2):
        o = 10 * b
        sg = 2.0 * b - 1.0
        for x in range(2):
            J[0, o + x], J[1, o + x], J[2, o + x] = sg * e[0, x], sg * e[1, x], sg * tau[x]
            J[b, o + 2 + x] = 2.0 / l * tau[x]
        J[0, o + 8], J[1, o + 8], J[2, o + 8] = sg * e[0, 2], sg * e[1, 2], sg * tau[2]
    return psi[0], psi[1], Lt - L


@njit(cache=True)
def _back(out, f, x, b, xi, Hm, l):
    """Add ``G_b^T f`` to ``out`` (22,): a vector ``f`` (20,) on the virtual pin ``b`` mapped back to the link's
    local coordinates (the transpose of :func:`_virtual_pin`'s linearisation, ``xi_b`` moving with ``q``, ``w_0``)."""
    o = 10 * b
    S = f[o + 8] * x[o + 9]
    for c in range(2):
        u1, du1 = 0.0, 0.0
        for i in range(4):
            out[o + 2 * i + c] += Hm[0, i] * f[o + c] + Hm[1, i] * f[o + 2 + c]
            u1 += Hm[1, i] * x[o + 2 * i + c]
            du1 += Hm[2, i] * x[o + 2 * i + c]
        S += f[o + c] * u1 + f[o + 2 + c] * du1
    out[o + 8] += f[o + 8] - 2.0 / l * S
    out[o + 9] += f[o + 8] * xi + f[o + 9]
    out[20 + b] += 2.0 / l * S


@njit(cache=True)
def _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, loc, Dv, want_dv, wk):
    """Plates (per-plate law, elastic plus damping) and twist (1.146), (1.217) of link ``e`` on its 22 local
    coordinates ``x`` (half ``-`` of pin ``e``, half ``+`` of pin ``e+1``, ``q_e``, ``q_{e+1}``; layout of
    ``ChainA5._links``) and velocities ``xd``.  Adds the forces to ``loc`` (22,) and, with ``want_dv``,
    their exact velocity derivative (they are linear in ``xd``) to ``Dv`` (22, 22; symmetric, the upper triangle
    overwritten).  Returns the link tension (N).
    """
    qv, qvd, Qf, Ha, Hb, J, A, V, ev, ed, r, m, Jp, row, AJG, pw_ = wk
    l, beta_ext, beta_shear, beta_twist, h_pl = par[0], par[6], par[7], par[8], par[15]
    Le = L[e]
    T = 0.0
    for k in range(plate_w.shape[1]):
        pw = plate_w[e, k]
        if pw == 0.0:
            continue
        xa = _virtual_pin(x, xd, 0, plate_d[e, k], l, qv, qvd, Ha)
        xb = _virtual_pin(x, xd, 1, plate_d[e, k], l, qv, qvd, Hb)
        c, c1, c2 = plate_c[e, k], plate_c1[e, k], plate_c2[e, k]
        psi1, psi2, Delta = _virtual_strains(qv, l, Le, J, V, ev)
        st, d1, d2, tension = _plate_law(kmodel, psi1, psi2, Delta, c, c1, c2, h_pl, A, m)
        z1, z2 = psi1 - d1, psi2 - d2
        _strain_rates(J, qvd, A, ed, r)
        s0 = c1 * z1 + c2 * z2 + beta_shear * (c1 * r[0] + c2 * r[1])
        s1 = c2 * z1 + c1 * z2 + beta_shear * (c2 * r[0] + c1 * r[1])
        s2 = tension + beta_ext * c * r[2]
        pw_[0] -= pw * (beta_shear * (r[0] * (c1 * r[0] + c2 * r[1]) + r[1] * (c2 * r[0] + c1 * r[1]))
                        + beta_ext * c * r[2] * r[2])
        g0 = -(A[0, 0] * s0 + A[1, 0] * s1 + A[2, 0] * s2)
        g1 = -(A[0, 1] * s0 + A[1, 1] * s1 + A[2, 1] * s2)
        g2 = -(A[0, 2] * s0 + A[1, 2] * s1 + A[2, 2] * s2)
        for j in range(20):
            Qf[j] = (J[0, j] * g0 + J[1, j] * g1 + J[2, j] * g2) * pw
        T += tension * pw
        _back(loc, Qf, x, 0, xa, Ha, l)
        _back(loc, Qf, x, 1, xb, Hb, l)
        if want_dv:                                               # -(A J G)^T D (A J G), D of (1.192)-(1.193)
            for i in range(3):
                for j in range(20):
                    row[j] = A[i, 0] * J[0, j] + A[i, 1] * J[1, j] + A[i, 2] * J[2, j]
                AJG[i, :] = 0.0
                _back(AJG[i], row, x, 0, xa, Ha, l)
                _back(AJG[i], row, x, 1, xb, Hb, l)
            for a in range(22):                                   # lower triangle; symmetric
                da0 = pw * beta_shear * (c1 * AJG[0, a] + c2 * AJG[1, a])
                da1 = pw * beta_shear * (c2 * AJG[0, a] + c1 * AJG[1, a])
                da2 = pw * beta_ext * c * AJG[2, a]
                for b in range(a, 22):
                    Dv[b, a] -= AJG[0, b] * da0 + AJG[1, b] * da1 + AJG[2, b] * da2
    if c_twist[e] != 0.0:
        kk = 2.0 / (l * Le)
        d00, d01, d10, d11 = x[10] - x[0], x[11] - x[1], x[12] - x[2], x[13] - x[3]
        phi = kk * (d10 * d01 - d11 * d00)
        Jp[:] = 0.0
        Jp[10], Jp[11], Jp[12], Jp[13] = -kk * d11, kk * d10, kk * d01, -kk * d00
        for j in range(4):
            Jp[j] = -Jp[10 + j]
        phid = 0.0
        for j in range(22):
            phid += Jp[j] * xd[j]
        f = c_twist[e] * (phi + beta_twist * phid)
        pw_[0] -= beta_twist * c_twist[e] * phid * phid
        for j in range(22):
            loc[j] -= f * Jp[j]
        if want_dv:
            for a in range(22):
                for b in range(a, 22):
                    Dv[b, a] -= beta_twist * c_twist[e] * Jp[b] * Jp[a]
    if want_dv:
        for a in range(22):
            for b in range(a + 1, 22):
                Dv[a, b] = Dv[b, a]
    return T


# ---------------------------------------------------------------------------------------------- pins
@njit(cache=True)
def _pin_work():
    """Scratch arrays of :func:`_pin`; the last accumulates the power of its damping and friction forces (W)."""
    return (np.zeros((2, 2)), np.zeros(2), np.zeros(2), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2),
            np.zeros(4), np.zeros(4), np.zeros(4), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2), np.zeros(2),
            np.zeros((2, 2)), np.zeros((2, 4)), np.zeros((2, 3, 9)), np.zeros(1))


@njit(cache=True)
def _pair(loc, Qth, A, B, H, s, v0, v1, kA, kB):
    """Add ``s v . (dU_B - dU_A + kB dth_B - kA dth_A)`` of one station to the pin's local forces and half torques."""
    sv0, sv1 = s * v0, s * v1
    for i in range(4):
        loc[10 * B + 2 * i] += H[i] * sv0
        loc[10 * B + 2 * i + 1] += H[i] * sv1
        loc[10 * A + 2 * i] -= H[i] * sv0
        loc[10 * A + 2 * i + 1] -= H[i] * sv1
    Qth[B] += sv0 * kB[0] + sv1 * kB[1]
    Qth[A] -= sv0 * kA[0] + sv1 * kA[1]


@njit(cache=True)
def _half_bending(x, xd, h, th, nh, thd, par, elastic, loc, Qth, nab):
    """Half bending (1.216) of half ``h`` on axes turning with its link (with ``elastic``), and its co-rotational
    damping (section 5.4); returns the power of the damping forces (W)."""
    l, A_tau, A_n, beta = par[0], par[3], par[4], par[5]
    o = 10 * h + 4                                                # u_2 of the half
    t0, t1, n0, n1 = th[h, 0], th[h, 1], nh[h, 0], nh[h, 1]
    gth = 0.0
    for k in range(2 if elastic else 0):
        a0 = (4 * x[o + 2 * k] + 2 * x[o + 2 - 2 * k]) / l
        a1 = (4 * x[o + 2 * k + 1] + 2 * x[o + 3 - 2 * k]) / l
        at, an = A_tau * (t0 * a0 + t1 * a1), A_n * (n0 * a0 + n1 * a1)
        loc[o + 2 * k] -= at * t0 + an * n0
        loc[o + 2 * k + 1] -= at * t1 + an * n1
        gth += (n0 * x[o + 2 * k] + n1 * x[o + 2 * k + 1]) * (t0 * a0 + t1 * a1)
    Qth[h] -= (A_tau - A_n) * gth
    if beta != 0.0:
        for k in range(2):                                        # nabla = U' - theta' k x U
            nab[k, 0] = xd[o + 2 * k] + thd[h] * x[o + 2 * k + 1]
            nab[k, 1] = xd[o + 2 * k + 1] - thd[h] * x[o + 2 * k]
        dth, power = 0.0, 0.0
        for k in range(2):
            a0 = (4 * nab[k, 0] + 2 * nab[1 - k, 0]) / l
            a1 = (4 * nab[k, 1] + 2 * nab[1 - k, 1]) / l
            at, an = A_tau * (t0 * a0 + t1 * a1), A_n * (n0 * a0 + n1 * a1)
            mb0, mb1 = at * t0 + an * n0, at * t1 + an * n1
            loc[o + 2 * k] -= beta * mb0
            loc[o + 2 * k + 1] -= beta * mb1
            dth += -x[o + 2 * k + 1] * mb0 + x[o + 2 * k] * mb1
            power -= beta * (nab[k, 0] * mb0 + nab[k, 1] * mb1)
        Qth[h] += beta * dth
        return power
    return 0.0


@njit(cache=True)
def _pin_geometry(x, p, cs, arc, idx, sig_, cw, par, tau, rho, th, nh, H, Hp, Hpp, Ux, Hs, CG):
    """Link frames ``tau``, ``rho`` and half axes ``th``, ``nh`` (1.215) of pin ``p``, the station shape values
    ``Hs`` (2, 4) and per station and contact ``CG (2, 3, 9) = (distance, normal (2), gap, normal force, k x r_A,
    k x r_B)`` (arcs at the half axes, penalty ``(l/2) w k [-g]_+``)."""
    l = par[0]
    for j in range(2):
        o = 21 + 4 * j
        x0, x1 = x[o + 2] - x[o], x[o + 3] - x[o + 1]
        rho[j] = np.sqrt(x0 * x0 + x1 * x1)
        tau[j, 0], tau[j, 1] = x0 / rho[j], x1 / rho[j]
        c, s = cs[j, 0], cs[j, 1]
        th[j, 0] = c * tau[j, 0] - s * tau[j, 1]
        th[j, 1] = c * tau[j, 1] + s * tau[j, 0]
        nh[j, 0], nh[j, 1] = -th[j, 1], th[j, 0]
    for s in range(2):
        _shape((2 * s - 1) * _G, l, H, Hp, Hpp)
        Hs[s, :] = H
        for h in range(2):
            for c in range(2):
                a = 0.0
                for i in range(4):
                    a += H[i] * x[10 * h + 2 * i + c]
                Ux[h, c] = a
        for ic in range(3):
            A, B = idx[ic, 0], idx[ic, 1]
            rA0 = arc[ic, 0] * th[A, 0] + arc[ic, 1] * nh[A, 0]
            rA1 = arc[ic, 0] * th[A, 1] + arc[ic, 1] * nh[A, 1]
            rB0 = arc[ic, 3] * th[B, 0] + arc[ic, 4] * nh[B, 0]
            rB1 = arc[ic, 3] * th[B, 1] + arc[ic, 4] * nh[B, 1]
            d0 = Ux[B, 0] + rB0 - Ux[A, 0] - rA0
            d1 = Ux[B, 1] + rB1 - Ux[A, 1] - rA1
            dist = np.sqrt(d0 * d0 + d1 * d1)
            g = sig_[ic] * (dist - arc[ic, 6])
            CG[s, ic, 0], CG[s, ic, 1], CG[s, ic, 2], CG[s, ic, 3] = dist, d0 / dist, d1 / dist, g
            CG[s, ic, 4] = l / 2 * cw[ic, p] * arc[ic, 7] * max(-g, 0.0)
            CG[s, ic, 5], CG[s, ic, 6], CG[s, ic, 7], CG[s, ic, 8] = -rA1, rA0, -rB1, rB0


@njit(cache=True)
def _pin(x, xd, p, T_next, T_prev, b_joint, cs, arc, idx, sig_, cw, par, law, elastic, lateral, cached, loc, wk):
    """Everything of pin ``p`` but its links, on 29 local coordinates ``x`` and velocities ``xd``: half ``-`` (0..9,
    A1 order), half ``+`` (10..19), ``q_p`` (20) and the ends of the links giving the half axes (1.215): start and
    end ``u_0`` of the ``-`` half's link (21..24), of the ``+`` half's link (25..28), copies allowed.  Half axial
    (1.214), half bending (1.216), the three arc contacts at two Gauss stations (penalty, roll damping, tie,
    rolling friction), stoppers, axial friction (1.221) with the link tensions ``T_next`` (link ``(p, p+1)``) and
    ``T_prev`` (``(p-1, p)``) and joint damping (1.80); half torques go to the link ends.  Adds to ``loc`` (29,);
    without ``elastic`` only the velocity-dependent forces (their differences then keep their own round-off),
    without ``lateral`` only the axial terms (half axial, stoppers, axial friction: all that ``w``, ``q_p`` reach);
    with ``cached`` the geometry (frames, stations, contact normals and forces) of the previous call is reused
    (only ``xd`` changed since).
    """
    tau, rho, thd, th, nh, Qth, H, Hp, Hpp, Ux, Vx, kA, kB, nab, Hs, CG, pw = wk
    l, c_half, b_half, b_roll, k_tie = par[0], par[1], par[2], par[9], par[10]
    k_stop, d_stop, f0, v0 = par[11], par[12], par[13], par[14]
    for h in range(2):
        o = 10 * h
        loc[o + 9] -= (2 * c_half * (2 * x[o + 9] - l) if elastic else 0.0) + 4 * b_half * xd[o + 9]
        pw[0] -= 4 * b_half * xd[o + 9] * xd[o + 9]
    for h in range(2 if elastic else 0):                          # stoppers (erratum 13)
        s = x[10 * h + 8] - x[20]
        f = k_stop * max(abs(s) - d_stop, 0.0) * np.sign(s)
        loc[10 * h + 8] -= f
        loc[20] += f
    if f0 != 0.0:                                                 # axial friction (1.221)
        Tn, Tp = max(T_next, 0.0), max(T_prev, 0.0)
        v_hh = xd[18] - xd[8]
        R = -0.5 * (Tn + Tp) * _gain(abs(v_hh), f0, v0, law, SMOOTH_EPS) * v_hh
        loc[18] += R
        loc[8] -= R
        pw[0] += R * v_hh
        for h in range(2):
            v_hp = xd[10 * h + 8] - xd[20]
            R = -(Tn if h == 0 else Tp) * _gain(abs(v_hp), f0, v0, law, SMOOTH_EPS) * v_hp
            loc[10 * h + 8] += R
            loc[20] -= R
            pw[0] += R * v_hp
    if not lateral:
        return
    if not cached:
        _pin_geometry(x, p, cs, arc, idx, sig_, cw, par, tau, rho, th, nh, H, Hp, Hpp, Ux, Hs, CG)
    for j in range(2):                                            # spin rates of the links
        o = 21 + 4 * j
        thd[j] = (-tau[j, 1] * (xd[o + 2] - xd[o]) + tau[j, 0] * (xd[o + 3] - xd[o + 1])) / rho[j]
        Qth[j] = 0.0
    for h in range(2):
        pw[0] += _half_bending(x, xd, h, th, nh, thd, par, elastic, loc, Qth, nab)
    for s in range(2):
        Hst = Hs[s]
        for h in range(2):
            for c in range(2):
                b = 0.0
                for i in range(4):
                    b += Hst[i] * xd[10 * h + 2 * i + c]
                Vx[h, c] = b
        for ic in range(3):
            A, B, sig = idx[ic, 0], idx[ic, 1], sig_[ic]
            RA, RB = arc[ic, 2], arc[ic, 5]
            wgt = l / 2 * cw[ic, p]
            dist, n0, n1, g, N = CG[s, ic, 0], CG[s, ic, 1], CG[s, ic, 2], CG[s, ic, 3], CG[s, ic, 4]
            kA[0], kA[1], kB[0], kB[1] = CG[s, ic, 5], CG[s, ic, 6], CG[s, ic, 7], CG[s, ic, 8]
            t0, t1 = -n1, n0
            if N != 0.0 and elastic:
                _pair(loc, Qth, A, B, Hst, N * sig, n0, n1, kA, kB)
            vr0, vr1 = Vx[B, 0] - Vx[A, 0], Vx[B, 1] - Vx[A, 1]
            if b_roll != 0.0 and ic == 0 and g < 0:
                gdot = sig * (n0 * vr0 + n1 * vr1 + (n0 * kB[0] + n1 * kB[1]) * thd[B]
                              - (n0 * kA[0] + n1 * kA[1]) * thd[A])
                _pair(loc, Qth, A, B, Hst, -wgt * b_roll * gdot * sig, n0, n1, kA, kB)
                pw[0] -= wgt * b_roll * gdot * gdot
            if k_tie != 0.0 and ic == 0 and elastic:              # g_t = R_A ang(n, tau_A) + R_B ang(n, tau_B)
                gt = (RA * np.arctan2(n0 * tau[A, 1] - n1 * tau[A, 0], n0 * tau[A, 0] + n1 * tau[A, 1])
                      + RB * np.arctan2(n0 * tau[B, 1] - n1 * tau[B, 0], n0 * tau[B, 0] + n1 * tau[B, 1]))
                st = wgt * k_tie * gt
                _pair(loc, Qth, A, B, Hst, (RA + RB) / dist * st, t0, t1, kA, kB)
                Qth[A] -= st * RA
                Qth[B] -= st * RB
            if f0 != 0.0 and N != 0.0:
                vs = (t0 * vr0 + t1 * vr1 + (t0 * kB[0] + t1 * kB[1] - sig * RB) * thd[B]
                      - (t0 * kA[0] + t1 * kA[1] + RA) * thd[A])
                Ft = -N * _gain(abs(vs), f0, v0, law, SMOOTH_EPS) * vs
                _pair(loc, Qth, A, B, Hst, Ft, t0, t1, kA, kB)
                Qth[B] -= Ft * sig * RB
                Qth[A] -= Ft * RA
                pw[0] += Ft * vs
    if b_joint[p] != 0.0:                                         # joint damping (1.80)
        tq = b_joint[p] * (thd[0] - thd[1])
        pw[0] -= tq * (thd[0] - thd[1])
        Qth[0] -= tq
        Qth[1] += tq
    for j in range(2):                                            # half torques to the link ends
        o = 21 + 4 * j
        a = Qth[j] / rho[j]
        g0, g1 = -a * tau[j, 1], a * tau[j, 0]
        loc[o + 2] += g0
        loc[o + 3] += g1
        loc[o] -= g0
        loc[o + 1] -= g1


@njit(cache=True)
def _axial_friction_slopes(xd, p, T_next, T_prev, f0, v0, law, out):
    """``d Q / d T`` of pin ``p``'s axial friction (rows ``w_0-``, ``w_0+``, ``q_p``) for ``T_next`` (``out[0]``)
    and ``T_prev`` (``out[1]``); zero where a tension is not positive."""
    v_hh = xd[18] - xd[8]
    r_hh = -0.5 * _gain(abs(v_hh), f0, v0, law, SMOOTH_EPS) * v_hh
    for j in range(2):
        Tj = T_next if j == 0 else T_prev
        v_hp = xd[10 * j + 8] - xd[20]
        r_hp = -_gain(abs(v_hp), f0, v0, law, SMOOTH_EPS) * v_hp if Tj > 0 else 0.0
        rh = r_hh if Tj > 0 else 0.0
        out[j, 0] = -rh + (r_hp if j == 0 else 0.0)
        out[j, 1] = rh + (r_hp if j == 1 else 0.0)
        out[j, 2] = -r_hp


# ---------------------------------------------------------------------------------------------- passes
@njit(cache=True)
def forces(q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc, idx, sig,
           cw, par, ints):
    """Generalized forces ``Q (21 n,)`` of the A5 chain: elastic, dissipative and friction (``ChainA5.forces``)."""
    return forces_power(q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc,
                        idx, sig, cw, par, ints)[0]


@njit(cache=True)
def forces_power(q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc, idx,
                 sig, cw, par, ints):
    """``(Q, D)``: the forces of :func:`forces` and the power dissipated by their damping and friction parts,
    ``D = -(Q_d + Q_fr) . v = 2 Phi - P_fr`` (W, >= 0), summed element by element."""
    n = L.shape[0]
    law, kmodel = ints[0], ints[1]
    Q = np.zeros(q.shape[0])
    T = np.zeros(n)
    x, xd, loc, Dv = np.zeros(22), np.zeros(22), np.zeros(22), np.zeros((1, 1))
    wk = _link_work()
    for e in range(n):
        for j in range(22):
            x[j], xd[j], loc[j] = q[gl[e, j]], v[gl[e, j]], 0.0
        T[e] = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, loc, Dv,
                     False, wk)
        for j in range(22):
            Q[gl[e, j]] += loc[j]
    y, yd, lp = np.zeros(29), np.zeros(29), np.zeros(29)
    pk = _pin_work()
    for p in range(n):
        for j in range(29):
            y[j], yd[j], lp[j] = q[gp[p, j]], v[gp[p, j]], 0.0
        _pin(y, yd, p, T[p], T[(p - 1) % n], b_joint, cs, arc, idx, sig, cw, par, law, True, True, False, lp, pk)
        for j in range(29):
            Q[gp[p, j]] += lp[j]
    return Q, -(wk[-1][0] + pk[-1][0])


@njit(cache=True)
def _step(x, rel, floor):
    """A difference step ``rel max(|x|, floor)`` rounded so that ``x + h`` is exact."""
    h = rel * max(abs(x), floor)
    return (x + h) - x


@njit(cache=True)
def jacobian(q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc, idx, sig,
             cw, par, ints, pos_l, pos_p, pos_t, first, steps, central_link, Jq, Jv, dDq, dDv):
    """``dQ/dq``, ``dQ/dv`` of :func:`forces` added into the CSR data ``Jq``, ``Jv`` (positions ``pos_l (n, 22, 22)``
    of the link blocks, ``pos_p (n, 29, 29)`` of the pin blocks, ``pos_t (n, 2, 3, 22)`` of the axial friction
    rows against the tensions' link coordinates; ``first`` of :func:`positions`).

    Element by element: a link's velocity block is exact (its forces are linear in the velocities), its
    coordinate block forward (``central_link`` false) or central differences of the link alone; a pin's blocks
    central differences of the pin alone (a coordinate and its copies at once); the axial friction's
    dependence on the link tensions by the chain rule with the tensions' differences.  ``steps = (link, pin
    coordinate, pin velocity)`` relative steps, applied to ``max(|x|, l)`` (smaller steps drown in the round-off
    of the contact forces) and to ``v_0`` (the friction laws bend on that scale of the slip, whatever the speed:
    a step relative to ``|v|`` spans the law's knee at chain speed).

    The gradient of the dissipated power ``D`` of :func:`forces_power` over ``q`` and ``v`` is added into ``dDq``,
    ``dDv`` (21 n,) from the same element passes: the elements' power differences (a link's ``dD/dv`` exact,
    ``-2 Q_d``: its damping forces are linear in the velocities) and the axial friction's tension dependence.
    """
    n = L.shape[0]
    l, f0, v0 = par[0], par[13], par[14]
    law, kmodel = ints[0], ints[1]
    floor = l
    rel_link = steps[0]
    T, dT = np.zeros(n), np.zeros((n, 22))
    x, xd, f_0, f_p, f_m = np.zeros(22), np.zeros(22), np.zeros(22), np.zeros(22), np.zeros(22)
    Dv, Dx = np.zeros((22, 22)), np.zeros((1, 1))
    wk = _link_work()
    pw = wk[-1]
    for e in range(n):
        for j in range(22):
            x[j], xd[j], f_0[j] = q[gl[e, j]], v[gl[e, j]], 0.0
        Dv[:, :] = 0.0
        pw[0] = 0.0                                               # each pass's power alone (no round-off of a sum)
        T[e] = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, f_0, Dv,
                     True, wk)
        P0 = pw[0]
        for j in range(22):
            x0 = x[j]
            h = _step(x0, rel_link, floor)
            x[j] = x0 + h
            f_p[:] = 0.0
            pw[0] = 0.0
            Tp = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, f_p, Dx,
                       False, wk)
            Pp = pw[0]
            if central_link:
                x[j] = x0 - h
                f_m[:] = 0.0
                pw[0] = 0.0
                Tm = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, f_m,
                           Dx, False, wk)
                Pm = pw[0]
                h2 = 2 * h
            else:
                f_m[:] = f_0
                Tm, Pm, h2 = T[e], P0, h
            x[j] = x0
            dT[e, j] = (Tp - Tm) / h2
            dDq[gl[e, j]] -= (Pp - Pm) / h2
            for r in range(22):
                Jq[pos_l[e, r, j]] += (f_p[r] - f_m[r]) / h2
                Jv[pos_l[e, r, j]] += Dv[r, j]
                dDv[gl[e, r]] -= 2 * Dv[r, j] * xd[j]
    y, yd, g_p, g_m = np.zeros(29), np.zeros(29), np.zeros(29), np.zeros(29)
    pk = _pin_work()
    ppw = pk[-1]
    slopes = np.zeros((2, 3))
    for p in range(n):
        pv = (p - 1) % n
        for j in range(29):
            y[j], yd[j] = q[gp[p, j]], v[gp[p, j]]
        for j in range(58):                                       # 29 coordinates, then 29 velocities
            z = y if j < 29 else yd
            jj = j % 29
            if first[p, jj] != jj:                                # a copy: moved with its first
                continue
            if j == 29:                                           # geometry at the unperturbed coordinates
                _pin(y, yd, p, T[p], T[pv], b_joint, cs, arc, idx, sig, cw, par, law, False, True, False, g_p, pk)
            lateral = jj < 8 or 9 < jj < 18 or jj > 20                # w, q_p reach the axial terms only
            z0 = z[jj]
            h = _step(z0, steps[1], floor) if j < 29 else (z0 + steps[2] * v0) - z0
            dP = 0.0
            for sgn in range(2):
                for k in range(jj, 29):
                    if first[p, k] == jj:
                        z[k] = z0 + h if sgn == 0 else z0 - h
                g = g_p if sgn == 0 else g_m
                g[:] = 0.0
                ppw[0] = 0.0
                _pin(y, yd, p, T[p], T[pv], b_joint, cs, arc, idx, sig, cw, par, law, j < 29, lateral, j >= 29, g,
                     pk)
                dP += ppw[0] if sgn == 0 else -ppw[0]
            for k in range(jj, 29):
                if first[p, k] == jj:
                    z[k] = z0
            Jx = Jq if j < 29 else Jv
            (dDq if j < 29 else dDv)[gp[p, jj]] -= dP / (2 * h)
            for r in range(29):
                Jx[pos_p[p, r, jj]] += (g_p[r] - g_m[r]) / (2 * h)
        if f0 != 0.0:
            _axial_friction_slopes(yd, p, T[p], T[pv], f0, v0, law, slopes)
            for j in range(2):
                e = p if j == 0 else pv
                dP_dT = slopes[j, 0] * yd[8] + slopes[j, 1] * yd[18] + slopes[j, 2] * yd[20]
                for c in range(22):
                    dDq[gl[e, c]] -= dP_dT * dT[e, c]
                for r in range(3):
                    for c in range(22):
                        Jq[pos_t[p, j, r, c]] += slopes[j, r] * dT[e, c]


__all__ = ["HAVE_NUMBA", "SMOOTH_EPS", "forces", "forces_power", "jacobian", "pack", "positions"]
