"""Compiled force pass (numba) of the A5 chain with independent pin halves: one loop over links, one over pins.

The numpy methods of :class:`~cvtfem.elements.chain.halves.ChainA5` are the reference twin:
:func:`forces` computes ``Q = -dPi/dq - dPhi/dv + Q_friction`` with the same formulas (half axial and
bending (1.214), (1.216); plates at the variable stations (1.211)-(1.212) through the virtual-pin map and
the per-plate law of :mod:`plates_kernel`; twist (1.146), (1.217); the three arc contacts with damping, tie
and rolling friction; stoppers; axial friction (1.221); joint damping (1.80)), without numpy's per-call
overhead on 84-pin arrays (``tests/elements/chain/test_halves_kernel.py`` checks the two against each other).

Arguments: state ``q`` and velocity ``v`` (21 n, layout of ``ChainA5``) and the constant tuple of
:func:`pack`.  Without numba (``HAVE_NUMBA`` false) the family uses its numpy twin.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.plates_kernel import _plate_law, _strain_rates, _strains
from cvtfem.elements.contact.kernels import LAW_CODES, _gain
from cvtfem.elements.jit import HAVE_NUMBA, njit

#: ``friction_gain``'s default blend width of the ``smooth`` law, as the numpy twin calls it.
SMOOTH_EPS = 0.1
_G = 1.0 / np.sqrt(3.0)


def pack(ch, contacts) -> tuple:
    """Kernel constants of a :class:`ChainA5` with its ``contacts`` table (built once per family).

    Per contact one row ``arc = (offset of A's centre along tau, n; R_A; offset of B's; R_B; rho_0; k)``.
    """
    arcs = [ch._arcs[c[0]] for c in contacts]
    arc = np.array([[a[0][0], a[0][1], a[1], a[2][0], a[2][1], a[3], a[4], a[5]] for a in arcs])
    idx = np.array([[c[1], c[2]] for c in contacts], np.int64)
    sig = np.array([c[3] for c in contacts])
    cw = np.stack([ch._contact_w[c[0]] for c in contacts])
    par = np.array([ch.l, ch.c_half, ch.b_half, ch.A_tau, ch.A_n, ch.beta_bend, ch.beta_ext, ch.beta_shear,
                    ch.beta_twist, ch.b_roll, ch.k_tie, ch.k_stop, ch.d_stop, ch.f0, ch.v0, ch.plate_h])
    ints = np.array([LAW_CODES[ch.law], ch._kmodel], np.int64)
    return (np.ascontiguousarray(ch.axis_link), np.ascontiguousarray(ch._cs), ch.L, ch.c_twist, ch.b_joint,
            np.ascontiguousarray(ch.plate_w), np.ascontiguousarray(ch.plate_d), np.ascontiguousarray(ch.plate_c),
            np.ascontiguousarray(ch.plate_c1), np.ascontiguousarray(ch.plate_c2), arc, idx, sig,
            np.ascontiguousarray(cw), par, ints)


@njit(cache=True)
def _unpack(x, n, u, w, qp):
    """State vector -> ``u (2, 4, n, 2)``, ``w (2, 2, n)``, ``qp (n,)`` (layout of ``ChainA5.split``)."""
    for h in range(2):
        o = 10 * n * h
        for i in range(4):
            for p in range(n):
                for c in range(2):
                    u[h, i, p, c] = x[o + 2 * n * i + 2 * p + c]
        for j in range(2):
            for p in range(n):
                w[h, j, p] = x[o + 8 * n + n * j + p]
    for p in range(n):
        qp[p] = x[20 * n + p]


@njit(cache=True)
def _pack_out(n, Qu, Qw, Qq, Q):
    """Inverse of :func:`_unpack`."""
    for h in range(2):
        o = 10 * n * h
        for i in range(4):
            for p in range(n):
                for c in range(2):
                    Q[o + 2 * n * i + 2 * p + c] = Qu[h, i, p, c]
        for j in range(2):
            for p in range(n):
                Q[o + 8 * n + n * j + p] = Qw[h, j, p]
    for p in range(n):
        Q[20 * n + p] = Qq[p]


@njit(cache=True)
def _shape(xi, l, H, Hp, Hpp):
    """``h_i``, ``h_i'``, ``h_i''`` of (1.132) at ``xi`` into ``H``, ``Hp``, ``Hpp`` (4,)."""
    l8 = l / 8.0
    H[0], H[1], H[2], H[3] = 1.0, xi, l8 * (1 - xi) ** 2 * (1 + xi), l8 * (xi - 1) * (1 + xi) ** 2
    Hp[0], Hp[1], Hp[2], Hp[3] = 0.0, 1.0, l8 * (-1 - 2 * xi + 3 * xi * xi), l8 * (-1 + 2 * xi + 3 * xi * xi)
    Hpp[0], Hpp[1], Hpp[2], Hpp[3] = 0.0, 0.0, l8 * (6 * xi - 2), l8 * (6 * xi + 2)


