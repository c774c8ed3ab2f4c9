"""Compiled right-hand side of the 6+2n / 6+2n+8 band models (numba), with a finite-difference Jacobian.

The numpy methods of :class:`~cvtfem.elements.band.compressible.CompressibleBand` are the reference
twin: ``accel_kernel`` computes the same accelerations, normal forces and powers statement by
statement (same complex-step derivatives in phi, same quadrature), only without numpy's per-call
overhead on 16-node arrays (``tests/band/test_compressible_kernel.py`` checks them against each other).
Without numba (``HAVE_NUMBA`` false) the model uses its numpy methods.

Parameters are packed by :func:`pack`: ``s`` (scalars, index constants ``S_*``), ``sh`` (2, 5) sheave
faces ``[profile (0 conical, 1 toroidal), gamma, R, y, w]``, ``sf`` (2, 5) shafts
``[J, m_sheave, Theta, c_U, c_psi]``, ``xidx`` (2, nx) elastic-coordinate indices, the Ritz shapes, and the
flexible sheave faces (issue 20): ``fc`` (2, H + 1, d + 1) Chebyshev coefficients of each pulley's face
compliance ``c_n(r)`` and ``fr`` (2, 2) their radius ranges (``S_FLEX`` = 0: rigid faces, not read), and their
table in phi ``tab`` (:class:`~cvtfem.elements.band.face_table.FaceTable` values; grid start, step and intervals in
``S_TLO``, ``S_TH``, ``S_TN``, ``S_TN`` = 0: no table), read where it covers phi, the exact face systems elsewhere.
Complex powers are written as products: numba's complex ``z ** k`` goes through exp/log, whose
rounding (~1e-16 |z|^k in the imaginary part) swamps a 1e-30 complex step.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.jit import HAVE_NUMBA, njit

H = 1e-30  # complex step, as in compressible.py
LAW_CODES = {"tanh": 0, "smoothed": 1, "linear-saturated": 2}
# scalar slots of ``s``
(S_LENGTH, S_L, S_MASS, S_RHO, S_CEDGE, S_C, S_KAPPA, S_BETA, S_F0, S_V0, S_LAW, S_FRICTION, S_SHAFT,
 S_DAMPING, S_GYRO, S_NU, S_FLEX, S_TLO, S_TH, S_TN) = range(20)


def pack(model) -> tuple:
    """Kernel arguments of a :class:`CompressibleBand` (arrays only, built once per model)."""
    p, c = model.p, model._c
    table = c.get("table")
    s = np.array([p.length, p.L, p.mass, p.rho, c["c_edge"], p.c, p.kappa, c["beta"], p.f0, p.v0,
                  LAW_CODES[p.law], p.friction, model.shaft_compliance, p.damping, p.gyroscopic, p.damping_ratio,
                  model.faces is not None, table.lo if table else 0.0, table.h if table else 1.0,
                  table.values.shape[0] - 1 if table else 0], dtype=float)
    tab = np.ascontiguousarray(table.values) if table else np.zeros((2, 2, 2, 1, 1))
    sh = np.array([[0.0 if f.profile == "conical" else 1.0, f.gamma, f.R, f.y, f.w] for f in p.sheaves])
    sf = np.array([[p.J[k], p.m_sheave[k], p.Theta[k], p.c_U[k], p.c_psi[k]] for k in range(2)])
    if model.faces is None:
        fc, fr = np.zeros((2, 1, 1)), np.array([[0.0, 1.0], [0.0, 1.0]])
    else:
        fc = np.ascontiguousarray(np.stack([f.coef for f in model.faces]))
        fr = np.array([[f.r_lo, f.r_hi] for f in model.faces])
    return s, sh, sf, np.ascontiguousarray(c["xidx"]), c["xi"], c["wq"], c["F"], c["dF"], fc, fr, tab


@njit(cache=True)
def _table_at(tab, s, phi, k):
    """Hermite interpolation of the face table (``FaceTable.at``) for arc ``k``: ``(on, value, d/dphi)`` of
    ``[dG; dK]``, each ``(g + nx, nx)``; ``on`` false off the grid (the caller solves the exact face systems)."""
    nint = int(s[S_TN])
    h = s[S_TH]
    u = (phi - s[S_TLO]) / h
    if nint == 0 or u < 0.0 or u > nint:
        return False, tab[0, k, 0], tab[0, k, 1]
    i = min(int(u), nint - 1)
    t = u - i
    t2, t3 = t * t, t * t * t
    w0, w1, w2, w3 = 2 * t3 - 3 * t2 + 1, (t3 - 2 * t2 + t) * h, 3 * t2 - 2 * t3, (t3 - t2) * h
    d0, d1, d2, d3 = (6 * t2 - 6 * t) / h, 3 * t2 - 4 * t + 1, (6 * t - 6 * t2) / h, 3 * t2 - 2 * t
    a, b = tab[i, k], tab[i + 1, k]
    val = w0 * a[0] + w1 * a[1] + w2 * b[0] + w3 * b[1]
    der = d0 * a[0] + d1 * a[1] + d2 * b[0] + d3 * b[1]
    return True, val, der


@njit(cache=True)
def _face_system(fck, frk, ce, r, th, ds):
    """``A = I + c' K_f D`` of one arc (complex, (g, g)) as ``CompressibleBand.arcs``: the face compliance
    ``c_n(r)`` by Clenshaw's recurrence, ``K_f = C^T diag(c) C + S^T diag(c) S`` symmetrised."""
    x = (2 * r - (frk[0] + frk[1])) / (frk[1] - frk[0])
    nh, nd = fck.shape
    g = th.size
    C = np.empty((nh, g), np.complex128)
    S = np.empty((nh, g), np.complex128)
    cC = np.empty((nh, g), np.complex128)
    cS = np.empty((nh, g), np.complex128)
    for n in range(nh):
        b1, b2 = 0j, 0j
        for k in range(nd - 1, 0, -1):
            b1, b2 = 2 * x * b1 - b2 + fck[n, k], b1
        c = x * b1 - b2 + fck[n, 0]
        for j in range(g):
            if n < 2:  # cos n theta, sin n theta: directly for n = 0, 1, then by the Chebyshev recurrence
                C[n, j], S[n, j] = np.cos(n * th[j]), np.sin(n * th[j])
            else:
                C[n, j] = 2 * C[1, j] * C[n - 1, j] - C[n - 2, j]
                S[n, j] = 2 * C[1, j] * S[n - 1, j] - S[n - 2, j]
            cC[n, j], cS[n, j] = c * C[n, j], c * S[n, j]
    K = C.T.copy() @ cC + S.T.copy() @ cS
    A = np.empty((g, g), np.complex128)
    for i in range(g):
        for j in range(g):
            A[i, j] = ce * 0.5 * (K[i, j] + K[j, i]) * ds[j]
        A[i, i] += 1.0
    return A


