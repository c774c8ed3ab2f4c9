"""Compiled local pass of :class:`~cvtfem.elements.chain.sheave_contact_refined.RefinedSheaveContact` (H2 on the
running chain): the same formulas in the same order, one loop over the contacts, outputs written in place.
:meth:`RefinedSheaveContact.local` with ``reference=True`` (numpy) is the tested twin.  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.contact.kernels import _cross, _slip_and_friction
from cvtfem.elements.contact.meridian import TORUS, evaluate
from cvtfem.elements.jit import njit


@njit(cache=True)
def _third(params, r):
    """``f'''`` (1/m^2) of a :class:`~cvtfem.elements.contact.meridian.Meridian` at radius ``r``."""
    if params[0] != TORUS:
        return 0.0
    u = r + params[2]
    w = np.sqrt(params[1] * params[1] - u * u)
    return -3.0 * params[1] * params[1] * u / w ** 5


@njit(cache=True)
def refined_local_kernel(X, shafts, centres, meridians, face, slopes, slope_factor, c, f0, v0, law, eps,
                         Y, slip, friction):
    """Local outputs ``Y`` (m, n_out) of H2 chain contacts with inputs ``X`` (m, n_in) (layout of
    :class:`RefinedSheaveContact`); ``meridians`` (2, 4) the shafts' face profiles ``f = -s(r)`` as
    :attr:`Meridian.params`; ``face`` the pin end face ``(R_f (m), tan(theta))`` (:attr:`RefinedSheaveContact.face`);
    ``slip``, ``friction`` (m, 3) scratch.  Returns the index of the first contact with its pin end on the shaft
    axis, or -1."""
    s = -1.0
    npos = 10 if slopes else 8
    Rf, T = face[0], face[1]
    bad = -1
    for i in range(X.shape[0]):
        k = shafts[i]
        um0, um1, up0, up1, un0, un1, u3 = X[i, 0], X[i, 1], X[i, 2], X[i, 3], X[i, 4], X[i, 5], X[i, 6]
        vm0, vm1, vp0, vp1 = X[i, npos], X[i, npos + 1], X[i, npos + 2], X[i, npos + 3]
        vn0, vn1, u3d = X[i, npos + 4], X[i, npos + 5], X[i, npos + 6]
        g0 = g1 = gd0 = gd1 = 0.0
        if slopes:
            g0, g1 = slope_factor * X[i, 7], slope_factor * X[i, 8]
            gd0, gd1 = slope_factor * X[i, npos + 7], slope_factor * X[i, npos + 8]
        z, zd, w = X[i, npos - 1], X[i, 2 * npos - 1], X[i, 2 * npos]
        d0, d1 = up0 - centres[k, 0], up1 - centres[k, 1]
        r = np.sqrt(d0 * d0 + d1 * d1)
        if not r > 0.0:
            if bad < 0:
                bad = i
            r = 1.0
        e0, e1 = d0 / r, d1 / r
        n0, n1 = -e1, e0
        # pin spin from the unit chords: normal k x tau_p of the bisector, twist map (1.349)
        cp0, cp1, cn0, cn1 = up0 - um0, up1 - um1, un0 - up0, un1 - up1
        lp, ln = np.sqrt(cp0 * cp0 + cp1 * cp1), np.sqrt(cn0 * cn0 + cn1 * cn1)
        ep0, ep1, en0, en1 = cp0 / lp, cp1 / lp, cn0 / ln, cn1 / ln
        xb0, xb1 = ep0 + en0, ep1 + en1
        nx = np.sqrt(xb0 * xb0 + xb1 * xb1)
        np0, np1 = -xb1 / nx, xb0 / nx
        sp, sn = np0 * ep0 + np1 * ep1, np0 * en0 + np1 * en1
        tp0, tp1 = (np0 - sp * ep0) / (nx * lp), (np1 - sp * ep1) / (nx * lp)
        tn0, tn1 = (np0 - sn * en0) / (nx * ln), (np1 - sn * en1) / (nx * ln)
        q0, q1 = T * np0, T * np1                                # face slope beta_phi = T n_perp (mirrored frame)
        f, fp, fpp = evaluate(meridians[k], r)
        f3 = _third(meridians[k], r)
        me, mn = 1.0 / Rf - fpp, 1.0 / Rf - fp / r
        ge, gn = g0 * e0 + g1 * e1, g0 * n0 + g1 * n1
        qe, qn = q0 * e0 + q1 * e1, q0 * n0 + q1 * n1
        P, Pn = fp + s * ge - qe, s * gn - qn
        xe, xn = P / me, Pn / mn
        delta = s * (z - u3) + f + 0.5 * (P * xe + Pn * xn)
        ce = fp + xe * fpp + 0.5 * xe * xe * f3 + 0.5 * xn * xn * (fpp / r - fp / (r * r))
        cn = (xe * Pn - xn * (s * ge - qe)) / r
        dd0, dd1 = e0 * ce + n0 * cn, e1 * ce + n1 * cn
        x0, x1 = xe * e0 + xn * n0, xe * e1 + xn * n1
        dd = max(delta, 0.0)
        N = c[k] * dd * np.sqrt(dd)
        # contact point and normal
        Ax0, Ax1 = fpp * xe * e0 + fp / r * xn * n0, fpp * xe * e1 + fp / r * xn * n1
        gs0, gs1 = fp * e0 + Ax0, fp * e1 + Ax1
        z_pul = s * z + f + fp * (e0 * x0 + e1 * x1) + 0.5 * (x0 * Ax0 + x1 * Ax1)
        z_pin = s * u3 - s * (g0 * x0 + g1 * x1) + (q0 * x0 + q1 * x1) + 0.5 * (x0 * x0 + x1 * x1) / Rf
        p3 = 0.5 * s * (z_pul + z_pin)
        gl = np.sqrt(gs0 * gs0 + gs1 * gs1 + 1.0)
        nr0, nr1, nr2 = -gs0 / gl, -gs1 / gl, s / gl
        rho0, rho1, rho2 = x0, x1, p3 - u3
        a0, a1, a2 = d0 + x0, d1 + x1, p3 - z
        om = tp0 * (vp0 - vm0) + tp1 * (vp1 - vm1) + tn0 * (vn0 - vp0) + tn1 * (vn1 - vp1)
        l0, l1, l2 = _cross(g0, g1, 1.0, rho0, rho1, rho2)
        kg0, kg1, kg2 = _cross(0.0, 0.0, 1.0, gd0, gd1, 0.0)
        t0, t1, t2 = _cross(kg0, kg1, kg2, rho0, rho1, rho2)
        w0 = vp0 + t0 + om * l0 + w * a1
        w1 = vp1 + t1 + om * l1 - w * a0
        w2 = u3d + t2 + om * l2 - zd
        _slip_and_friction(i, w0, w1, w2, nr0, nr1, nr2, N, f0, v0, law, eps, slip, friction)
        F0, F1, F2 = friction[i, 0], friction[i, 1], friction[i, 2]
        # spin force: friction's work on (k + gamma) x rho and the turning face's -N dDelta/dphi = -N T x_* . tau_p
        Qphi = F0 * l0 + F1 * l1 + F2 * l2 - N * T * (x0 * xb0 + x1 * xb1) / nx
        m0, m1, _ = _cross(rho0, rho1, rho2, F0, F1, F2)
        rear0, rear1 = -Qphi * tp0, -Qphi * tp1
        front0, front1 = Qphi * tn0, Qphi * tn1
        Y[i, 0], Y[i, 1] = 2 * rear0, 2 * rear1
        Y[i, 2] = 2 * (-N * dd0 + F0 - rear0 - front0)
        Y[i, 3] = 2 * (-N * dd1 + F1 - rear1 - front1)
        Y[i, 4], Y[i, 5] = 2 * front0, 2 * front1
        Y[i, 6] = 2 * (s * N + F2)
        j = 7
        if slopes:
            Y[i, 7] = 2 * slope_factor * (-N * s * x0 + m1)
            Y[i, 8] = 2 * slope_factor * (-N * s * x1 - m0)
            j = 9
        Y[i, j] = 2 * (-s * N - F2)
        Y[i, j + 1] = -2 * (a0 * F1 - a1 * F0)
        Y[i, j + 2] = 2 * (F0 * slip[i, 0] + F1 * slip[i, 1] + F2 * slip[i, 2])
    return bad
