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

from cvtfem.elements.chain.plates_kernel import A4, _plate_law
from cvtfem.elements.contact.kernels import LAW_CODES, _gain
from cvtfem.elements.jit import HAVE_NUMBA, njit

#: ``friction_gain``'s default blend width of the ``smooth`` law, as the numpy twin calls it.
SMOOTH_EPS = 0.1
#: How :func:`jacobian` takes the links' coordinate blocks: forward or central differences, or exact (within states).
FORWARD, CENTRAL, ANALYTIC = 0, 1, 2
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
    """Scratch arrays of :func:`_link`: shape values per plate end ``Hm (2, 3, 4)``, virtual end values ``ve (2, 12)``,
    strain gradients ``te (3, 3)``, state Jacobian, margins, rates, twist map, ``A J G`` rows, the stations, the plate's
    strain forces and state (:func:`_plate`); the last accumulates
    the power of the link damping forces (W)."""
    return (np.zeros((2, 3, 4)), np.zeros((2, 12)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(10), np.zeros(3),
            np.zeros(22), np.zeros((3, 22)), np.zeros(2), np.zeros(9), np.zeros(1))


@njit(cache=True)
def _virtual_end(x, xd, b, d, l, Hm, ve):
    """End ``b`` of a plate at offset ``d`` as a virtual whole pin at ``xi = 0`` (1.211)-(1.212): ``Hm[b]`` gets
    ``h, h', h''`` at ``xi_b``, ``ve[b]`` the pin's ``u_0 = U_perp(xi_b)`` (0, 1), ``u_1 = dU_perp/dxi`` (2, 3),
    ``w_0 = U_par(xi_b)`` (4), their rates (5..9) and ``d u_1/dxi`` (10, 11) (``u_2 = u_3 = 0``, ``w_1`` the half's:
    the same strains as the half's axis).  Returns ``xi_b``."""
    o = 10 * b
    xi = 2.0 / l * (x[20 + b] - x[o + 8] + d)
    xid = 2.0 / l * (xd[20 + b] - xd[o + 8])
    _shape(xi, l, Hm[b, 0], Hm[b, 1], Hm[b, 2])
    for c in range(2):
        U, u1, du1, Ud, u1d = 0.0, 0.0, 0.0, 0.0, 0.0
        for i in range(4):
            y, yd = x[o + 2 * i + c], xd[o + 2 * i + c]
            U += Hm[b, 0, i] * y
            u1 += Hm[b, 1, i] * y
            du1 += Hm[b, 2, i] * y
            Ud += Hm[b, 0, i] * yd
            u1d += Hm[b, 1, i] * yd
        ve[b, c], ve[b, 2 + c], ve[b, 10 + c] = U, u1, du1
        ve[b, 5 + c], ve[b, 7 + c] = Ud + u1 * xid, u1d + du1 * xid
    ve[b, 4] = x[o + 8] + x[o + 9] * xi
    ve[b, 9] = xd[o + 8] + xd[o + 9] * xi + x[o + 9] * xid
    return xi


@njit(cache=True)
def _end_strains(ve, l, L, te):
    """``(psi_1, psi_2, Delta)`` of a plate between its virtual end pins ``ve`` (the strains (1.186)-(1.189) at
    ``xi = 0``, ``u_2 = u_3 = 0``: ``V = u_0+ - u_0-``, ``t_a = (2/l u_1, 1)``) and their gradients over ``V``
    into ``te`` (3, 3): ``tau`` (of ``Delta``), ``e_1``, ``e_2`` (of ``psi_a``); ``psi_a`` also moves with end
    ``a``'s ``u_1`` as ``2/l tau``."""
    V0, V1, V2 = ve[1, 0] - ve[0, 0], ve[1, 1] - ve[0, 1], ve[1, 4] - ve[0, 4]
    Lt = np.sqrt(V0 * V0 + V1 * V1 + V2 * V2)
    il = 1.0 / Lt
    t0, t1, t2 = V0 * il, V1 * il, V2 * il
    te[0, 0], te[0, 1], te[0, 2] = t0, t1, t2
    k = 2.0 / l
    psi1 = k * (t0 * ve[0, 2] + t1 * ve[0, 3]) + t2
    psi2 = k * (t0 * ve[1, 2] + t1 * ve[1, 3]) + t2
    for a in range(2):
        psi = psi1 if a == 0 else psi2
        te[1 + a, 0] = (k * ve[a, 2] - t0 * psi) * il
        te[1 + a, 1] = (k * ve[a, 3] - t1 * psi) * il
        te[1 + a, 2] = (1.0 - t2 * psi) * il
    return psi1, psi2, Lt - L


@njit(cache=True)
def _end_rates(ve, l, te, ed):
    """Strain rates ``ed`` (3,) of a plate from its virtual end rates (``J qvd`` over the nonzero columns)."""
    d0, d1, d2 = ve[1, 5] - ve[0, 5], ve[1, 6] - ve[0, 6], ve[1, 9] - ve[0, 9]
    k = 2.0 / l
    for a in range(2):
        ed[a] = (te[1 + a, 0] * d0 + te[1 + a, 1] * d1 + te[1 + a, 2] * d2
                 + k * (te[0, 0] * ve[a, 7] + te[0, 1] * ve[a, 8]))
    ed[2] = te[0, 0] * d0 + te[0, 1] * d1 + te[0, 2] * d2


@njit(cache=True)
def _to_link(out, g0, g1, g2, x, xis, Hm, ve, te, l):
    """Add ``G^T J^T g`` to ``out`` (22,): a generalized force ``g`` on a plate's strains ``(psi_1, psi_2, Delta)``
    through the strain gradients ``J`` (nonzero on the virtual pins' ``u_0``, ``u_1``, ``w_0`` only) and the
    transpose of the virtual-end map (its stations ``xi_b`` moving with ``q`` and ``w_0``)."""
    k = 2.0 / l
    F0 = g0 * te[1, 0] + g1 * te[2, 0] + g2 * te[0, 0]
    F1 = g0 * te[1, 1] + g1 * te[2, 1] + g2 * te[0, 1]
    F2 = g0 * te[1, 2] + g1 * te[2, 2] + g2 * te[0, 2]
    for b in range(2):
        o = 10 * b
        sg = 2.0 * b - 1.0
        gb = k * (g0 if b == 0 else g1)
        fu0, fu1, fw = sg * F0, sg * F1, sg * F2                  # on u_0 (2), w_0 of the virtual pin
        fv0, fv1 = gb * te[0, 0], gb * te[0, 1]                   # on u_1
        for i in range(4):
            out[o + 2 * i] += Hm[b, 0, i] * fu0 + Hm[b, 1, i] * fv0
            out[o + 2 * i + 1] += Hm[b, 0, i] * fu1 + Hm[b, 1, i] * fv1
        S = fw * x[o + 9] + fu0 * ve[b, 2] + fu1 * ve[b, 3] + fv0 * ve[b, 10] + fv1 * ve[b, 11]
        out[o + 8] += fw - k * S
        out[o + 9] += fw * xis[b]
        out[20 + b] += k * S


@njit(cache=True)
def _near_kink(kmodel, st, Delta, m, c, c1, c2, h_pl, l, rel):
    """Whether a plate's law may switch within a difference step ``rel l`` of its link's coordinates: its best state
    margin (A4, N m) leads the next one, or (A3) its strain ``Delta`` sits, by less than ten times what such a step
    changes them."""
    c0 = h_pl * h_pl * c / 4.0
    dM = rel * (c * h_pl * l / 2.0 + 2.0 * (c0 + c1 + abs(c2)))
    if kmodel != A4:
        return abs(Delta) * c * h_pl / 2.0 < 10.0 * dM
    k = st - 1
    second = -np.inf
    for j in range(10):
        if j != k and m[j] > second:
            second = m[j]
    return m[k] - second < 10.0 * dM


@njit(cache=True)
def _twist(x, xd, e, L, c_twist, par, Jp, M):
    """Twist (1.146), (1.217) of link ``e``: ``Jp`` (22,) gets ``d phi / dx`` and, with ``M`` of shape (22, 22), that
    constant matrix ``d^2 phi / dx^2`` (``phi`` is a quadratic form of the cross-half differences).  Returns
    ``(f, phi', power)``: the twist moment (elastic and damping, the forces are ``-f Jp``), the twist rate and the
    power of the damping (W)."""
    l, beta_twist = par[0], par[8]
    kk = 2.0 / (l * L[e])
    d00, d01, d10, d11 = x[10] - x[0], x[11] - x[1], x[12] - x[2], x[13] - x[3]
    phi = kk * (d10 * d01 - d11 * d00)
    Jp[:] = 0.0
    Jp[10], Jp[11], Jp[12], Jp[13] = -kk * d11, kk * d10, kk * d01, -kk * d00
    for j in range(4):
        Jp[j] = -Jp[10 + j]
    if M.shape[0] == 22:                                          # Jp = M x: the entries of that linear map
        M[:, :] = 0.0
        for a, b, s in ((2, 1, 1.0), (3, 0, -1.0)):               # d_ab pairs (d10 d01 - d11 d00)
            for i in (a, 10 + a):
                for j in (b, 10 + b):
                    sg = s * kk * (1.0 if (i < 10) == (j < 10) else -1.0)
                    M[i, j] += sg
                    M[j, i] += sg
    phid = 0.0
    for j in range(22):
        phid += Jp[j] * xd[j]
    f = c_twist[e] * (phi + beta_twist * phid)
    return f, phid, -beta_twist * c_twist[e] * phid * phid


@njit(cache=True)
def _keep(K):
    """Per-plate store of :func:`_link` for K plates (0: none): shape values, virtual ends, strain gradients, state
    Jacobian, strain forces (the ``gr`` of :func:`_link`) and stations."""
    return (np.zeros((K, 2, 3, 4)), np.zeros((K, 2, 12)), np.zeros((K, 3, 3)), np.zeros((K, 3, 3)), np.zeros((K, 9)),
            np.zeros((K, 2)))


@njit(cache=True)
def _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, loc, Dv, want_dv, wk,
          keep):
    """Plates (per-plate law, elastic plus damping) and twist (1.146), (1.217) of link ``e`` on its 22 local
    coordinates ``x`` (half ``-`` of pin ``e``, half ``+`` of pin ``e+1``, ``q_e``, ``q_{e+1}``; layout of
    ``ChainA5._links``) and velocities ``xd``.  Adds the forces to ``loc`` (22,) and, with ``want_dv``,
    their exact velocity derivative (they are linear in ``xd``) to ``Dv`` (22, 22; symmetric, the upper triangle
    overwritten).  Returns the link tension (N).

    Per plate ``gr`` (9,) holds the generalized forces on its strains ``g = -A^T (stress + D A epsdot)`` (times the
    plate weight), the state-projected strain rates ``r = A epsdot``, the power of its damping forces (W), the
    state (1..10) and whether it is slack within a difference step of tension (:func:`_near_kink`); a ``keep`` of
    :func:`_keep` with room for the link's plates stores them with the plate's geometry for :func:`_link_jacobian`.
    """
    Hm, ve, te, A, m, ed, Jp, AJG, xis, gr, pw_ = wk
    kHm, kve, kte, kA, kgr, kxis = keep
    l, beta_ext, beta_shear, beta_twist, h_pl = par[0], par[6], par[7], par[8], par[15]
    Le = L[e]
    T = 0.0
    for k in range(plate_w.shape[1]):
        pw = plate_w[e, k]
        if pw == 0.0:
            continue
        xis[0] = _virtual_end(x, xd, 0, plate_d[e, k], l, Hm, ve)
        xis[1] = _virtual_end(x, xd, 1, plate_d[e, k], l, Hm, ve)
        c, c1, c2 = plate_c[e, k], plate_c1[e, k], plate_c2[e, k]
        psi1, psi2, Delta = _end_strains(ve, l, Le, te)
        st, d1, d2, tension = _plate_law(kmodel, psi1, psi2, Delta, c, c1, c2, h_pl, A, m)
        z1, z2 = psi1 - d1, psi2 - d2
        _end_rates(ve, l, te, ed)
        r0 = A[0, 0] * ed[0] + A[0, 1] * ed[1] + A[0, 2] * ed[2]
        r1 = A[1, 0] * ed[0] + A[1, 1] * ed[1] + A[1, 2] * ed[2]
        r2 = A[2, 0] * ed[0] + A[2, 1] * ed[1] + A[2, 2] * ed[2]
        s0 = c1 * z1 + c2 * z2 + beta_shear * (c1 * r0 + c2 * r1)
        s1 = c2 * z1 + c1 * z2 + beta_shear * (c2 * r0 + c1 * r1)
        s2 = tension + beta_ext * c * r2
        g0 = -(A[0, 0] * s0 + A[1, 0] * s1 + A[2, 0] * s2) * pw
        g1 = -(A[0, 1] * s0 + A[1, 1] * s1 + A[2, 1] * s2) * pw
        g2 = -(A[0, 2] * s0 + A[1, 2] * s1 + A[2, 2] * s2) * pw
        p = -pw * (beta_shear * (r0 * (c1 * r0 + c2 * r1) + r1 * (c2 * r0 + c1 * r1)) + beta_ext * c * r2 * r2)
        pw_[0] += p
        T += tension * pw
        _to_link(loc, g0, g1, g2, x, xis, Hm, ve, te, l)
        if kgr.shape[0] > 0:
            gr[0], gr[1], gr[2], gr[3], gr[4], gr[5], gr[6], gr[7] = g0, g1, g2, r0, r1, r2, p, st
            gr[8] = st == 10 and _near_kink(kmodel, st, Delta, m, c, c1, c2, h_pl, l, 1e-7)
            kHm[k], kve[k], kte[k], kA[k], kgr[k], kxis[k] = Hm, ve, te, A, gr, xis
        if want_dv:                                               # -(A J G)^T D (A J G), D of (1.192)-(1.193)
            for i in range(3):
                AJG[i, :] = 0.0
                _to_link(AJG[i], A[i, 0], A[i, 1], A[i, 2], x, xis, Hm, ve, te, l)
            for a in range(22):                                   # lower triangle; symmetric
                da0 = pw * beta_shear * (c1 * AJG[0, a] + c2 * AJG[1, a])
                da1 = pw * beta_shear * (c2 * AJG[0, a] + c1 * AJG[1, a])
                da2 = pw * beta_ext * c * AJG[2, a]
                for b in range(a, 22):
                    Dv[b, a] -= AJG[0, b] * da0 + AJG[1, b] * da1 + AJG[2, b] * da2
    if c_twist[e] != 0.0:
        f, phid, pt = _twist(x, xd, e, L, c_twist, par, Jp, AJG[:1, :1])
        pw_[0] += pt
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


