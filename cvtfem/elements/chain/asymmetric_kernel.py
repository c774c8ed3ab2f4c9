"""Compiled force kernel of the A1 chain (numba): one pass over links, two over pins.

The numpy methods of :class:`~cvtfem.elements.chain.asymmetric.ChainA1` are the reference twin:
:func:`forces` computes the same generalized forces, term by term (spec chain-models-2 section 2.8),
without numpy's per-call overhead on 84-element arrays (``tests/elements/chain/test_asymmetric.py``
checks the two against each other).  Without numba (``HAVE_NUMBA`` false) the family uses numpy.

Arguments: ``u (4, n, 2)``, ``w (2, n)``, their velocities ``vu, vw`` (``damped`` false: ignored),
the per-link arrays ``L, weight, cij (n, 4, 4), c_tors, c_shear`` and per-pin ``c_pin, b_pin, b_joint``
of the family, and the scalars ``par = [l, A_tau, A_n, beta_ext, beta_tors, beta_shear, beta_bend,
s_gamma, exact_joint]``.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.jit import HAVE_NUMBA, njit


def pack(ch) -> tuple:
    """Kernel arguments of a :class:`ChainA1` (built once per family)."""
    par = np.array([ch.l, ch.A_tau, ch.A_n, ch.beta_ext, ch.beta_tors, ch.beta_shear, ch.beta_bend, ch.s_gamma,
                    1.0 if ch.joint_damping_form == "exact" else 0.0])
    return (ch.L, ch.weight, np.ascontiguousarray(ch.cij), ch.c_tors, ch.c_shear, ch.c_pin, ch.b_pin, ch.b_joint, par)


@njit(cache=True)
def forces(u, w, vu, vw, damped, elastic, L, weight, cij, c_tors, c_shear, c_pin, b_pin, b_joint, par):
    """Generalized forces ``(Qu (4, n, 2), Qw (2, n))``: elastic if ``elastic``, plus dissipative if ``damped``."""
    n = w.shape[1]
    l, A_tau, A_n = par[0], par[1], par[2]
    beta_ext, beta_tors, beta_shear, beta_bend, sg = par[3], par[4], par[5], par[6], par[7]
    exact_joint = par[8] > 0.5
    Qu = np.zeros((4, n, 2))
    Qw = np.zeros((2, n))
    wt = np.zeros((n, 2))        # weighted link directions (bisector sums)
    wtd = np.zeros((n, 2))       # their rates
    W = np.zeros((n, 2))         # d omega_e / d u'_{e+1,0}
    om = np.zeros(n)             # link angular rates (1.82)
    du = np.zeros((4, 2))
    dv = np.zeros((4, 2))
    D = np.zeros(4)
    Dd = np.zeros(4)
    f = np.zeros(4)
    # ---- links e = (e, e+1): extension (1.140), twist (1.146), shear (1.153) and their rates
    for e in range(n):
        e1 = (e + 1) % n
        Le = L[e]
        for i in range(4):
            for c in range(2):
                du[i, c] = u[i, e1, c] - u[i, e, c]
                dv[i, c] = vu[i, e1, c] - vu[i, e, c]
        t0, t1 = du[0, 0] / Le, du[0, 1] / Le
        wt[e, 0], wt[e, 1] = weight[e] * t0, weight[e] * t1
        D[0] = 0.5 * Le * (t0 * t0 + t1 * t1 - 1.0)
        for i in range(1, 4):
            D[i] = t0 * du[i, 0] + t1 * du[i, 1]
        phi = 2.0 / l * (du[1, 0] * t1 - du[1, 1] * t0)
        s10, s11 = u[1, e, 0] + u[1, e1, 0], u[1, e, 1] + u[1, e1, 1]
        dw0 = w[0, e1] - w[0, e]
        gam = sg * ((s10 * t0 + s11 * t1) / l + dw0 / Le)
        for i in range(4):
            f[i] = 0.0
        ft = 0.0
        fs = 0.0
        if elastic:
            for i in range(4):
                for j in range(4):
                    f[i] += cij[e, i, j] * D[j]
            ft = c_tors[e] * phi
            fs = c_shear[e] * gam
        if damped:
            d0, d1 = dv[0, 0] / Le, dv[0, 1] / Le
            wtd[e, 0], wtd[e, 1] = weight[e] * d0, weight[e] * d1
            Dd[0] = t0 * dv[0, 0] + t1 * dv[0, 1]
            for i in range(1, 4):
                Dd[i] = t0 * dv[i, 0] + t1 * dv[i, 1] + d0 * du[i, 0] + d1 * du[i, 1]
            for i in range(4):
                for j in range(4):
                    f[i] += beta_ext * cij[e, i, j] * Dd[j]
            phid = 2.0 / l * (dv[1, 0] * t1 - dv[1, 1] * t0 + du[1, 0] * d1 - du[1, 1] * d0)
            s1d0, s1d1 = vu[1, e, 0] + vu[1, e1, 0], vu[1, e, 1] + vu[1, e1, 1]
            gamd = sg * ((s1d0 * t0 + s1d1 * t1 + s10 * d0 + s11 * d1) / l + (vw[0, e1] - vw[0, e]) / Le)
            ft += beta_tors * c_tors[e] * phid
            fs += beta_shear * c_shear[e] * gamd
            tt2 = t0 * t0 + t1 * t1
            W[e, 0], W[e, 1] = -t1 / (Le * tt2), t0 / (Le * tt2)
            om[e] = W[e, 0] * dv[0, 0] + W[e, 1] * dv[0, 1]
        # link gradients G_i, assembled +G on pin e, -G on pin e+1 (2.8)
        a = 2.0 * ft / (l * Le)
        b = sg * fs / (l * Le)
        g00 = f[0] * t0 - a * du[1, 1] + b * s10
        g01 = f[0] * t1 + a * du[1, 0] + b * s11
        for i in range(1, 4):
            g00 += f[i] * du[i, 0] / Le
            g01 += f[i] * du[i, 1] / Le
        Qu[0, e, 0] += g00
        Qu[0, e, 1] += g01
        Qu[0, e1, 0] -= g00
        Qu[0, e1, 1] -= g01
        tw = 2.0 * ft / l
        g10, g11 = f[1] * t0 + tw * t1, f[1] * t1 - tw * t0
        sh = sg * fs / l
        Qu[1, e, 0] += g10 - sh * t0
        Qu[1, e, 1] += g11 - sh * t1
        Qu[1, e1, 0] -= g10 + sh * t0
        Qu[1, e1, 1] -= g11 + sh * t1
        for i in range(2, 4):
            Qu[i, e, 0] += f[i] * t0
            Qu[i, e, 1] += f[i] * t1
            Qu[i, e1, 0] -= f[i] * t0
            Qu[i, e1, 1] -= f[i] * t1
        gw = sg * fs / Le
        Qw[0, e] += gw
        Qw[0, e1] -= gw
    # ---- pins: axial (1.136), bending (1.137) with the bisector axes (1.103), damping (1.158)-(1.159)
    daxes = np.zeros((n, 2))
    tq = np.zeros(n)
    for p in range(n):
        pm = (p - 1) % n
        x0, x1 = wt[pm, 0] + wt[p, 0], wt[pm, 1] + wt[p, 1]
        r = np.sqrt(x0 * x0 + x1 * x1)
        ta0, ta1 = x0 / r, x1 / r
        n0, n1 = -ta1, ta0
        if elastic:
            Qw[1, p] -= 2.0 * c_pin[p] * (2.0 * w[1, p] - l)
            m20 = (4.0 * u[2, p, 0] + 2.0 * u[3, p, 0]) / l
            m21 = (4.0 * u[2, p, 1] + 2.0 * u[3, p, 1]) / l
            m30 = (2.0 * u[2, p, 0] + 4.0 * u[3, p, 0]) / l
            m31 = (2.0 * u[2, p, 1] + 4.0 * u[3, p, 1]) / l
            at2, an2 = A_tau * (ta0 * m20 + ta1 * m21), A_n * (n0 * m20 + n1 * m21)
            at3, an3 = A_tau * (ta0 * m30 + ta1 * m31), A_n * (n0 * m30 + n1 * m31)
            Qu[2, p, 0] -= at2 * ta0 + an2 * n0
            Qu[2, p, 1] -= at2 * ta1 + an2 * n1
            Qu[3, p, 0] -= at3 * ta0 + an3 * n0
            Qu[3, p, 1] -= at3 * ta1 + an3 * n1
            sv = (A_tau - A_n) / r * ((n0 * u[2, p, 0] + n1 * u[2, p, 1]) * (ta0 * m20 + ta1 * m21)
                                      + (n0 * u[3, p, 0] + n1 * u[3, p, 1]) * (ta0 * m30 + ta1 * m31))
            daxes[p, 0] += sv * n0
            daxes[p, 1] += sv * n1
        if damped:
            Qw[1, p] -= 4.0 * b_pin[p] * vw[1, p]
            if beta_bend != 0.0:
                omega = (n0 * (wtd[pm, 0] + wtd[p, 0]) + n1 * (wtd[pm, 1] + wtd[p, 1])) / r
                a20, a21 = vu[2, p, 0] + omega * u[2, p, 1], vu[2, p, 1] - omega * u[2, p, 0]
                a30, a31 = vu[3, p, 0] + omega * u[3, p, 1], vu[3, p, 1] - omega * u[3, p, 0]
                m20, m21 = (4.0 * a20 + 2.0 * a30) / l, (4.0 * a21 + 2.0 * a31) / l
                m30, m31 = (2.0 * a20 + 4.0 * a30) / l, (2.0 * a21 + 4.0 * a31) / l
                at2, an2 = A_tau * (ta0 * m20 + ta1 * m21), A_n * (n0 * m20 + n1 * m21)
                at3, an3 = A_tau * (ta0 * m30 + ta1 * m31), A_n * (n0 * m30 + n1 * m31)
                b20, b21 = at2 * ta0 + an2 * n0, at2 * ta1 + an2 * n1
                b30, b31 = at3 * ta0 + an3 * n0, at3 * ta1 + an3 * n1
                Qu[2, p, 0] -= beta_bend * b20
                Qu[2, p, 1] -= beta_bend * b21
                Qu[3, p, 0] -= beta_bend * b30
                Qu[3, p, 1] -= beta_bend * b31
                # w_p of (1.167): (k x u_i) . b_i with k x u = (-u_y, u_x)
                sw = -beta_bend / r * (-u[2, p, 1] * b20 + u[2, p, 0] * b21 - u[3, p, 1] * b30 + u[3, p, 0] * b31)
                daxes[p, 0] += sw * n0
                daxes[p, 1] += sw * n1
            tq[p] = b_joint[p] * (om[p] - om[pm])
    # ---- scatter of the axis-rotation terms (stencil of (1.162)) and the joint damping (2.8)
    for p in range(n):
        pm, pp = (p - 1) % n, (p + 1) % n
        g, gm = weight[p] / L[p], weight[pm] / L[pm]
        for c in range(2):
            Qu[0, p, c] += g * daxes[pp, c] + (g - gm) * daxes[p, c] - gm * daxes[pm, c]
            if damped:
                if exact_joint:
                    G = (tq[p] - tq[pp]) * W[p, c]
                    Qu[0, p, c] += G
                    Qu[0, pp, c] -= G
                else:
                    Qu[0, p, c] += tq[p] * (W[p, c] + W[pm, c])
    return Qu, Qw