@njit(cache=True)
def _face(shk, r):
    """``(tan gamma, z0, lever)`` of sheave face ``shk`` at contact radius r (complex), as Sheave does."""
    if shk[0] == 0.0:
        tg = np.tan(shk[1]) + 0.0 * r
        z0 = shk[4] - r * np.tan(shk[1])
    else:
        u = (r + shk[3]) / shk[2]
        tg = u / np.sqrt(1.0 - u * u)
        z0 = shk[4] + np.sqrt(shk[2] * shk[2] - (r + shk[3]) * (r + shk[3]))
    return tg, z0, shk[4] - z0


@njit(cache=True)
def _geometry(phi, s, sh, xi, wq, dF, nx, shaft):
    """Arc geometry at complex phi: r, dr, tg, z0, lever (2,), th, ds (2, g), fr (2, n, g), E (2, nx, g)."""
    length, L = s[S_LENGTH], s[S_L]
    sn, cs = np.sin(phi), np.cos(phi)
    S = (length - 2 * L * (cs + phi * sn)) / np.pi
    n, g = dF.shape
    r = np.empty(2, np.complex128)
    dr = np.empty(2, np.complex128)
    ts = np.empty(2, np.complex128)
    tg = np.empty(2, np.complex128)
    z0 = np.empty(2, np.complex128)
    lev = np.empty(2, np.complex128)
    th = np.empty((2, g), np.complex128)
    ds = np.empty((2, g), np.complex128)
    fr = np.empty((2, n, g), np.complex128)
    E = np.zeros((2, nx, g), np.complex128)
    cth = np.zeros((2, g))
    sth = np.zeros((2, g))
    for k in range(2):
        sg = 1.0 - 2.0 * k
        r[k] = 0.5 * (S + sg * L * sn)
        dr[k] = L * cs * (0.5 * sg - phi / np.pi)
        ts[k] = np.pi / 2 + sg * phi
        tg[k], z0[k], lev[k] = _face(sh[k], r[k])
        for j in range(g):
            th[k, j] = ts[k] * xi[j]
            ds[k, j] = r[k] * ts[k] * wq[j]
            E[k, 0, j] = 1.0
            for i in range(n):
                fr[k, i, j] = -dF[i, j] / ts[k]
                E[k, 1 + i, j] = tg[k] * fr[k, i, j]
            if shaft:
                ta = th[k, j] + np.pi * k
                ca, sa = np.cos(ta), np.sin(ta)
                cth[k, j], sth[k, j] = ca.real, sa.real
                lv = r[k] + tg[k] * lev[k]
                E[k, n + 1, j] = -tg[k] * ca
                E[k, n + 2, j] = -tg[k] * sa
                E[k, n + 3, j] = lv * sa
                E[k, n + 4, j] = -lv * ca
    return r, dr, tg, z0, lev, th, ds, fr, E, cth, sth