@njit(cache=True)
def _jac_work():
    """Scratch of :func:`_link_jacobian`: ``Rx`` (7, 22) the gradients of the reduced variables ``R = (V (3), u_1 of
    end 0 (2), of end 1 (2))`` of a plate, ``Rd`` (7,) their rates, ``dRd`` (7, 22) ``d R' / dx``, ``Jr`` (3, 7) the
    strain gradients over ``R``, ``Mm`` (7, 7), ``W`` (3, 22), ``AJG`` (3, 22), ``MR`` (7, 22), ``Mt`` (22, 22)."""
    return (np.zeros((7, 22)), np.zeros(7), np.zeros((7, 22)), np.zeros((3, 7)), np.zeros((7, 7)), np.zeros((3, 22)),
            np.zeros((3, 22)), np.zeros((7, 22)), np.zeros((22, 22)))


@njit(cache=True)
def _reduced(x, xd, xis, Hm, ve, l, Rx, Rd, dRd):
    """Gradients ``Rx`` of a plate's reduced variables ``R = (V, u_1^0, u_1^1)`` over the link's 22 coordinates (the
    virtual-end map (1.211)-(1.212) with its moving stations ``xi_b``), their rates ``Rd = Rx x'`` and
    ``dRd = d(Rx x')/dx``."""
    k = 2.0 / l
    l6 = 6.0 * l / 8.0                                            # h_i''' of i = 2, 3
    Rx[:, :] = 0.0
    dRd[:, :] = 0.0
    for b in range(2):
        o = 10 * b
        sg = 2.0 * b - 1.0
        xid = k * (xd[20 + b] - xd[o + 8])
        cb, co = 20 + b, o + 8                                    # d xi_b / dx = k (e_cb - e_co)
        for c in range(2):
            u1, du1 = ve[b, 2 + c], ve[b, 10 + c]
            d3u = l6 * (x[o + 4 + c] + x[o + 6 + c])
            u1d_raw, du1d_raw = 0.0, 0.0
            ru, r1 = c, 3 + 2 * b + c
            for i in range(4):
                col = o + 2 * i + c
                Rx[ru, col] += sg * Hm[b, 0, i]
                Rx[r1, col] += Hm[b, 1, i]
                u1d_raw += Hm[b, 1, i] * xd[col]
                du1d_raw += Hm[b, 2, i] * xd[col]
                dRd[ru, col] += sg * xid * Hm[b, 1, i]
                dRd[r1, col] += xid * Hm[b, 2, i]
            for cc, s in ((cb, k), (co, -k)):
                Rx[ru, cc] += sg * u1 * s
                Rx[r1, cc] += du1 * s
                dRd[ru, cc] += sg * (u1d_raw + xid * du1) * s
                dRd[r1, cc] += (du1d_raw + xid * d3u) * s
        Rx[2, o + 8] += sg
        Rx[2, o + 9] += sg * xis[b]
        Rx[2, cb] += sg * x[o + 9] * k
        Rx[2, co] -= sg * x[o + 9] * k
        dRd[2, cb] += sg * xd[o + 9] * k
        dRd[2, co] -= sg * xd[o + 9] * k
        dRd[2, o + 9] += sg * xid
    for r in range(7):
        s = 0.0
        for j in range(22):
            s += Rx[r, j] * xd[j]
        Rd[r] = s