@njit(cache=True)
def _half_bending(u, vu, th, nh, thd_h, par, Qu, Qth):
    """Half bending (1.216) on axes turning with the links and its co-rotational damping (section 5.4)."""
    n = u.shape[2]
    l, A_tau, A_n, beta = par[0], par[3], par[4], par[5]
    m = np.zeros((2, 2))
    nab = np.zeros((2, 2))
    for h in range(2):
        for p in range(n):
            t0, t1, n0, n1 = th[h, p, 0], th[h, p, 1], nh[h, p, 0], nh[h, p, 1]
            for c in range(2):
                m[0, c] = (4 * u[h, 2, p, c] + 2 * u[h, 3, p, c]) / l
                m[1, c] = (2 * u[h, 2, p, c] + 4 * u[h, 3, p, c]) / l
            gth = 0.0
            for k in range(2):
                at = A_tau * (t0 * m[k, 0] + t1 * m[k, 1])
                an = A_n * (n0 * m[k, 0] + n1 * m[k, 1])
                Qu[h, 2 + k, p, 0] -= at * t0 + an * n0
                Qu[h, 2 + k, p, 1] -= at * t1 + an * n1
                gth += (n0 * u[h, 2 + k, p, 0] + n1 * u[h, 2 + k, p, 1]) * (t0 * m[k, 0] + t1 * m[k, 1])
            Qth[h, p] -= (A_tau - A_n) * gth
            if beta != 0.0:
                for k in range(2):                               # nabla = U' - theta' k x U
                    nab[k, 0] = vu[h, 2 + k, p, 0] + thd_h[h, p] * u[h, 2 + k, p, 1]
                    nab[k, 1] = vu[h, 2 + k, p, 1] - thd_h[h, p] * u[h, 2 + k, p, 0]
                dth = 0.0
                for k in range(2):
                    a0 = (4 * nab[k, 0] + 2 * nab[1 - k, 0]) / l
                    a1 = (4 * nab[k, 1] + 2 * nab[1 - k, 1]) / l
                    at, an = A_tau * (t0 * a0 + t1 * a1), A_n * (n0 * a0 + n1 * a1)
                    mb0, mb1 = at * t0 + an * n0, at * t1 + an * n1
                    Qu[h, 2 + k, p, 0] -= beta * mb0
                    Qu[h, 2 + k, p, 1] -= beta * mb1
                    dth += -u[h, 2 + k, p, 1] * mb0 + u[h, 2 + k, p, 0] * mb1
                Qth[h, p] += beta * dth


@njit(cache=True)
def _virtual_pin(u, w, ud, wd, qa, qad, d, l, o, qv, qvd, mp):
    """End ``o`` (0 or 10) of one plate as a virtual whole pin at ``xi = 0`` (docstring of
    ``ChainA5``); ``mp`` (3, 4) keeps ``H, H', H''`` for the back map.  Returns ``xi``."""
    xi = 2.0 / l * (qa - w[0] + d)
    xid = 2.0 / l * (qad - wd[0])
    _shape(xi, l, mp[0], mp[1], mp[2])
    for c in range(2):
        U, u1, du1, Ud, u1d = 0.0, 0.0, 0.0, 0.0, 0.0
        for i in range(4):
            U += mp[0, i] * u[i, c]
            u1 += mp[1, i] * u[i, c]
            du1 += mp[2, i] * u[i, c]
            Ud += mp[0, i] * ud[i, c]
            u1d += mp[1, i] * ud[i, c]
        qv[o + c], qv[o + 2 + c], qv[o + 4 + c], qv[o + 6 + c] = U, u1, 0.0, 0.0
        qvd[o + c], qvd[o + 2 + c], qvd[o + 4 + c], qvd[o + 6 + c] = Ud + u1 * xid, u1d + du1 * xid, 0.0, 0.0
    qv[o + 8], qv[o + 9] = w[0] + w[1] * xi, w[1]
    qvd[o + 8], qvd[o + 9] = wd[0] + wd[1] * xi + w[1] * xid, wd[1]
    return xi


