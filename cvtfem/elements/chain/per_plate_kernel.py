"""Compiled per-plate force Jacobians (numba) of models A3/A4, summed per link.

The numpy functions :func:`.plates.strain_hessians` and :func:`.plates.force_jacobians` are the reference
twin: :func:`plate_jacobians_kernel` computes, plate by plate, the strain gradient ``J`` (the compiled
``plates_kernel._strains``), the state and its Jacobian ``A`` (``plates_kernel._plate_law``: A4, or the
clamped plate of A3), the strain Hessians and ``dQ/dq``, ``dQ/dqdot`` within the current state with the same
formulas, and adds them into the blocks of the plate's link (``tests/machines/test_free_chain.py``
holds the two equal).
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.plates_kernel import _plate_law, _strain_rates, _strains
from cvtfem.elements.jit import njit


@njit(cache=True)
def _hessians(xi, l, Lt, tau, e, psi1, psi2, H, Hp, Heps, B, BtP, Tt, bt, be):
    """``Heps`` (3, 20, 20) = d^2 (psi_1, psi_2, Delta) / dq^2 of one plate (:func:`.plates.strain_hessians`):
    ``HD = B^T P B / L~``, ``H_a = -(psi_a HD + B^T tau (B^T e_a)^T + B^T e_a (B^T tau)^T) / L~ + X_a + X_a^T``
    with ``X_a = B^T P_perp T_a / L~``, ``P = E - tau tau``.  ``tau`` (3,), ``e`` (2, 3) from ``_strains``;
    the rest is scratch.
    """
    B[:, :] = 0.0
    Tt[:, :, :] = 0.0
    for i in range(4):
        for x in range(2):
            B[x, 2 * i + x] = -H[i]
            B[x, 10 + 2 * i + x] = H[i]
            Tt[0, x, 2 * i + x] = 2.0 / l * Hp[i]
            Tt[1, x, 10 + 2 * i + x] = 2.0 / l * Hp[i]
    B[2, 8], B[2, 9], B[2, 18], B[2, 19] = -1.0, -xi, 1.0, xi
    for j in range(20):
        for k in range(3):
            s = 0.0
            for m in range(3):
                s += B[m, j] * ((1.0 if m == k else 0.0) - tau[m] * tau[k])
            BtP[j, k] = s / Lt
        bt[j] = B[0, j] * tau[0] + B[1, j] * tau[1] + B[2, j] * tau[2]
        for a in range(2):
            be[a, j] = B[0, j] * e[a, 0] + B[1, j] * e[a, 1] + B[2, j] * e[a, 2]
    for i in range(20):
        for j in range(20):
            Heps[2, i, j] = BtP[i, 0] * B[0, j] + BtP[i, 1] * B[1, j] + BtP[i, 2] * B[2, j]
    for a in range(2):
        psi = psi1 if a == 0 else psi2
        for i in range(20):
            for j in range(20):
                mixed = (BtP[i, 0] * Tt[a, 0, j] + BtP[i, 1] * Tt[a, 1, j]
                         + BtP[j, 0] * Tt[a, 0, i] + BtP[j, 1] * Tt[a, 1, i])
                Heps[a, i, j] = -(psi * Heps[2, i, j] + bt[i] * be[a, j] + be[a, i] * bt[j]) / Lt + mixed


@njit(cache=True)
def plate_jacobians_kernel(q, qdot, link, xi, l, L, c, c1, c2, h, beta_ext, beta_shear, model, dQdq, dQdv):
    """Add ``dQ/dq`` and ``dQ/dqdot`` (20 x 20 per plate, layout of ``plates.N_LOCAL``) of n plates into the
    blocks ``dQdq``, ``dQdv`` (n_links, 20, 20) of their links ``link`` (n,); arguments as
    ``plates_kernel.plate_forces_kernel`` (``model`` A4, A3_DROP or A3_KEEP).  Within the current states."""
    J, A, AJ, AH = np.zeros((3, 20)), np.zeros((3, 3)), np.zeros((3, 20)), np.zeros((3, 20))
    H, Hp, V, t, e = np.zeros(4), np.zeros(4), np.zeros(3), np.zeros((2, 3)), np.zeros((2, 3))
    m, ed, r, g = np.zeros(10), np.zeros(3), np.zeros(3), np.zeros(3)
    Heps, Hq = np.zeros((3, 20, 20)), np.zeros((3, 20))
    B, BtP, Tt, bt, be = np.zeros((3, 20)), np.zeros((20, 3)), np.zeros((2, 2, 20)), np.zeros(20), np.zeros((2, 20))
    K, D = np.zeros((3, 3)), np.zeros((3, 3))
    for p in range(q.shape[0]):
        psi1, psi2, Delta = _strains(q[p], xi[p], l[p], L[p], J, H, Hp, V, t, e)   # V becomes tau
        st, d1, d2, tension = _plate_law(model, psi1, psi2, Delta, c[p], c1[p], c2[p], h[p], A, m)
        z1, z2 = psi1 - d1, psi2 - d2
        K[:, :] = 0.0
        K[0, 0], K[0, 1], K[1, 0], K[1, 1], K[2, 2] = c1[p], c2[p], c2[p], c1[p], c[p]
        for i in range(3):
            sc = beta_shear if i < 2 else beta_ext
            for j in range(3):
                D[i, j] = sc * K[i, j]
        # g = -A^T (stress + D A epsdot): generalized forces on the strains (plates.strain_forces)
        _strain_rates(J, qdot[p], A, ed, r)
        s0 = c1[p] * z1 + c2[p] * z2 + D[0, 0] * r[0] + D[0, 1] * r[1]
        s1 = c2[p] * z1 + c1[p] * z2 + D[1, 0] * r[0] + D[1, 1] * r[1]
        s2 = tension + D[2, 2] * r[2]
        for i in range(3):
            g[i] = -(A[0, i] * s0 + A[1, i] * s1 + A[2, i] * s2)
        _hessians(xi[p], l[p], Delta + L[p], V, e, psi1, psi2, H, Hp, Heps, B, BtP, Tt, bt, be)
        for s in range(3):
            for i in range(20):
                acc = 0.0
                for j in range(20):
                    acc += Heps[s, i, j] * qdot[p, j]
                Hq[s, i] = acc
        for i in range(3):
            for j in range(20):
                AJ[i, j] = A[i, 0] * J[0, j] + A[i, 1] * J[1, j] + A[i, 2] * J[2, j]
                AH[i, j] = A[i, 0] * Hq[0, j] + A[i, 1] * Hq[1, j] + A[i, 2] * Hq[2, j]
        e_ = link[p]
        for i in range(20):
            for j in range(20):
                kq, kv, kd = 0.0, 0.0, 0.0
                for a in range(3):
                    for b in range(3):
                        kq += AJ[a, i] * K[a, b] * AJ[b, j]
                        kv += AJ[a, i] * D[a, b] * AJ[b, j]
                        kd += AJ[a, i] * D[a, b] * AH[b, j]
                dQdq[e_, i, j] += g[0] * Heps[0, i, j] + g[1] * Heps[1, i, j] + g[2] * Heps[2, i, j] - kq - kd
                dQdv[e_, i, j] -= kv