@njit(cache=True)
def _map_curvature(Kx, F, x, Hm, ve, l):
    """Add ``sum_r F_r d^2 R_r / dx^2`` to ``Kx`` (22, 22): the curvature of the virtual-end map under the reduced
    forces ``F`` (7,) (``F = Jr^T g``: on ``V`` and the two ends' ``u_1``)."""
    k = 2.0 / l
    l6 = 6.0 * l / 8.0
    a = np.zeros(22)
    for b in range(2):
        o = 10 * b
        sg = 2.0 * b - 1.0
        a[:] = 0.0
        s = 0.0
        for c in range(2):
            fu0, fu1 = sg * F[c], F[3 + 2 * b + c]
            for i in range(4):
                a[o + 2 * i + c] += fu0 * Hm[b, 1, i] + fu1 * Hm[b, 2, i]
            s += fu0 * ve[b, 10 + c] + fu1 * l6 * (x[o + 4 + c] + x[o + 6 + c])
        a[o + 9] += sg * F[2]
        cb, co = 20 + b, o + 8
        for j in range(22):
            if a[j] != 0.0:
                Kx[j, cb] += k * a[j]
                Kx[j, co] -= k * a[j]
                Kx[cb, j] += k * a[j]
                Kx[co, j] -= k * a[j]
        kk = k * k * s
        Kx[cb, cb] += kk
        Kx[co, co] += kk
        Kx[cb, co] -= kk
        Kx[co, cb] -= kk


