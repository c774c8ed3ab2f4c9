"""Compiled right-hand side and kinetic energy of the 4-DOF band model (numba); ``FourDofBand.accel_numpy`` and
``FourDofBand.kinetic_energy`` are their reference twins.

Same statements as the numpy method (complex step in phi for A and its derivative, Gauss quadrature
of the friction along each arc, the 3x3 elimination for N_k), written as loops over the two arcs
and the nodes; parameters are packed into the scalar layout of ``compressible_kernel`` (``S_*``).
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.band.compressible_kernel import (
    LAW_CODES, S_F0, S_FRICTION, S_KAPPA, S_L, S_LAW, S_LENGTH, S_MASS, S_RHO, S_V0, _band_inertia, _face, _gain, njit)

H = 1e-30  # complex step


def pack(model) -> tuple:
    """Kernel arguments of a :class:`FourDofBand`: scalars ``s``, sheaves ``sh`` (2, 5), ``J``, ``m_sheave``, nodes."""
    p = model.p
    s = np.zeros(16)
    s[[S_LENGTH, S_L, S_MASS, S_RHO, S_KAPPA, S_F0, S_V0, S_LAW, S_FRICTION]] = (
        p.length, p.L, p.mass, p.rho, p.kappa, p.f0, p.v0, LAW_CODES[p.law], p.friction)
    sh = np.array([[0.0 if f.profile == "conical" else 1.0, f.gamma, f.R, f.y, f.w] for f in p.sheaves])
    return s, sh, np.array(p.J, float), np.array(p.m_sheave, float), model._xi, model._wq


@njit(cache=True)
def accel4_kernel(q, v, F, Mt, s, sh, J, msh, xi, wq):
    """Accelerations (4,), normal forces N (2,) N/m, slip at the arc middles and largest slip (2,) m/s,
    dissipation and clamping power (W), as ``FourDofBand.accel_numpy``."""
    length, L = s[S_LENGTH], s[S_L]
    phi, dphi = q[0], v[0]
    phic = phi + 1j * H
    sn, cs = np.sin(phic), np.cos(phic)
    S = (length - 2 * L * (cs + phic * sn)) / np.pi
    rc = np.empty(2, np.complex128)
    r, dr, ddr, tg, dtg, ts = np.empty(2), np.empty(2), np.empty(2), np.empty(2), np.empty(2), np.empty(2)
    Ac = 0.0j
    for k in range(2):
        sg = 1.0 - 2.0 * k
        rc[k] = 0.5 * (S + sg * L * sn)
        drc = L * cs * (0.5 * sg - phic / np.pi)
        tgc, _, _ = _face(sh[k], rc[k])
        Ac += msh[k] * (tgc * drc) * (tgc * drc)
        r[k], dr[k], tg[k] = rc[k].real, drc.real, tgc.real
        ddr[k] = -L * np.sin(phi) * (0.5 * sg - phi / np.pi) - L * np.cos(phi) / np.pi
        if sh[k, 0] == 0.0:
            dtg[k] = 0.0
        else:
            u = (r[k] + sh[k, 3]) / sh[k, 2]
            dtg[k] = 1.0 / (sh[k, 2] * (1.0 - u * u) ** 1.5)
        ts[k] = np.pi / 2 + sg * phi
    Ac += _band_inertia(phic, rc, s)
    A, dA = Ac.real, Ac.imag / H
    kappa = s[S_KAPPA]
    rhs_phi = kappa * (F[0] * tg[0] * dr[0] + F[1] * tg[1] * dr[1]) - 0.5 * dA * dphi ** 2
    a = np.empty(4)
    N = np.zeros(2)
    slip = np.empty(2)
    slip_max = np.zeros(2)
    dissipation = 0.0
    for k in range(2):
        slip[k] = v[1] - r[k] * v[2 + k]
    if s[S_FRICTION] != 0.0:
        f0, v0, law = s[S_F0], s[S_V0], int(s[S_LAW])
        G_phi, G_sig, G_sh = np.empty(2), np.empty(2), np.empty(2)
        alpha, beta = np.empty(2), np.empty(2)
        for k in range(2):
            a_r = dr[k] * dphi
            a_z = tg[k] * a_r
            IG = IGt = IGtt = vt2 = 0.0
            for j in range(xi.size):
                th = ts[k] * xi[j]
                vt = v[1] - th * a_r - r[k] * v[2 + k]
                G = (f0 / v0) * _gain(np.sqrt(vt * vt + a_r * a_r + a_z * a_z) / v0, law) * r[k] * ts[k] * wq[j]
                IG += G
                IGt += G * vt
                IGtt += G * vt * th
                vt2 = max(vt2, vt * vt)
            G_phi[k] = -2 * dr[k] * (a_r * (1 + tg[k] * tg[k]) * IG - IGtt)
            G_sig[k] = -2 * IGt
            G_sh[k] = 2 * r[k] * IGt
            P = -2 * r[k] * ts[k] / np.sqrt(1 + tg[k] * tg[k]) - a_z * IG
            alpha[k] = (0.5 * msh[k] * (ddr[k] * tg[k] + dr[k] ** 2 * dtg[k]) * dphi ** 2 - F[k]) / P
            beta[k] = 0.5 * msh[k] * dr[k] * tg[k] / P
            slip_max[k] = np.sqrt(vt2 + a_r * a_r + a_z * a_z)
        a[0] = (rhs_phi + alpha[0] * G_phi[0] + alpha[1] * G_phi[1]) / (A - beta[0] * G_phi[0] - beta[1] * G_phi[1])
        for k in range(2):
            N[k] = alpha[k] + beta[k] * a[0]
        a[1] = (N[0] * G_sig[0] + N[1] * G_sig[1]) / s[S_MASS]
        for k in range(2):
            a[2 + k] = (Mt[k] + N[k] * G_sh[k]) / J[k]
        dissipation = -((N[0] * G_phi[0] + N[1] * G_phi[1]) * v[0] + (N[0] * G_sig[0] + N[1] * G_sig[1]) * v[1]
                        + N[0] * G_sh[0] * v[2] + N[1] * G_sh[1] * v[3])
    else:
        a[0] = rhs_phi / A
        a[1] = 0.0
        for k in range(2):
            a[2 + k] = Mt[k] / J[k]
    clamp_power = kappa * (F[0] * tg[0] * dr[0] + F[1] * tg[1] * dr[1]) * dphi
    return a, N, slip, slip_max, dissipation, clamp_power


@njit(cache=True)
def kinetic4_kernel(q, v, s, sh, J, msh):
    """Kinetic energy ``(Acal phi'^2 + m sigma'^2 + sum J_k phi_k'^2) / 2``, J, as ``FourDofBand.kinetic_energy``."""
    length, L = s[S_LENGTH], s[S_L]
    phi = q[0]
    sn, cs = np.sin(phi), np.cos(phi)
    S = (length - 2 * L * (cs + phi * sn)) / np.pi
    r = np.empty(2)
    A = 0.0
    for k in range(2):
        sg = 1.0 - 2.0 * k
        r[k] = 0.5 * (S + sg * L * sn)
        dr = L * cs * (0.5 * sg - phi / np.pi)
        tg, _, _ = _face(sh[k], r[k])
        A += msh[k] * (tg * dr) ** 2
    A = _band_inertia(phi, r, s) + A
    return 0.5 * (A * v[0] ** 2 + s[S_MASS] * v[1] ** 2 + (J[0] * v[2] ** 2 + J[1] * v[3] ** 2))