@njit(cache=True)
def _band_inertia(phi, r, s):
    """A(phi) of eq. (1.45, corrected), as ``inertia.band_inertia``."""
    L = s[S_L]
    p1, p2 = np.pi + 2 * phi, np.pi - 2 * phi
    b1, b2 = 0.5 - phi / np.pi, 0.5 + phi / np.pi
    f2 = phi * phi
    cphi = np.cos(phi)
    arcs = r[0] * (p1 + p1 * p1 * p1 / 12) * b1 * b1 + r[1] * (p2 + p2 * p2 * p2 / 12) * b2 * b2
    spans = L * cphi * (1 / 6 + np.pi ** 2 / 8 - (1 - 2 / np.pi ** 2) * f2 + 2 * f2 * f2 / np.pi ** 2)
    return s[S_RHO] * L * L * cphi * cphi * (arcs + spans)


@njit(cache=True)
def _band_mass(phi, s, r, dr, th, ds, fr, Fs):
    """Band block of the mass matrix over ``[phi, sigma, h1, h2]`` (complex), as ``band_mass``."""
    n, g = Fs.shape
    rho = s[S_RHO]
    M = np.zeros((2 + 2 * n, 2 + 2 * n), np.complex128)
    M[0, 0] = _band_inertia(phi, r, s)
    M[1, 1] = s[S_MASS]
    for k in range(2):
        o = 2 + k * n
        for i in range(n):
            a1 = 0.0j
            a0 = 0.0j
            for j in range(g):
                a1 += Fs[i, j] * ds[k, j]
                a0 += (fr[k, i, j] - th[k, j] * Fs[i, j]) * ds[k, j]
            M[1, o + i] = M[o + i, 1] = rho * a1
            M[0, o + i] = M[o + i, 0] = rho * dr[k] * a0
            for m in range(i, n):
                acc = 0.0j
                for j in range(g):
                    acc += (fr[k, i, j] * fr[k, m, j] + Fs[i, j] * Fs[m, j]) * ds[k, j]
                M[o + i, o + m] = M[o + m, o + i] = rho * acc
    return M


@njit(cache=True)
def _gain(x, law):
    """``f(v) / v`` in units of ``f0 / v0`` at ``x = v / v0``, as ``friction.friction_gain``."""
    if law == 0:
        return np.tanh(x) / x if x > 1e-8 else 1.0 - x * x / 3
    if law == 1:
        return 1.5 - 0.5 * x * x if x < 1.0 else 1.0 / x
    return 1.0 if x < 1.0 else 1.0 / x


