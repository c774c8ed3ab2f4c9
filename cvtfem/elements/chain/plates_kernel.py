"""Compiled per-plate forces (numba) of models A3/A4: strains, state, tension, moments and forces in one loop.

The numpy functions of :mod:`cvtfem.elements.chain.plates` are the reference twin:
:func:`plate_forces_kernel` computes, plate by plate, what ``plate_strains`` -> ``plate_state`` (or
``clamped_plate_state``) -> ``plate_forces`` compute with arrays (same formulas, same state choice:
the largest existence margin, the lower state on ties), only without numpy's per-call overhead on
arrays of a thousand plates (``tests/elements/chain/test_plates_kernel.py`` checks them against each
other).  Without numba (``HAVE_NUMBA`` false) the kernel runs as plain Python.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.jit import HAVE_NUMBA, njit

#: Plate models of :func:`plate_forces_kernel`: A4 (bounded moment), A3 dropping compressed plates, A3 keeping them.
A4, A3_DROP, A3_KEEP = 0, 1, 2


@njit(cache=True)
def _strains(q, xi, l, L, J, H, Hp, V, t, e):
    """``(psi_1, psi_2, Delta)`` of one plate; fills ``J`` (3, 20) = d eps / dq (1.186)-(1.189), (1.209).

    ``H``, ``Hp`` (4,), ``V`` (3,), ``t``, ``e`` (2, 3) are scratch arrays.
    """
    l8 = l / 8.0
    H[0], H[1], H[2], H[3] = 1.0, xi, l8 * (1 - xi) ** 2 * (1 + xi), l8 * (xi - 1) * (1 + xi) ** 2
    Hp[0], Hp[1], Hp[2], Hp[3] = 0.0, 1.0, l8 * (3 * xi * xi - 2 * xi - 1), l8 * (3 * xi * xi + 2 * xi - 1)
    V[:] = 0.0
    t[:, :] = 0.0
    for i in range(4):
        for x in range(2):
            V[x] += H[i] * (q[10 + 2 * i + x] - q[2 * i + x])
            t[0, x] += 2.0 / l * Hp[i] * q[2 * i + x]
            t[1, x] += 2.0 / l * Hp[i] * q[10 + 2 * i + x]
    V[2] = q[18] - q[8] + xi * (q[19] - q[9])
    t[0, 2] = 1.0
    t[1, 2] = 1.0
    Lt = np.sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2])
    tau = V
    for x in range(3):
        tau[x] = V[x] / Lt
    psi1 = tau[0] * t[0, 0] + tau[1] * t[0, 1] + tau[2]
    psi2 = tau[0] * t[1, 0] + tau[1] * t[1, 1] + tau[2]
    for x in range(3):
        e[0, x] = (t[0, x] - tau[x] * psi1) / Lt
        e[1, x] = (t[1, x] - tau[x] * psi2) / Lt
    for b in range(2):
        off = 10 * b
        sg = 2.0 * b - 1.0
        for i in range(4):
            for x in range(2):
                for a in range(2):
                    J[a, off + 2 * i + x] = sg * H[i] * e[a, x] + (2.0 / l * Hp[i] * tau[x] if a == b else 0.0)
                J[2, off + 2 * i + x] = sg * H[i] * tau[x]
        for a in range(2):
            J[a, off + 8] = sg * e[a, 2]
            J[a, off + 9] = sg * xi * e[a, 2]
        J[2, off + 8] = sg * tau[2]
        J[2, off + 9] = sg * xi * tau[2]
    return psi1, psi2, Lt - L


@njit(cache=True)
def _strain_rates(J, qdot, A, ed, r):
    """Strain rates ``ed = J qdot`` of one plate and their state projection ``r = A ed`` (written in place)."""
    for i in range(3):
        ed[i] = 0.0
        for j in range(20):
            ed[i] += J[i, j] * qdot[j]
    for i in range(3):
        r[i] = A[i, 0] * ed[0] + A[i, 1] * ed[1] + A[i, 2] * ed[2]


@njit(cache=True, inline="always")
def _taut(psi1, psi2, Delta, c, c1, c2, h):
    """Whether an A4 plate is in the taut state 1, proven from a bound of the other margins of :func:`_state`
    (False: undecided).  Each margin of the states 2..10 is at most one of ``|M01| - M0``, ``|M02| - M0``,
    ``|M11| - M0``, ``|M21| - M0``, ``-M0``, in floating point too (rounding is monotone), so state 1's margin above
    them all wins, as the full selection finds."""
    c0 = h * h * c / 4.0
    M0 = h * c * Delta / 2.0
    M01, M02 = c1 * psi1 + c2 * psi2, c2 * psi1 + c1 * psi2
    M11 = (c0 + c1 + c2) * psi1 - c0 * psi2
    M21 = (c0 + c1 - c2) * psi1 + c0 * psi2
    m0 = min(M0, M0 - abs(M01), M0 - abs(M02))
    return m0 > -M0 and m0 > max(abs(M01), abs(M02), abs(M11), abs(M21)) - M0


@njit(cache=True, inline="always")
def _plate_law(model, psi1, psi2, Delta, c, c1, c2, h, A, m):
    """State, corner angles and tension (N) of one plate under ``model`` (A4: the ten-state law; A3: clamped,
    a compressed plate dropped, or kept with ``A3_KEEP``); fills the state Jacobian ``A``.  Inlined, with the taut
    state of A4 decided first (:func:`_taut`; nearly every plate of a running chain): the full selection
    :func:`_state` (its margins in ``m``) runs only where that leaves it open."""
    if model == A4 and _taut(psi1, psi2, Delta, c, c1, c2, h):
        st, d1, d2, stretch = 1, 0.0, 0.0, Delta
        A[:, :] = 0.0
        for i in range(3):
            A[i, i] = 1.0
    elif model == A4:
        st, d1, d2, stretch = _state(psi1, psi2, Delta, c, c1, c2, h, A, m)
    else:
        live = Delta > 0 or model == A3_KEEP
        st, d1, d2, stretch = (1, 0.0, 0.0, Delta) if live else (10, psi1, psi2, Delta)
        A[:, :] = 0.0
        if live:
            for i in range(3):
                A[i, i] = 1.0
    tension = c * (max(stretch, 0.0) if model != A3_KEEP else stretch)
    if st == 10:
        tension = 0.0
    return st, d1, d2, tension


@njit(cache=True)
def _state(psi1, psi2, Delta, c, c1, c2, h, A, m):
    """State 1..10, ``(delta_1, delta_2)`` and ``Delta~`` of one A4 plate (1.175)-(1.185); fills ``A`` (1.205)-(1.208).

    ``m`` (10,) is scratch for the existence margins (N m).
    """
    c0 = h * h * c / 4.0
    M0 = h * c * Delta / 2.0
    M01, M02 = c1 * psi1 + c2 * psi2, c2 * psi1 + c1 * psi2
    M11, M12 = (c0 + c1 + c2) * psi1 - c0 * psi2, -c0 * psi1 + (c0 + c1 + c2) * psi2
    M21, M22 = (c0 + c1 - c2) * psi1 + c0 * psi2, c0 * psi1 + (c0 + c1 - c2) * psi2
    k1 = c0 + c1
    Dp, Dm = 2 * c0 + c1 + c2, 2 * c0 + c1 - c2
    m[0] = min(M0, M0 - abs(M01), M0 - abs(M02))
    m[1] = min(M01 - M0, M0 - M12, M22 + M0)
    m[2] = min(-M01 - M0, M0 - M22, M12 + M0)
    m[3] = min(M02 - M0, M0 - M11, M21 + M0)
    m[4] = min(-M02 - M0, M0 - M21, M11 + M0)
    m[5] = min(M11 - M0, M12 - M0, (c1 + c2) / Dp * (c0 * (psi1 + psi2) + M0))
    m[6] = min(-M11 - M0, -M12 - M0, (c1 + c2) / Dp * (c0 * (-psi1 - psi2) + M0))
    m[7] = min(-M21 - M0, M22 - M0, (c1 - c2) / Dm * (c0 * (-psi1 + psi2) + M0))
    m[8] = min(M21 - M0, -M22 - M0, (c1 - c2) / Dm * (c0 * (psi1 - psi2) + M0))
    m[9] = -(M0 + c0 * (abs(psi1) + abs(psi2)))
    k = 0
    for j in range(1, 10):
        if m[j] > m[k]:
            k = j
    s1, s2 = 0.0, 0.0
    d1, d2 = 0.0, 0.0
    if k == 1 or k == 2:
        s1 = 1.0 if k == 1 else -1.0
        d1 = (M01 - s1 * M0) / k1
    elif k == 3 or k == 4:
        s2 = 1.0 if k == 3 else -1.0
        d2 = (M02 - s2 * M0) / k1
    elif 5 <= k <= 8:
        s1 = 1.0 if k == 5 or k == 8 else -1.0
        s2 = 1.0 if k == 5 or k == 7 else -1.0
        if s1 * s2 > 0:
            d1, d2 = (M11 - s1 * M0) / Dp, (M12 - s2 * M0) / Dp
        else:
            d1, d2 = (M21 - s1 * M0) / Dm, (M22 - s2 * M0) / Dm
    elif k == 9:
        d1, d2 = psi1, psi2
    A[:, :] = 0.0
    if k == 0:
        for i in range(3):
            A[i, i] = 1.0
    elif k <= 2:
        A[0, 0], A[0, 1], A[0, 2] = c0 / k1, -c2 / k1, s1 * 2 / h * c0 / k1
        A[1, 1] = 1.0
        A[2, 0], A[2, 1], A[2, 2] = s1 * h / 2 * c1 / k1, s1 * h / 2 * c2 / k1, c1 / k1
    elif k <= 4:
        A[0, 0] = 1.0
        A[1, 0], A[1, 1], A[1, 2] = -c2 / k1, c0 / k1, s2 * 2 / h * c0 / k1
        A[2, 0], A[2, 1], A[2, 2] = s2 * h / 2 * c2 / k1, s2 * h / 2 * c1 / k1, c1 / k1
    elif k <= 8:
        ss = s1 * s2
        D = 2 * c0 + c1 + ss * c2
        A[0, 0], A[0, 1], A[0, 2] = c0 / D, ss * c0 / D, s1 * 2 / h * c0 / D
        A[1, 0], A[1, 1], A[1, 2] = ss * c0 / D, c0 / D, s2 * 2 / h * c0 / D
        A[2, 0] = h / 2 * (s1 * c1 + s2 * c2) / D
        A[2, 1] = h / 2 * (s2 * c1 + s1 * c2) / D
        A[2, 2] = (c1 + ss * c2) / D
    if k == 9:
        s1, s2 = np.sign(psi1), np.sign(psi2)
    return k + 1, d1, d2, Delta + h / 2 * (s1 * d1 + s2 * d2)


@njit(cache=True)
def plate_forces_kernel(q, qdot, xi, l, L, c, c1, c2, h, beta_ext, beta_shear, model, Q, T, M, state):
    """Forces ``Q`` (n, 20) of n plates with their tension ``T`` (n,), end moments ``M`` (n, 2), state (n,).

    ``q``, ``qdot`` (n, 20) local coordinates and velocities (layout of ``plates.N_LOCAL``); ``xi``, ``l``,
    ``L``, ``c``, ``c1``, ``c2``, ``h`` per plate (n,); damping times ``beta_ext``, ``beta_shear`` (s);
    ``model`` one of :data:`A4`, :data:`A3_DROP`, :data:`A3_KEEP`.  Outputs are written in place.
    """
    J, A = np.zeros((3, 20)), np.zeros((3, 3))
    H, Hp, V, t, e = np.zeros(4), np.zeros(4), np.zeros(3), np.zeros((2, 3)), np.zeros((2, 3))
    ed, r, stress, m = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(10)
    for p in range(q.shape[0]):
        psi1, psi2, Delta = _strains(q[p], xi[p], l[p], L[p], J, H, Hp, V, t, e)
        st, d1, d2, tension = _plate_law(model, psi1, psi2, Delta, c[p], c1[p], c2[p], h[p], A, m)
        z1, z2 = psi1 - d1, psi2 - d2
        M1, M2 = c1[p] * z1 + c2[p] * z2, c2[p] * z1 + c1[p] * z2
        _strain_rates(J, qdot[p], A, ed, r)
        stress[0] = M1 + beta_shear * (c1[p] * r[0] + c2[p] * r[1])
        stress[1] = M2 + beta_shear * (c2[p] * r[0] + c1[p] * r[1])
        stress[2] = tension + beta_ext * c[p] * r[2]
        g0 = -(A[0, 0] * stress[0] + A[1, 0] * stress[1] + A[2, 0] * stress[2])
        g1 = -(A[0, 1] * stress[0] + A[1, 1] * stress[1] + A[2, 1] * stress[2])
        g2 = -(A[0, 2] * stress[0] + A[1, 2] * stress[1] + A[2, 2] * stress[2])
        for j in range(20):
            Q[p, j] = J[0, j] * g0 + J[1, j] * g1 + J[2, j] * g2
        T[p] = tension
        M[p, 0], M[p, 1] = M1, M2
        state[p] = st