@njit(cache=True)
def _links(u, w, qp, vu, vw, vq, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel,
           Qu, Qw, Qq, T_link):
    """Plates (virtual-pin map and per-plate law, elastic plus damping) and twist of every link."""
    n, K = u.shape[2], plate_w.shape[1]
    l, beta_ext, beta_shear, beta_twist, h_pl = par[0], par[6], par[7], par[8], par[15]
    ua, ub, uad, ubd = np.zeros((4, 2)), np.zeros((4, 2)), np.zeros((4, 2)), np.zeros((4, 2))
    wa, wb, wad, wbd = np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2)
    qv, qvd, Qf = np.zeros(20), np.zeros(20), np.zeros(20)
    mpa, mpb = np.zeros((3, 4)), np.zeros((3, 4))
    J, A = np.zeros((3, 20)), np.zeros((3, 3))
    H, Hp, V, t, e = np.zeros(4), np.zeros(4), np.zeros(3), np.zeros((2, 3)), np.zeros((2, 3))
    ed, r, m = np.zeros(3), np.zeros(3), np.zeros(10)
    loc = np.zeros(22)
    Jp = np.zeros(22)
    for e_ in range(n):
        nx = (e_ + 1) % n
        for i in range(4):
            for c in range(2):
                ua[i, c], ub[i, c] = u[0, i, e_, c], u[1, i, nx, c]
                uad[i, c], ubd[i, c] = vu[0, i, e_, c], vu[1, i, nx, c]
        for j in range(2):
            wa[j], wb[j], wad[j], wbd[j] = w[0, j, e_], w[1, j, nx], vw[0, j, e_], vw[1, j, nx]
        loc[:] = 0.0
        Le = L[e_]
        for k in range(K):
            pw = plate_w[e_, k]
            if pw == 0.0:
                continue
            xa = _virtual_pin(ua, wa, uad, wad, qp[e_], vq[e_], plate_d[e_, k], l, 0, qv, qvd, mpa)
            xb = _virtual_pin(ub, wb, ubd, wbd, qp[nx], vq[nx], plate_d[e_, k], l, 10, qv, qvd, mpb)
            c, c1, c2 = plate_c[e_, k], plate_c1[e_, k], plate_c2[e_, k]
            psi1, psi2, Delta = _strains(qv, 0.0, l, Le, J, H, Hp, V, t, e)
            st, d1, d2, tension = _plate_law(kmodel, psi1, psi2, Delta, c, c1, c2, h_pl, A, m)
            z1, z2 = psi1 - d1, psi2 - d2
            _strain_rates(J, qvd, A, ed, r)
            s0 = c1 * z1 + c2 * z2 + beta_shear * (c1 * r[0] + c2 * r[1])
            s1 = c2 * z1 + c1 * z2 + beta_shear * (c2 * r[0] + c1 * r[1])
            s2 = tension + beta_ext * c * r[2]
            g0 = -(A[0, 0] * s0 + A[1, 0] * s1 + A[2, 0] * s2)
            g1 = -(A[0, 1] * s0 + A[1, 1] * s1 + A[2, 1] * s2)
            g2 = -(A[0, 2] * s0 + A[1, 2] * s1 + A[2, 2] * s2)
            for j in range(20):
                Qf[j] = (J[0, j] * g0 + J[1, j] * g1 + J[2, j] * g2) * pw
            T_link[e_] += tension * pw
            for b in range(2):                                    # back through the virtual-pin map
                o = 10 * b
                mp = mpa if b == 0 else mpb
                uu = ua if b == 0 else ub
                ww = wa if b == 0 else wb
                xi = xa if b == 0 else xb
                S = Qf[o + 8] * ww[1]
                for c_ in range(2):
                    u1, du1 = 0.0, 0.0
                    for i in range(4):
                        loc[o + 2 * i + c_] += mp[0, i] * Qf[o + c_] + mp[1, i] * Qf[o + 2 + c_]
                        u1 += mp[1, i] * uu[i, c_]
                        du1 += mp[2, i] * uu[i, c_]
                    S += Qf[o + c_] * u1 + Qf[o + 2 + c_] * du1
                loc[o + 8] += Qf[o + 8] - 2.0 / l * S
                loc[o + 9] += Qf[o + 8] * xi + Qf[o + 9]
                loc[20 + b] += 2.0 / l * S
        if c_twist[e_] != 0.0:                                    # (1.146) with (1.217)
            kk = 2.0 / (l * Le)
            d00, d01 = ub[0, 0] - ua[0, 0], ub[0, 1] - ua[0, 1]
            d10, d11 = ub[1, 0] - ua[1, 0], ub[1, 1] - ua[1, 1]
            phi = kk * (d10 * d01 - d11 * d00)
            Jp[:] = 0.0
            Jp[10], Jp[11] = -kk * d11, kk * d10
            Jp[12], Jp[13] = kk * d01, -kk * d00
            for j in range(4):
                Jp[j] = -Jp[10 + j]
            phid = 0.0
            for j in range(4):
                phid += Jp[j] * uad[j // 2, j % 2] + Jp[10 + j] * ubd[j // 2, j % 2]
            f = c_twist[e_] * (phi + beta_twist * phid)
            for j in range(22):
                loc[j] -= f * Jp[j]
        for i in range(4):
            for c in range(2):
                Qu[0, i, e_, c] += loc[2 * i + c]
                Qu[1, i, nx, c] += loc[10 + 2 * i + c]
        for j in range(2):
            Qw[0, j, e_] += loc[8 + j]
            Qw[1, j, nx] += loc[18 + j]
        Qq[e_] += loc[20]
        Qq[nx] += loc[21]


@njit(cache=True)
def _pair(Qu, Qth, p, A, B, H, s, v0, v1, kA, kB):
    """Add ``s v . (dU_B - dU_A + kB dth_B - kA dth_A)`` at one station (generalized-force sign applied by caller)."""
    sv0, sv1 = s * v0, s * v1
    for i in range(4):
        Qu[B, i, p, 0] += H[i] * sv0
        Qu[B, i, p, 1] += H[i] * sv1
        Qu[A, i, p, 0] -= H[i] * sv0
        Qu[A, i, p, 1] -= H[i] * sv1
    Qth[B, p] += sv0 * kB[0] + sv1 * kB[1]
    Qth[A, p] -= sv0 * kA[0] + sv1 * kA[1]


@njit(cache=True)
def _contacts(u, vu, tau, th, nh, thd_h, axis_link, arc, idx, sig_, cw, par, law, Qu, Qth):
    """The three arc contacts of every pin at two Gauss stations: penalty, roll damping, tie, rolling friction."""
    n = u.shape[2]
    l, b_roll, k_tie, f0, v0 = par[0], par[9], par[10], par[13], par[14]
    H, Hp, Hpp = np.zeros(4), np.zeros(4), np.zeros(4)
    Ux, Vx = np.zeros((2, 2)), np.zeros((2, 2))
    kA, kB = np.zeros(2), np.zeros(2)
    for s in range(2):
        _shape((2 * s - 1) * _G, l, H, Hp, Hpp)
        for p in range(n):
            for h in range(2):
                for c in range(2):
                    a, b = 0.0, 0.0
                    for i in range(4):
                        a += H[i] * u[h, i, p, c]
                        b += H[i] * vu[h, i, p, c]
                    Ux[h, c], Vx[h, c] = a, b
            for ic in range(3):
                A, B, sig = idx[ic, 0], idx[ic, 1], sig_[ic]
                RA, RB, rho0, k = arc[ic, 2], arc[ic, 5], arc[ic, 6], arc[ic, 7]
                wgt = l / 2 * cw[ic, p]
                rA0 = arc[ic, 0] * th[A, p, 0] + arc[ic, 1] * nh[A, p, 0]
                rA1 = arc[ic, 0] * th[A, p, 1] + arc[ic, 1] * nh[A, p, 1]
                rB0 = arc[ic, 3] * th[B, p, 0] + arc[ic, 4] * nh[B, p, 0]
                rB1 = arc[ic, 3] * th[B, p, 1] + arc[ic, 4] * nh[B, p, 1]
                d0 = Ux[B, 0] + rB0 - Ux[A, 0] - rA0
                d1 = Ux[B, 1] + rB1 - Ux[A, 1] - rA1
                rho = np.sqrt(d0 * d0 + d1 * d1)
                n0, n1 = d0 / rho, d1 / rho
                t0, t1 = -n1, n0
                g = sig * (rho - rho0)
                pen = max(-g, 0.0)
                N = wgt * k * pen
                kA[0], kA[1], kB[0], kB[1] = -rA1, rA0, -rB1, rB0
                if N != 0.0:
                    _pair(Qu, Qth, p, A, B, H, N * sig, n0, n1, kA, kB)
                vr0, vr1 = Vx[B, 0] - Vx[A, 0], Vx[B, 1] - Vx[A, 1]
                if b_roll != 0.0 and ic == 0 and g < 0:
                    gdot = sig * (n0 * vr0 + n1 * vr1 + (n0 * kB[0] + n1 * kB[1]) * thd_h[B, p]
                                  - (n0 * kA[0] + n1 * kA[1]) * thd_h[A, p])
                    _pair(Qu, Qth, p, A, B, H, -wgt * b_roll * gdot * sig, n0, n1, kA, kB)
                if k_tie != 0.0 and ic == 0:
                    ta, tb = axis_link[A, p], axis_link[B, p]
                    gt = (RA * np.arctan2(n0 * tau[ta, 1] - n1 * tau[ta, 0], n0 * tau[ta, 0] + n1 * tau[ta, 1])
                          + RB * np.arctan2(n0 * tau[tb, 1] - n1 * tau[tb, 0], n0 * tau[tb, 0] + n1 * tau[tb, 1]))
                    st = wgt * k_tie * gt
                    _pair(Qu, Qth, p, A, B, H, (RA + RB) / rho * st, t0, t1, kA, kB)
                    Qth[A, p] -= st * RA
                    Qth[B, p] -= st * RB
                if f0 != 0.0 and N != 0.0:
                    vs = (t0 * vr0 + t1 * vr1 + (t0 * kB[0] + t1 * kB[1] - sig * RB) * thd_h[B, p]
                          - (t0 * kA[0] + t1 * kA[1] + RA) * thd_h[A, p])
                    Ft = -N * _gain(abs(vs), f0, v0, law, SMOOTH_EPS) * vs
                    _pair(Qu, Qth, p, A, B, H, Ft, t0, t1, kA, kB)
                    Qth[B, p] -= Ft * sig * RB
                    Qth[A, p] -= Ft * RA


@njit(cache=True)
def forces(q, v, axis_link, cs, L, c_twist, b_joint, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc, idx, sig,
           cw, par, ints):
    """Generalized forces ``Q (21 n,)`` of the A5 chain: elastic, dissipative and friction (``ChainA5.forces``)."""
    n = L.shape[0]
    l, c_half, b_half, k_stop, d_stop, f0, v0 = par[0], par[1], par[2], par[11], par[12], par[13], par[14]
    law, kmodel = ints[0], ints[1]
    u, w, qp = np.zeros((2, 4, n, 2)), np.zeros((2, 2, n)), np.zeros(n)
    vu, vw, vq = np.zeros((2, 4, n, 2)), np.zeros((2, 2, n)), np.zeros(n)
    _unpack(q, n, u, w, qp)
    _unpack(v, n, vu, vw, vq)
    Qu, Qw, Qq = np.zeros((2, 4, n, 2)), np.zeros((2, 2, n)), np.zeros(n)
    Qth = np.zeros((2, n))                                        # generalized forces on the half angles
    # ---- link frames and spin rates, half axes (1.215)
    rho, tau, thd = np.zeros(n), np.zeros((n, 2)), np.zeros(n)
    for e in range(n):
        nx = (e + 1) % n
        x0, x1 = u[1, 0, nx, 0] - u[0, 0, e, 0], u[1, 0, nx, 1] - u[0, 0, e, 1]
        rho[e] = np.sqrt(x0 * x0 + x1 * x1)
        tau[e, 0], tau[e, 1] = x0 / rho[e], x1 / rho[e]
        thd[e] = (-tau[e, 1] * (vu[1, 0, nx, 0] - vu[0, 0, e, 0])
                  + tau[e, 0] * (vu[1, 0, nx, 1] - vu[0, 0, e, 1])) / rho[e]
    th, nh, thd_h = np.zeros((2, n, 2)), np.zeros((2, n, 2)), np.zeros((2, n))
    for h in range(2):
        c, s = cs[h, 0], cs[h, 1]
        for p in range(n):
            e = axis_link[h, p]
            th[h, p, 0] = c * tau[e, 0] - s * tau[e, 1]
            th[h, p, 1] = c * tau[e, 1] + s * tau[e, 0]
            nh[h, p, 0], nh[h, p, 1] = -th[h, p, 1], th[h, p, 0]
            thd_h[h, p] = thd[e]
    # ---- half axial (1.214)
    for h in range(2):
        for p in range(n):
            Qw[h, 1, p] -= 2 * c_half * (2 * w[h, 1, p] - l) + 4 * b_half * vw[h, 1, p]
    _half_bending(u, vu, th, nh, thd_h, par, Qu, Qth)
    T_link = np.zeros(n)
    _links(u, w, qp, vu, vw, vq, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel,
           Qu, Qw, Qq, T_link)
    _contacts(u, vu, tau, th, nh, thd_h, axis_link, arc, idx, sig, cw, par, law, Qu, Qth)
    # ---- stoppers (erratum 13), axial friction (1.221), joint damping (1.80)
    for p in range(n):
        pv = (p - 1) % n
        for h in range(2):
            s = w[h, 0, p] - qp[p]
            g = max(abs(s) - d_stop, 0.0)
            f = k_stop * g * np.sign(s)
            Qw[h, 0, p] -= f
            Qq[p] += f
        if f0 != 0.0:
            Tm, Tp = max(T_link[p], 0.0), max(T_link[pv], 0.0)
            v_hh = vw[1, 0, p] - vw[0, 0, p]
            R = -0.5 * (Tm + Tp) * _gain(abs(v_hh), f0, v0, law, SMOOTH_EPS) * v_hh
            Qw[1, 0, p] += R
            Qw[0, 0, p] -= R
            for h in range(2):
                v_hp = vw[h, 0, p] - vq[p]
                R = -(Tm if h == 0 else Tp) * _gain(abs(v_hp), f0, v0, law, SMOOTH_EPS) * v_hp
                Qw[h, 0, p] += R
                Qq[p] -= R
        if b_joint[p] != 0.0:
            tq = b_joint[p] * (thd[axis_link[0, p]] - thd[axis_link[1, p]])
            Qth[0, p] -= tq
            Qth[1, p] += tq
    # ---- half angles -> link angles -> u_0 (d theta_e = n_e . dx_e / rho_e)
    Qang = np.zeros(n)
    for h in range(2):
        for p in range(n):
            Qang[axis_link[h, p]] += Qth[h, p]
    for e in range(n):
        nx = (e + 1) % n
        a = Qang[e] / rho[e]
        g0, g1 = -a * tau[e, 1], a * tau[e, 0]
        Qu[1, 0, nx, 0] += g0
        Qu[1, 0, nx, 1] += g1
        Qu[0, 0, e, 0] -= g0
        Qu[0, 0, e, 1] -= g1
    Q = np.zeros(21 * n)
    _pack_out(n, Qu, Qw, Qq, Q)
    return Q


__all__ = ["HAVE_NUMBA", "SMOOTH_EPS", "forces", "pack"]