@njit(cache=True)
def accel_kernel(q, v, F, Mt, s, sh, sf, xidx, xi, wq, Fs, dF, fc, frng, tab):
    """Accelerations ``a`` (n2,), normal force ``N`` (2, g) N/m, strain ``eps`` (2, g), circumferential slip
    at the arc middles and largest slip per arc (2,) m/s, dissipation and clamping power (W); the numpy
    ``CompressibleBand.accel`` statement by statement."""
    n, g = Fs.shape
    n2 = q.size
    nx = xidx.shape[1]
    shaft = s[S_SHAFT] != 0.0
    ce = s[S_CEDGE]
    rc, drc, tgc, z0c, levc, thc, dsc, frc, Ec, cs, sn = _geometry(q[0] + 1j * H, s, sh, xi, wq, dF, nx, shaft)
    r, dr, tg, th, ds, fr, E, lev = rc.real, drc.real, tgc.real, thc.real, dsc.real, frc.real, Ec.real, levc.real
    Q = np.zeros(n2)
    eps = np.empty((2, g))
    deps = np.empty((2, g))
    Pi_im = 0.0
    flex = s[S_FLEX] != 0.0
    Ed = E  # d eps / d x at the nodes (flexible faces: A^-1 E^T, or E + dG^T from the table)
    if flex:
        Ed = np.empty((2, nx, g))
    for k in range(2):
        on, val, der = _table_at(tab, s, q[0], k)
        on = on and flex
        xt0 = q[xidx[k, 0]] - z0c[k]  # flexible faces: eps_r = E^T x~, x~ = x - z0 e_0 (z - z0 rounded once)
        if flex and not on:  # exact face systems: eps = A^-1 eps_r, V = c' int eps eps_r ds
            er = np.empty(g, np.complex128)
            for j in range(g):
                e = xt0 * Ec[k, 0, j]
                for x in range(1, nx):
                    e += q[xidx[k, x]] * Ec[k, x, j]
                er[j] = e
            A = _face_system(fc[k], frng[k], ce, rc[k], thc[k], dsc[k])
            rhs = np.empty((g, nx + 1), np.complex128)  # one LU: the strain and (real parts) A^-1 E^T
            rhs[:, 0] = er
            rhs[:, 1:] = E[k].T
            X = np.linalg.solve(A, rhs)
            for j in range(g):
                ec = X[j, 0]
                eps[k, j], deps[k, j] = ec.real, ec.imag / H
                Pi_im += (ce * ec * er[j] * dsc[k, j]).imag
                for x in range(nx):
                    Ed[k, x, j] = X[j, 1 + x].real
        else:
            for j in range(g):
                if on:
                    e = xt0 * Ec[k, 0, j]
                    for x in range(1, nx):
                        e += q[xidx[k, x]] * Ec[k, x, j]
                else:
                    e = -z0c[k]
                    for x in range(nx):
                        e += q[xidx[k, x]] * Ec[k, x, j]
                eps[k, j], deps[k, j] = e.real, e.imag / H
                Pi_im += (ce * e * e * dsc[k, j]).imag
        for x in range(nx):
            acc = 0.0
            for j in range(g):
                acc += E[k, x, j] * eps[k, j] * ds[k, j]
            Q[xidx[k, x]] -= 2 * ce * acc
        if on:  # the table (CompressibleBand.accel_numpy): eps = eps_r + dG x~, V += c' x~^T dK x~
            xt = np.empty(nx)
            for x in range(nx):
                xt[x] = q[xidx[k, x]]
            xt[0] = xt0.real
            dxt0 = xt0.imag / H  # d x~ / d phi: only z0 moves
            for j in range(g):
                e, de = 0.0, val[j, 0] * dxt0
                for x in range(nx):
                    e += val[j, x] * xt[x]
                    de += der[j, x] * xt[x]
                    Ed[k, x, j] = E[k, x, j] + val[j, x]
                eps[k, j] += e
                deps[k, j] += de
            for x in range(nx):
                kx, kdx = 0.0, 0.0
                for y in range(nx):
                    kx += val[g + x, y] * xt[y]
                    kdx += der[g + x, y] * xt[y]
                Q[xidx[k, x]] -= 2 * ce * kx
                Q[0] -= ce * xt[x] * kdx
                if x == 0:
                    Q[0] -= 2 * ce * dxt0 * kx
    Q[0] -= Pi_im / H
    Q[4] -= s[S_KAPPA] * F[0]
    Q[5] -= s[S_KAPPA] * F[1]
    dissipation = 0.0
    b = 6 + 2 * n
    if shaft:
        for k in range(2):
            o = b + 4 * k
            for i in range(4):
                stiff = sf[k, 3] if i < 2 else sf[k, 4]
                Q[o + i] -= stiff * q[o + i]
                if s[S_DAMPING] != 0.0:
                    d = 2 * s[S_NU] * np.sqrt(stiff * (sf[k, 1] if i < 2 else sf[k, 2]))
                    Q[o + i] -= d * v[o + i]
                    dissipation += d * v[o + i] ** 2
    beta = s[S_BETA]
    if beta > 0:
        Qd = np.zeros(n2)
        for k in range(2):
            dd = np.empty(g)
            for j in range(g):
                acc = deps[k, j] * v[0]
                for x in range(nx):
                    acc += v[xidx[k, x]] * Ed[k, x, j]
                dd[j] = acc
                Qd[0] -= 2 * beta * ce * acc * deps[k, j] * ds[k, j]
            for x in range(nx):
                acc = 0.0
                for j in range(g):
                    acc += Ed[k, x, j] * dd[j] * ds[k, j]
                Qd[xidx[k, x]] = -2 * beta * ce * acc
        for i in range(n2):
            dissipation -= Qd[i] * v[i]
            Q[i] += Qd[i]
    N = np.zeros((2, g))
    vr = np.zeros((3, 2, g))
    if s[S_FRICTION] != 0.0:
        f0, v0, law = s[S_F0], s[S_V0], int(s[S_LAW])
        Qf = np.zeros(n2)
        for k in range(2):
            cosg = 1.0 / np.sqrt(1.0 + tg[k] ** 2)
            for j in range(g):
                vr_r = dr[k] * v[0]
                vr_t = v[1] - th[k, j] * dr[k] * v[0] - r[k] * v[2 + k]
                for i in range(n):
                    hd = v[6 + k * n + i]
                    vr_r += fr[k, i, j] * hd
                    vr_t += hd * Fs[i, j]
                if shaft:
                    o = b + 4 * k
                    U0, U1, P0, P1 = v[o], v[o + 1], v[o + 2], v[o + 3]
                    a = lev[k]
                    vr_r = vr_r - (U0 * cs[k, j] + U1 * sn[k, j]) - a * (-P0 * sn[k, j] + P1 * cs[k, j])
                    vr_t = vr_t - (-U0 * sn[k, j] + U1 * cs[k, j]) + a * (P0 * cs[k, j] + P1 * sn[k, j])
                vr_z = tg[k] * vr_r
                vr[0, k, j], vr[1, k, j], vr[2, k, j] = vr_r, vr_t, vr_z
                gn = (f0 / v0) * _gain(np.sqrt(vr_r ** 2 + vr_t ** 2 + vr_z ** 2) / v0, law)
                Nk = max(0.0, -s[S_C] * eps[k, j] / (cosg + gn * vr_z))
                N[k, j] = Nk
                T0, T1, T2 = gn * vr_r * Nk * ds[k, j], gn * vr_t * Nk * ds[k, j], gn * vr_z * Nk * ds[k, j]
                Tn = T0 + tg[k] * T2
                Qf[0] -= 2 * dr[k] * (Tn - th[k, j] * T1)
                Qf[1] -= 2 * T1
                Qf[2 + k] += 2 * r[k] * T1
                for i in range(n):
                    Qf[6 + k * n + i] -= 2 * (fr[k, i, j] * Tn + T1 * Fs[i, j])
                if shaft:
                    o = b + 4 * k
                    a = lev[k]
                    Qf[o] += 2 * (cs[k, j] * Tn - sn[k, j] * T1)
                    Qf[o + 1] += 2 * (sn[k, j] * Tn + cs[k, j] * T1)
                    Qf[o + 2] -= 2 * a * (sn[k, j] * Tn + cs[k, j] * T1)
                    Qf[o + 3] += 2 * a * (cs[k, j] * Tn - sn[k, j] * T1)
        for i in range(n2):
            dissipation -= Qf[i] * v[i]
            Q[i] += Qf[i]
    else:
        for k in range(2):
            vr[1, k, :] = v[1] - r[k] * v[2 + k]
    Q[2] += Mt[0]
    Q[3] += Mt[1]
    a = _solve(q, v, Q, s, sf, rc, drc, thc, dsc, frc, Fs, q[0] + 1j * H, shaft)
    clamp_power = -s[S_KAPPA] * (F[0] * v[4] + F[1] * v[5])
    slip = np.empty(2)
    slip_max = np.zeros(2)
    for k in range(2):
        slip[k] = vr[1, k, g // 2]
        for j in range(g):
            slip_max[k] = max(slip_max[k], np.sqrt(vr[0, k, j] ** 2 + vr[1, k, j] ** 2 + vr[2, k, j] ** 2))
    return a, N, eps, slip, slip_max, dissipation, clamp_power


@njit(cache=True)
def _solve(q, v, Q, s, sf, rc, drc, thc, dsc, frc, Fs, phic, shaft):
    n = Fs.shape[0]
    nb = 2 + 2 * n
    Mc = _band_mass(phic, s, rc, drc, thc, dsc, frc, Fs)
    Mb = np.ascontiguousarray(Mc.real)
    dMb = Mc.imag / H
    bi = np.empty(nb, np.int64)
    bi[0], bi[1] = 0, 1
    for i in range(2 * n):
        bi[2 + i] = 6 + i
    vb = np.empty(nb)
    for i in range(nb):
        vb[i] = v[bi[i]]
    dv = dMb @ vb
    rhs = np.empty(nb)
    for i in range(nb):
        rhs[i] = Q[bi[i]] - v[0] * dv[i]
    rhs[0] += 0.5 * np.dot(vb, dv)
    ab = np.linalg.solve(Mb, rhs)
    a = np.empty(q.size)
    for i in range(nb):
        a[bi[i]] = ab[i]
    a[4] = Q[4] / sf[0, 1]
    a[5] = Q[5] / sf[1, 1]
    if not shaft:
        a[2] = Q[2] / sf[0, 0]
        a[3] = Q[3] / sf[1, 0]
        return a
    b = 6 + 2 * n
    for k in range(2):
        j = b + 4 * k
        a[j] = Q[j] / sf[k, 1]
        a[j + 1] = Q[j + 1] / sf[k, 1]
        J, Th = sf[k, 0], sf[k, 2]
        p1, p2, d1, d2 = q[j + 2], q[j + 3], v[j + 2], v[j + 3]
        if s[S_GYRO] != 0.0:
            w_ax = v[2 + k] + 0.5 * (d1 * p2 - d2 * p1)
            wdot = Q[2 + k] / J
            a[j + 2] = (Q[j + 2] - 0.5 * J * wdot * p2 - J * w_ax * d2) / Th
            a[j + 3] = (Q[j + 3] + 0.5 * J * wdot * p1 + J * w_ax * d1) / Th
            a[2 + k] = wdot - 0.5 * (a[j + 2] * p2 - a[j + 3] * p1)
        else:
            a[j + 2] = Q[j + 2] / Th
            a[j + 3] = Q[j + 3] / Th
            a[2 + k] = Q[2 + k] / J
    return a


@njit(cache=True)
def jacobian_kernel(q, v, F, Mt, s, sh, sf, xidx, xi, wq, Fs, dF, fc, frng, tab):
    """Forward-difference Jacobian of ``y = [a, dissipation, clamp_power]`` (n2 + 2) with respect to
    ``[q, v, F, M]`` (2 n2 + 4 columns); the rotation angles q[1:4] never enter, their columns are 0.

    Increments as ``BandCVT.jac``: ``1e-8 max(1e-3, |q_j|)`` for coordinates, ``1e-7 max(1, |v_j|)``
    for velocities; ``y`` is affine in F and M, so their columns are exact to rounding.
    """
    n2 = q.size
    a0, _, _, _, _, d0, c0 = accel_kernel(q, v, F, Mt, s, sh, sf, xidx, xi, wq, Fs, dF, fc, frng, tab)
    Jm = np.zeros((n2 + 2, 2 * n2 + 4))
    for col in range(2 * n2 + 4):
        if 1 <= col <= 3:
            continue
        qp, vp, Fp, Mp = q.copy(), v.copy(), F.copy(), Mt.copy()
        if col < n2:
            h = 1e-8 * max(1e-3, abs(q[col]))
            qp[col] += h
        elif col < 2 * n2:
            h = 1e-7 * max(1.0, abs(v[col - n2]))
            vp[col - n2] += h
        elif col < 2 * n2 + 2:
            h = 1e-6 * max(1.0, abs(F[col - 2 * n2]))
            Fp[col - 2 * n2] += h
        else:
            h = 1e-6 * max(1.0, abs(Mt[col - 2 * n2 - 2]))
            Mp[col - 2 * n2 - 2] += h
        a1, _, _, _, _, d1, c1 = accel_kernel(qp, vp, Fp, Mp, s, sh, sf, xidx, xi, wq, Fs, dF, fc, frng, tab)
        for i in range(n2):
            Jm[i, col] = (a1[i] - a0[i]) / h
        Jm[n2, col] = (d1 - d0) / h
        Jm[n2 + 1, col] = (c1 - c0) / h
    return Jm


@njit(cache=True)
def energy_kernel(q, v, s, sh, sf, xidx, xi, wq, Fs, dF, fc, frng, tab):
    """Kinetic and elastic energy ``(T, V)``, J, as ``CompressibleBand.kinetic_energy`` and ``elastic_energy``
    (real geometry: the complex kernels at ``phi + 0j``; strain summed as the numpy twin's, ``E^T x - z0``)."""
    n, g = Fs.shape
    nx = xidx.shape[1]
    shaft = s[S_SHAFT] != 0.0
    phic = q[0] + 0j
    rc, drc, _, z0c, _, thc, dsc, frc, Ec, _, _ = _geometry(phic, s, sh, xi, wq, dF, nx, shaft)
    Mb = _band_mass(phic, s, rc, drc, thc, dsc, frc, Fs).real
    nb = 2 + 2 * n
    vb = np.empty(nb)
    vb[0], vb[1] = v[0], v[1]
    for i in range(2 * n):
        vb[2 + i] = v[6 + i]
    T = 0.0
    for i in range(nb):
        acc = 0.0
        for m in range(nb):
            acc += Mb[i, m] * vb[m]
        T += vb[i] * acc
    T = 0.5 * T + 0.5 * (sf[0, 1] * v[4] ** 2 + sf[1, 1] * v[5] ** 2)
    b = 6 + 2 * n
    if shaft:
        for k in range(2):
            j = b + 4 * k
            w_ax = v[2 + k]
            if s[S_GYRO] != 0.0:
                w_ax += 0.5 * (v[j + 2] * q[j + 3] - v[j + 3] * q[j + 2])
            T += 0.5 * (sf[k, 1] * (v[j] ** 2 + v[j + 1] ** 2) + sf[k, 0] * w_ax ** 2
                        + sf[k, 2] * (v[j + 2] ** 2 + v[j + 3] ** 2))
    else:
        T += 0.5 * (sf[0, 0] * v[2] ** 2 + sf[1, 0] * v[3] ** 2)
    E, ds, z0 = Ec.real, dsc.real, z0c.real
    V = 0.0
    for k in range(2):
        er = np.empty(g)
        xt = np.empty(nx)  # flexible faces: eps_r = E^T x~, x~ = x - z0 e_0 (as accel_kernel)
        for x in range(nx):
            xt[x] = q[xidx[k, x]]
        xt[0] -= z0[k]
        for j in range(g):
            e = 0.0
            if s[S_FLEX] != 0.0:
                for x in range(nx):
                    e += xt[x] * E[k, x, j]
            else:
                for x in range(nx):
                    e += q[xidx[k, x]] * E[k, x, j]
                e -= z0[k]
            er[j] = e
        on, val, _ = _table_at(tab, s, q[0], k)
        if on and s[S_FLEX] != 0.0:  # the band's strain energy and the sheaves', c' x~^T dK x~ (the table)
            for j in range(g):
                V += er[j] * er[j] * ds[k, j]
            for x in range(nx):
                for y in range(nx):
                    V += xt[x] * val[g + x, y] * xt[y]
        elif s[S_FLEX] != 0.0:  # the band's and the sheaves' strain energy, c' int eps eps_r ds (exact)
            A = _face_system(fc[k], frng[k], s[S_CEDGE], rc[k], thc[k], dsc[k]).real
            ef = np.linalg.solve(np.ascontiguousarray(A), er)
            for j in range(g):
                V += ef[j] * er[j] * ds[k, j]
        else:
            for j in range(g):
                V += er[j] * er[j] * ds[k, j]
    V *= s[S_CEDGE]
    if shaft:
        for k in range(2):
            j = b + 4 * k
            V += 0.5 * (sf[k, 3] * (q[j] ** 2 + q[j + 1] ** 2) + sf[k, 4] * (q[j + 2] ** 2 + q[j + 3] ** 2))
    return T, V