@njit(cache=True)
def _link_jacobian(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, loc, Kx, Dv,
                   dT, dPx, dPv, wk, jw, keep):
    """Link ``e`` as :func:`_link` (its pass, with the plates kept in ``keep``, :func:`_keep`) with its exact
    derivatives within the plates' states: adds the forces to ``loc``,
    ``dQ/dx`` to ``Kx`` and ``dQ/dx'`` to ``Dv`` (22, 22), the tension's gradient to ``dT`` and the gradients of the
    power of its damping forces (W) to ``dPx``, ``dPv`` (22,); returns ``(tension (N), power (W))``.

    Per plate with the reduced variables ``R`` of :func:`_reduced` (``eps = eps(R)``, ``Jr = d eps/dR``, the strain
    Hessians ``Hr_s`` over ``R`` of (1.186)-(1.189)): ``loc = Rx^T Jr^T g``, and
    ``dQ/dx = Rx^T (sum_s g_s Hr_s) Rx + curvature of the map (F = Jr^T g) - (A Jr Rx)^T (K A Jr Rx + D A d eps'/dx)``
    with ``d eps'/dx = (Hr . R') Rx + Jr dR'/dx``, ``K``, ``D`` the plate's stiffness and damping.  As in
    :mod:`per_plate_kernel`, the tension's stiffness ``c`` counts in every state (a slack plate, state 10, has
    ``A = 0``), so an unstretched plate in state 1 gets the one-sided stiffness into tension; a slack plate within a
    difference step of tension (:func:`_near_kink`) gets the elastic stiffness of the taut state 1 (``A = I``; its
    damping stays the slack state's, none, as in its forces): at a kink the exact blocks are one-sided, and the slack
    side has no stiffness at all (Newton from an unstretched chain stalls on it; central differences average the
    two sides)."""
    Jp, pw_ = wk[6], wk[-1]
    kHm, kve, kte, kA, kgr, kxis = keep
    Rx, Rd, dRd, Jr, Mm, W, AJG, MR, Mt = jw
    l, beta_ext, beta_shear, beta_twist = par[0], par[6], par[7], par[8]
    kl = 2.0 / l
    p0 = pw_[0]
    T = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, loc, Mt, False, wk,
              keep)
    P = pw_[0] - p0
    F, HR, AJr, AJe, AHR = np.zeros(7), np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7))
    for kp in range(plate_w.shape[1]):
        pw = plate_w[e, kp]
        if pw == 0.0:
            continue
        Hm, ve, te, A, gr, xis = kHm[kp], kve[kp], kte[kp], kA[kp], kgr[kp], kxis[kp]
        c, c1, c2 = plate_c[e, kp], plate_c1[e, kp], plate_c2[e, kp]
        taut = gr[8] != 0.0                                       # slack within a step of tension: K of state 1
        _reduced(x, xd, xis, Hm, ve, l, Rx, Rd, dRd)
        Jr[:, :] = 0.0
        for j in range(3):
            Jr[0, j], Jr[1, j], Jr[2, j] = te[1, j], te[2, j], te[0, j]
        Jr[0, 3], Jr[0, 4], Jr[1, 5], Jr[1, 6] = kl * te[0, 0], kl * te[0, 1], kl * te[0, 0], kl * te[0, 1]
        # strain Hessians over R: Delta: P/Lt; psi_a: -(psi_a P/Lt + t e_a^T + e_a t^T)/Lt, mixed k P[:, c]/Lt
        t0, t1, t2 = te[0, 0], te[0, 1], te[0, 2]
        V0, V1, V2 = ve[1, 0] - ve[0, 0], ve[1, 1] - ve[0, 1], ve[1, 4] - ve[0, 4]
        il = 1.0 / np.sqrt(V0 * V0 + V1 * V1 + V2 * V2)
        psi = (kl * (t0 * ve[0, 2] + t1 * ve[0, 3]) + t2, kl * (t0 * ve[1, 2] + t1 * ve[1, 3]) + t2)
        Mm[:, :] = 0.0
        HR[:, :] = 0.0
        for i in range(3):
            for j in range(3):
                Pij = ((1.0 if i == j else 0.0) - te[0, i] * te[0, j]) * il
                h2 = Pij
                h0 = -(psi[0] * Pij + te[0, i] * te[1, j] + te[1, i] * te[0, j]) * il
                h1 = -(psi[1] * Pij + te[0, i] * te[2, j] + te[2, i] * te[0, j]) * il
                Mm[i, j] += gr[0] * h0 + gr[1] * h1 + gr[2] * h2
                HR[0, i] += h0 * Rd[j]
                HR[1, i] += h1 * Rd[j]
                HR[2, i] += h2 * Rd[j]
            for a in range(2):
                for cc in range(2):
                    m_ = kl * ((1.0 if i == cc else 0.0) - te[0, i] * te[0, cc]) * il
                    Mm[i, 3 + 2 * a + cc] += gr[a] * m_
                    Mm[3 + 2 * a + cc, i] += gr[a] * m_
                    HR[a, i] += m_ * Rd[3 + 2 * a + cc]
                    HR[a, 3 + 2 * a + cc] += m_ * Rd[i]
        for r in range(7):
            F[r] = Jr[0, r] * gr[0] + Jr[1, r] * gr[1] + Jr[2, r] * gr[2]
        _map_curvature(Kx, F, x, Hm, ve, l)
        # A Jr (3, 7) and the stiffness/damping rows over R: -pw (A Jr)^T (K A Jr + D A HR) into Mm
        for i in range(3):
            for r in range(7):
                AJr[i, r] = A[i, 0] * Jr[0, r] + A[i, 1] * Jr[1, r] + A[i, 2] * Jr[2, r]
                AJe[i, r] = Jr[i, r] if taut else AJr[i, r]
        Kd = ((c1, c2, 0.0), (c2, c1, 0.0), (0.0, 0.0, c))
        Dd = ((beta_shear * c1, beta_shear * c2, 0.0), (beta_shear * c2, beta_shear * c1, 0.0),
              (0.0, 0.0, beta_ext * c))
        for i in range(3):
            for r in range(7):
                AHR[i, r] = A[i, 0] * HR[0, r] + A[i, 1] * HR[1, r] + A[i, 2] * HR[2, r]
        for i in range(3):
            for r in range(7):
                se, sd = 0.0, 0.0
                for jj in range(3):
                    se += Kd[i][jj] * AJe[jj, r]
                    sd += Dd[i][jj] * AHR[jj, r]
                for q in range(7):
                    Mm[q, r] -= pw * (AJe[i, q] * se + AJr[i, q] * sd)
        # Kx += Rx^T Mm Rx
        for q in range(7):
            for j in range(22):
                s = 0.0
                for r in range(7):
                    s += Mm[q, r] * Rx[r, j]
                MR[q, j] = s
        for i in range(22):
            for q in range(7):
                rq = Rx[q, i]
                if rq != 0.0:
                    for j in range(22):
                        Kx[i, j] += rq * MR[q, j]
        # AJG = A Jr Rx, W = A Jr dRd (the rate term of d eps'/dx through the map)
        for i in range(3):
            for j in range(22):
                s, w_ = 0.0, 0.0
                for r in range(7):
                    s += AJr[i, r] * Rx[r, j]
                    w_ += AJr[i, r] * dRd[r, j]
                AJG[i, j], W[i, j] = s, w_
        r0, r1, r2 = gr[3], gr[4], gr[5]
        Dr = (Dd[0][0] * r0 + Dd[0][1] * r1, Dd[1][0] * r0 + Dd[1][1] * r1, Dd[2][2] * r2)
        for j in range(22):
            h0, h1, h2 = 0.0, 0.0, 0.0                            # A (Hr . R') Rx
            for r in range(7):
                h0 += AHR[0, r] * Rx[r, j]
                h1 += AHR[1, r] * Rx[r, j]
                h2 += AHR[2, r] * Rx[r, j]
            dw0 = Dd[0][0] * W[0, j] + Dd[0][1] * W[1, j]
            dw1 = Dd[1][0] * W[0, j] + Dd[1][1] * W[1, j]
            dw2 = Dd[2][2] * W[2, j]
            da0 = Dd[0][0] * AJG[0, j] + Dd[0][1] * AJG[1, j]
            da1 = Dd[1][0] * AJG[0, j] + Dd[1][1] * AJG[1, j]
            da2 = Dd[2][2] * AJG[2, j]
            for i in range(22):
                Kx[i, j] -= pw * (AJG[0, i] * dw0 + AJG[1, i] * dw1 + AJG[2, i] * dw2)
                Dv[i, j] -= pw * (AJG[0, i] * da0 + AJG[1, i] * da1 + AJG[2, i] * da2)
            dT[j] += pw * c * AJG[2, j]
            # P = -pw r^T D r, r = A eps', d eps'/dx = HR Rx + Jr dRd
            dPv[j] -= 2 * pw * (Dr[0] * AJG[0, j] + Dr[1] * AJG[1, j] + Dr[2] * AJG[2, j])
            dPx[j] -= 2 * pw * (Dr[0] * (W[0, j] + h0) + Dr[1] * (W[1, j] + h1) + Dr[2] * (W[2, j] + h2))
    if c_twist[e] != 0.0:                                         # its forces and power came with _link's
        f, phid, _ = _twist(x, xd, e, L, c_twist, par, Jp, Mt)
        ct, bt = c_twist[e], beta_twist
        Mxd = np.zeros(22)
        for i in range(22):
            s = 0.0
            for j in range(22):
                s += Mt[i, j] * xd[j]
            Mxd[i] = s
        for i in range(22):
            for j in range(22):
                Kx[i, j] -= ct * (Jp[i] * Jp[j] + bt * Jp[i] * Mxd[j]) + f * Mt[i, j]
                Dv[i, j] -= ct * bt * Jp[i] * Jp[j]
            dPx[i] -= 2 * bt * ct * phid * Mxd[i]
            dPv[i] -= 2 * bt * ct * phid * Jp[i]
    return T, P


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
def _half_bending(x, xd, h, th, nh, thd, par, loc, Qth, nab):
    """Half bending (1.216) of half ``h`` on axes turning with its link, and its co-rotational
    damping (section 5.4); returns the power of the damping forces (W)."""
    l, A_tau, A_n, beta = par[0], par[3], par[4], par[5]
    o = 10 * h + 4                                                # u_2 of the half
    t0, t1, n0, n1 = th[h, 0], th[h, 1], nh[h, 0], nh[h, 1]
    gth = 0.0
    for k in range(2):
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
def _pin(x, xd, p, T_next, T_prev, b_joint, cs, arc, idx, sig_, cw, par, law, lateral, loc, wk):
    """Everything of pin ``p`` but its links, on 29 local coordinates ``x`` and velocities ``xd``: half ``-`` (0..9,
    A1 order), half ``+`` (10..19), ``q_p`` (20) and the ends of the links giving the half axes (1.215): start and
    end ``u_0`` of the ``-`` half's link (21..24), of the ``+`` half's link (25..28), copies allowed.  Half axial
    (1.214), half bending (1.216), the three arc contacts at two Gauss stations (penalty, roll damping, tie,
    rolling friction), stoppers, axial friction (1.221) with the link tensions ``T_next`` (link ``(p, p+1)``) and
    ``T_prev`` (``(p-1, p)``) and joint damping (1.80); half torques go to the link ends.  Adds to ``loc`` (29,);
    without ``lateral`` only the axial terms (half axial, stoppers, axial friction: all that ``w``, ``q_p`` reach).
    """
    tau, rho, thd, th, nh, Qth, H, Hp, Hpp, Ux, Vx, kA, kB, nab, Hs, CG, pw = wk
    l, c_half, b_half, b_roll, k_tie = par[0], par[1], par[2], par[9], par[10]
    k_stop, d_stop, f0, v0 = par[11], par[12], par[13], par[14]
    for h in range(2):
        o = 10 * h
        loc[o + 9] -= 2 * c_half * (2 * x[o + 9] - l) + 4 * b_half * xd[o + 9]
        pw[0] -= 4 * b_half * xd[o + 9] * xd[o + 9]
    for h in range(2):                                            # stoppers (erratum 13)
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
    _pin_geometry(x, p, cs, arc, idx, sig_, cw, par, tau, rho, th, nh, H, Hp, Hpp, Ux, Hs, CG)
    for j in range(2):                                            # spin rates of the links
        o = 21 + 4 * j
        thd[j] = (-tau[j, 1] * (xd[o + 2] - xd[o]) + tau[j, 0] * (xd[o + 3] - xd[o + 1])) / rho[j]
        Qth[j] = 0.0
    for h in range(2):
        pw[0] += _half_bending(x, xd, h, th, nh, thd, par, loc, Qth, nab)
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
            if N != 0.0:
                _pair(loc, Qth, A, B, Hst, N * sig, n0, n1, kA, kB)
            vr0, vr1 = Vx[B, 0] - Vx[A, 0], Vx[B, 1] - Vx[A, 1]
            if b_roll != 0.0 and ic == 0 and g < 0:
                gdot = sig * (n0 * vr0 + n1 * vr1 + (n0 * kB[0] + n1 * kB[1]) * thd[B]
                              - (n0 * kA[0] + n1 * kA[1]) * thd[A])
                _pair(loc, Qth, A, B, Hst, -wgt * b_roll * gdot * sig, n0, n1, kA, kB)
                pw[0] -= wgt * b_roll * gdot * gdot
            if k_tie != 0.0 and ic == 0:                          # g_t = R_A ang(n, tau_A) + R_B ang(n, tau_B)
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
def _rank1(Jl, dPl, w, nz, c, dP):
    """Add ``c w w^T`` to the local block ``Jl`` (29, 29) and ``dP w`` to ``dPl`` (29,) over the nonzero entries of
    ``w``, then clear ``w``: one velocity term ``F(s) w`` with ``s = w . v``, slope ``c = F'(s)`` and power
    derivative ``dP = (F s)'``."""
    m = 0
    for i in range(29):
        if w[i] != 0.0:
            nz[m] = i
            m += 1
    for a in range(m):
        wa = w[nz[a]]
        dPl[nz[a]] += dP * wa
        for b in range(m):
            Jl[nz[a], nz[b]] += c * wa * w[nz[b]]
    for a in range(m):
        w[nz[a]] = 0.0


@njit(cache=True)
def _damper(Jl, dPl, w, nz, xd, c):
    """A damper ``-c s w`` on ``s = w . v`` (power ``-c s^2``)."""
    s = 0.0
    for i in range(29):
        s += w[i] * xd[i]
    _rank1(Jl, dPl, w, nz, -c, -2 * c * s)


@njit(cache=True)
def _slope(v, f0, v0, law, eps):
    """``df/dv`` (s/m) of the friction law ``f(v) = psi(v) v`` at ``v >= 0`` (:func:`.friction.friction_slope`;
    at the kink of ``linear-saturated`` the right-hand slope)."""
    x = v / v0
    if law == 4:
        t = np.tanh(x)
        s = 1.0 - t * t
    elif law == 2:
        y = 0.5 * np.pi * x
        s = 1.0 / (1.0 + y * y)
    elif law == 3:
        s = 1.5 * (1.0 - x * x) if x < 1.0 else 0.0
    elif law == 1:
        s = 1.0 if x < 1 - eps else (0.0 if x > 1 + eps else 1.0 - (x - (1 - eps)) / (2 * eps))
    else:
        s = 1.0 if x < 1.0 else 0.0
    return (f0 / v0) * s


@njit(cache=True)
def _slider(Jl, dPl, w, nz, xd, N, f0, v0, law):
    """Friction ``F = -N psi(|s|) s`` along ``w`` on ``s = w . v``: slope ``-N f'(|s|)``, power derivative
    ``F' s + F``."""
    s = 0.0
    for i in range(29):
        s += w[i] * xd[i]
    F = -N * _gain(abs(s), f0, v0, law, SMOOTH_EPS) * s
    c = -N * _slope(abs(s), f0, v0, law, SMOOTH_EPS)
    _rank1(Jl, dPl, w, nz, c, c * s + F)


@njit(cache=True)
def _station_map(w, A, B, H, n0, n1, cA, cB, ath):
    """``w = n . (dU_B - dU_A) + cA dth_A + cB dth_B`` at a station with shape values ``H``: the rate map of a
    contact direction ``n`` whose force :func:`_pair` spreads (``ath (2, 29)``: the links' spin-rate maps)."""
    for i in range(4):
        w[10 * B + 2 * i] += H[i] * n0
        w[10 * B + 2 * i + 1] += H[i] * n1
        w[10 * A + 2 * i] -= H[i] * n0
        w[10 * A + 2 * i + 1] -= H[i] * n1
    for k in range(21, 29):
        w[k] += cA * ath[A, k] + cB * ath[B, k]


@njit(cache=True)
def _pin_velocity_block(x, xd, p, T_next, T_prev, b_joint, cs, arc, idx, sig_, cw, par, law, wk, vw, Jl, dPl):
    """``dQ/dv`` of pin ``p``'s element (:func:`_pin`) added into ``Jl (29, 29)`` and the gradient of its power over
    ``v`` into ``dPl (29,)``, in one pass.  Every velocity term of the pin is ``F_k(s_k) w_k`` with a rate
    ``s_k = w_k . v`` whose map ``w_k`` depends on ``x`` only (the forces are the transposed rate maps): its block
    is ``F_k' w_k w_k^T`` (dampers ``F_k = -c_k s_k``, friction laws by their slopes :func:`_slope`), its power
    gradient ``(F_k' s_k + F_k) w_k``.  Half bending damping splits into four such dampers."""
    tau, rho, thd, th, nh, Qth, H, Hp, Hpp, Ux, Vx, kA, kB, nab, Hs, CG, pw = wk
    w, nz, ath = vw
    l, b_half, A_tau, A_n, beta = par[0], par[2], par[3], par[4], par[5]
    b_roll, f0, v0 = par[9], par[13], par[14]
    for h2 in range(2):                                           # half axial damping
        w[10 * h2 + 9] = 1.0
        _damper(Jl, dPl, w, nz, xd, 4 * b_half)
    if f0 != 0.0:                                                 # axial friction (1.221)
        Tn, Tp = max(T_next, 0.0), max(T_prev, 0.0)
        w[18], w[8] = 1.0, -1.0
        _slider(Jl, dPl, w, nz, xd, 0.5 * (Tn + Tp), f0, v0, law)
        for h2 in range(2):
            w[10 * h2 + 8], w[20] = 1.0, -1.0
            _slider(Jl, dPl, w, nz, xd, Tn if h2 == 0 else Tp, f0, v0, law)
    _pin_geometry(x, p, cs, arc, idx, sig_, cw, par, tau, rho, th, nh, H, Hp, Hpp, Ux, Hs, CG)
    for j in range(2):                                            # spin-rate maps of the links
        o = 21 + 4 * j
        ath[j, :] = 0.0
        ath[j, o], ath[j, o + 1] = tau[j, 1] / rho[j], -tau[j, 0] / rho[j]
        ath[j, o + 2], ath[j, o + 3] = -tau[j, 1] / rho[j], tau[j, 0] / rho[j]
    if beta != 0.0:                                               # half bending damping, beta N^T G N
        for h2 in range(2):
            o = 10 * h2 + 4
            for d in range(2):                                    # directions t, n of the half and their weights
                u0, u1 = (th[h2, 0], th[h2, 1]) if d == 0 else (nh[h2, 0], nh[h2, 1])
                A = A_tau if d == 0 else A_n
                for sg in (1.0, -1.0):                            # [[4, 2], [2, 4]] = 3 (1,1)(1,1)^T + (1,-1)(1,-1)^T
                    for k in range(2):
                        a = 1.0 if k == 0 else sg
                        w[o + 2 * k] += a * u0
                        w[o + 2 * k + 1] += a * u1
                        cth = a * (u0 * x[o + 2 * k + 1] - u1 * x[o + 2 * k])
                        for c in range(21, 29):
                            w[c] += cth * ath[h2, c]
                    _damper(Jl, dPl, w, nz, xd, beta * (3.0 if sg > 0 else 1.0) * A / l)
    for s in range(2):
        Hst = Hs[s]
        for ic in range(3):
            A, B, sig = idx[ic, 0], idx[ic, 1], sig_[ic]
            RA, RB = arc[ic, 2], arc[ic, 5]
            wgt = l / 2 * cw[ic, p]
            n0, n1, g, N = CG[s, ic, 1], CG[s, ic, 2], CG[s, ic, 3], CG[s, ic, 4]
            kA0, kA1, kB0, kB1 = CG[s, ic, 5], CG[s, ic, 6], CG[s, ic, 7], CG[s, ic, 8]
            t0, t1 = -n1, n0
            if b_roll != 0.0 and ic == 0 and g < 0:               # roll damping on the gap rate
                _station_map(w, A, B, Hst, n0, n1, -(n0 * kA0 + n1 * kA1), n0 * kB0 + n1 * kB1, ath)
                _damper(Jl, dPl, w, nz, xd, wgt * b_roll)
            if f0 != 0.0 and N != 0.0:                            # rolling friction on the slip
                _station_map(w, A, B, Hst, t0, t1, -(t0 * kA0 + t1 * kA1 + RA), t0 * kB0 + t1 * kB1 - sig * RB, ath)
                _slider(Jl, dPl, w, nz, xd, N, f0, v0, law)
    if b_joint[p] != 0.0:                                         # joint damping (1.80)
        for c in range(21, 29):
            w[c] = ath[0, c] - ath[1, c]
        _damper(Jl, dPl, w, nz, xd, b_joint[p])


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


@njit(cache=True)
def link_tensions(q, gl, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, ints):
    """Tension (N) of every link, the normal-force proxy of the axial friction (1.221): the sum of its plates'
    tensions, as :func:`add_forces_power` computes it (the plate tension is elastic: no velocity enters)."""
    n = L.shape[0]
    T = np.zeros(n)
    x, xd, loc, Dv = np.zeros(22), np.zeros(22), np.zeros(22), np.zeros((1, 1))
    wk, none = _link_work(), _keep(0)
    for e in range(n):
        for j in range(22):
            x[j] = q[gl[e, j]]
        T[e] = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, ints[1], loc, Dv,
                     False, wk, none)
    return T


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
    Q = np.zeros(q.shape[0])
    D = add_forces_power(Q, q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2,
                         arc, idx, sig, cw, par, ints)
    return Q, D


@njit(cache=True)
def add_forces_power(Q, q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc,
                     idx, sig, cw, par, ints):
    """Add the forces of :func:`forces` to ``Q`` and return their dissipated power ``D`` (W) as :func:`forces_power`.
    ``q``, ``v`` and ``Q`` may be longer than the chain's ``21 n`` (a model's state with the chain first): only the
    entries the index tables name are read and written."""
    n = L.shape[0]
    law, kmodel = ints[0], ints[1]
    T = np.zeros(n)
    x, xd, loc, Dv = np.zeros(22), np.zeros(22), np.zeros(22), np.zeros((1, 1))
    wk, none = _link_work(), _keep(0)
    for e in range(n):
        for j in range(22):
            x[j], xd[j], loc[j] = q[gl[e, j]], v[gl[e, j]], 0.0
        T[e] = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, loc, Dv,
                     False, wk, none)
        for j in range(22):
            Q[gl[e, j]] += loc[j]
    y, yd, lp = np.zeros(29), np.zeros(29), np.zeros(29)
    pk = _pin_work()
    for p in range(n):
        for j in range(29):
            y[j], yd[j], lp[j] = q[gp[p, j]], v[gp[p, j]], 0.0
        _pin(y, yd, p, T[p], T[(p - 1) % n], b_joint, cs, arc, idx, sig, cw, par, law, True, lp, pk)
        for j in range(29):
            Q[gp[p, j]] += lp[j]
    return -(wk[-1][0] + pk[-1][0])


@njit(cache=True)
def _step(x, rel, floor):
    """A difference step ``rel max(|x|, floor)`` rounded so that ``x + h`` is exact."""
    h = rel * max(abs(x), floor)
    return (x + h) - x


@njit(cache=True)
def jacobian(q, v, gl, gp, L, c_twist, b_joint, cs, plate_w, plate_d, plate_c, plate_c1, plate_c2, arc, idx, sig,
             cw, par, ints, pos_l, pos_p, pos_t, first, steps, link_scheme, Jq, Jv, dDq, dDv):
    """``dQ/dq``, ``dQ/dv`` of :func:`forces` added into the CSR data ``Jq``, ``Jv`` (positions ``pos_l (n, 22, 22)``
    of the link blocks, ``pos_p (n, 29, 29)`` of the pin blocks, ``pos_t (n, 2, 3, 22)`` of the axial friction
    rows against the tensions' link coordinates; ``first`` of :func:`positions`).

    Element by element: a link's velocity block is exact (its forces are linear in the velocities), its
    coordinate block exact within the plates' states (``link_scheme`` :data:`ANALYTIC`, :func:`_link_jacobian`) or
    :data:`FORWARD` or :data:`CENTRAL` differences of the link alone; a pin's coordinate block central
    differences of the pin alone (a coordinate and its copies at once), its velocity block exact in one pass
    (:func:`_pin_velocity_block`); the axial friction's dependence on the link tensions by the chain rule with
    the tensions' differences.  ``steps = (link, pin coordinate)`` relative steps, applied to ``max(|x|, l)``
    (smaller steps drown in the round-off of the contact forces).

    The gradient of the dissipated power ``D`` of :func:`forces_power` over ``q`` and ``v`` is added into ``dDq``,
    ``dDv`` (21 n,) from the same element passes: the elements' power differences over ``q``, exact over ``v`` (a
    link's ``-2 Q_d``: its damping forces are linear in the velocities; a pin's from its velocity block) and the
    axial friction's tension dependence.
    """
    n = L.shape[0]
    l, f0, v0 = par[0], par[13], par[14]
    law, kmodel = ints[0], ints[1]
    floor = l
    rel_link = steps[0]
    T, dT = np.zeros(n), np.zeros((n, 22))
    x, xd, f_0, f_p, f_m = np.zeros(22), np.zeros(22), np.zeros(22), np.zeros(22), np.zeros(22)
    Dv, Dx = np.zeros((22, 22)), np.zeros((1, 1))
    wk, none, keep = _link_work(), _keep(0), _keep(plate_w.shape[1])
    pw = wk[-1]
    Kx, dPx, dPv, jw = np.zeros((22, 22)), np.zeros(22), np.zeros(22), _jac_work()
    for e in range(n):
        for j in range(22):
            x[j], xd[j], f_0[j] = q[gl[e, j]], v[gl[e, j]], 0.0
        Dv[:, :] = 0.0
        if link_scheme == ANALYTIC:
            Kx[:, :] = 0.0
            dPx[:] = 0.0
            dPv[:] = 0.0
            T[e] = _link_jacobian(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel,
                                  f_0, Kx, Dv, dT[e], dPx, dPv, wk, jw, keep)[0]
            for j in range(22):
                dDq[gl[e, j]] -= dPx[j]
                dDv[gl[e, j]] -= dPv[j]
                for r in range(22):
                    Jq[pos_l[e, r, j]] += Kx[r, j]
                    Jv[pos_l[e, r, j]] += Dv[r, j]
            continue
        pw[0] = 0.0                                               # each pass's power alone (no round-off of a sum)
        T[e] = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, f_0, Dv,
                     True, wk, none)
        P0 = pw[0]
        for j in range(22):
            x0 = x[j]
            h = _step(x0, rel_link, floor)
            x[j] = x0 + h
            f_p[:] = 0.0
            pw[0] = 0.0
            Tp = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, f_p, Dx,
                       False, wk, none)
            Pp = pw[0]
            if link_scheme != FORWARD:
                x[j] = x0 - h
                f_m[:] = 0.0
                pw[0] = 0.0
                Tm = _link(x, xd, e, L, c_twist, plate_w, plate_d, plate_c, plate_c1, plate_c2, par, kmodel, f_m,
                           Dx, False, wk, none)
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
    Jl, dPl, vw = np.zeros((29, 29)), np.zeros(29), (np.zeros(29), np.zeros(29, np.int64), np.zeros((2, 29)))
    for p in range(n):
        pv = (p - 1) % n
        for j in range(29):
            y[j], yd[j] = q[gp[p, j]], v[gp[p, j]]
        for jj in range(29):                                      # coordinates
            if first[p, jj] != jj:                                # a copy: moved with its first
                continue
            lateral = jj < 8 or 9 < jj < 18 or jj > 20                # w, q_p reach the axial terms only
            z0 = y[jj]
            h = _step(z0, steps[1], floor)
            dP = 0.0
            for sgn in range(2):
                for k in range(jj, 29):
                    if first[p, k] == jj:
                        y[k] = z0 + h if sgn == 0 else z0 - h
                g = g_p if sgn == 0 else g_m
                g[:] = 0.0
                ppw[0] = 0.0
                _pin(y, yd, p, T[p], T[pv], b_joint, cs, arc, idx, sig, cw, par, law, lateral, g, pk)
                dP += ppw[0] if sgn == 0 else -ppw[0]
            for k in range(jj, 29):
                if first[p, k] == jj:
                    y[k] = z0
            dDq[gp[p, jj]] -= dP / (2 * h)
            for r in range(29):
                Jq[pos_p[p, r, jj]] += (g_p[r] - g_m[r]) / (2 * h)
        Jl[:, :] = 0.0                                            # velocities: one pass (copies add up)
        dPl[:] = 0.0
        _pin_velocity_block(y, yd, p, T[p], T[pv], b_joint, cs, arc, idx, sig, cw, par, law, pk, vw, Jl, dPl)
        for c in range(29):
            dDv[gp[p, c]] -= dPl[c]
            for r in range(29):
                Jv[pos_p[p, r, c]] += Jl[r, c]
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


__all__ = ["ANALYTIC", "CENTRAL", "FORWARD", "HAVE_NUMBA", "SMOOTH_EPS", "add_forces_power", "forces", "forces_power",
           "jacobian", "pack", "positions"]
