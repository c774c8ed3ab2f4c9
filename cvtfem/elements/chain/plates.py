"""Per-plate model of the chain (A3/A4): plate strains, the ten contact states, forces.

Spec chain-models-2.md section 4.  Every plate of a link is evaluated on its
own.  Its rigid-attachment strains ``eps = (psi_1, psi_2, Delta)`` (end tilts
in rad, elongation in m; (1.186)-(1.189)) come from the two end pins at the
plate's station ``xi``.  In A4 the pin may bear on the plate along a line or at
a corner, so the end moments are bounded by ``|M_a| <= T h / 2`` and the plate
carries tension only: the corner angles ``delta_a`` minimise the convex plate
energy, which gives ten states with closed forms (1.175)-(1.185).  A3 clamps
the plates to the pins (``delta = 0``).

Every function is vectorised over any leading shape of plates (``(n_plates,)``
or the padded ``(n_links, K_max)`` of spec section 8); no loop over plates.

State numbers (spec table of section 4.3; ``s_a`` the corner sign at end ``a``):
1 line contact at both ends, 2/3 corner ``+``/``-`` at end 1, 4/5 at end 2,
6 ``(+, +)``, 7 ``(-, -)``, 8 ``(-, +)``, 9 ``(+, -)``, 10 slack (no force).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.outputs import OutputSpec

#: State of a slack plate (state 10): it carries nothing.
SLACK = 10
#: Corner signs ``(s_1, s_2)`` of states 1..10 (row ``state - 1``); state 10 takes ``sgn psi``.
CORNER_SIGNS = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1],
                         [1, 1], [-1, -1], [-1, 1], [1, -1], [0, 0]], dtype=float)
#: Local coordinates of one plate: pin ``p`` then pin ``p + 1``, each
#: ``u_perp[0..3]`` (x1, x2 interleaved, m / rad) then ``u_par[0..1]`` (m).
N_LOCAL = 20


def bending_stiffnesses(a: np.ndarray, L: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Plate end-moment stiffnesses ``c_1 = 4 a / L``, ``c_2 = 2 a / L`` (N m/rad) from ``a`` (N m^2), ``L`` (m); (1.170)."""
    return 4.0 * a / L, 2.0 * a / L


@dataclass(frozen=True)
class PlateState:
    """Quasi-static state of every plate (arrays over the plates' leading shape ``S``).

    Attributes
    ----------
    state : int ndarray S
        Contact state 1..10 (module docstring).
    delta : ndarray S + (2,)
        Corner-contact angles ``delta_a``, rad (state 10: ``psi``).
    zeta : ndarray S + (2,)
        True end bending strains ``zeta_a = psi_a - delta_a``, rad.
    stretch : ndarray S
        True elongation ``Delta~ = Delta + h/2 (|delta_1| + |delta_2|)``, m (<= 0 in state 10).
    tension : ndarray S
        ``T = c Delta~`` (0 in state 10), N.
    moment : ndarray S + (2,)
        End moments ``M = C zeta``, N m.
    energy : ndarray S
        Elastic energy ``1/2 c Delta~^2 + 1/2 zeta^T C zeta`` (1.190)-(1.191), J.
    A : ndarray S + (3, 3)
        State Jacobian ``d(zeta_1, zeta_2, Delta~) / d(psi_1, psi_2, Delta)`` (1.205)-(1.208); 0 in state 10.
    """

    state: np.ndarray
    delta: np.ndarray
    zeta: np.ndarray
    stretch: np.ndarray
    tension: np.ndarray
    moment: np.ndarray
    energy: np.ndarray
    A: np.ndarray


def _moments(zeta: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> np.ndarray:
    """``M = C zeta`` with ``C = [[c1, c2], [c2, c1]]`` (1.171), N m."""
    return np.stack([c1 * zeta[..., 0] + c2 * zeta[..., 1], c2 * zeta[..., 0] + c1 * zeta[..., 1]], axis=-1)


def _state_margins(eps, c, c1, c2, h):
    """Existence margins (N m) of states 1..10 (S + (10,)) and the candidate ``delta`` of each (S + (10, 2)).

    A state exists where all its conditions (spec table, section 4.3) hold, i.e. its margin (the smallest
    condition value, each written as a moment) is positive; (1.174)-(1.185).
    """
    psi1, psi2, Delta = eps[..., 0], eps[..., 1], eps[..., 2]
    c0 = h * h * c / 4.0
    M0 = h * c * Delta / 2.0
    M01, M02 = c1 * psi1 + c2 * psi2, c2 * psi1 + c1 * psi2
    M11, M12 = (c0 + c1 + c2) * psi1 - c0 * psi2, -c0 * psi1 + (c0 + c1 + c2) * psi2
    M21, M22 = (c0 + c1 - c2) * psi1 + c0 * psi2, c0 * psi1 + (c0 + c1 - c2) * psi2
    zero = np.zeros_like(Delta)
    k1 = c0 + c1
    Dp, Dm = 2 * c0 + c1 + c2, 2 * c0 + c1 - c2          # D of states 6/7 (s1 s2 = +1) and 8/9 (s1 s2 = -1)

    def half_T(s1, s2, D):
        """``h T / 2`` of a double-corner state (1.184)."""
        return (c1 + s1 * s2 * c2) / D * (c0 * (s1 * psi1 + s2 * psi2) + M0)

    margins = np.stack([
        np.minimum(M0, np.minimum(M0 - np.abs(M01), M0 - np.abs(M02))),
        np.minimum(M01 - M0, np.minimum(M0 - M12, M22 + M0)),
        np.minimum(-M01 - M0, np.minimum(M0 - M22, M12 + M0)),
        np.minimum(M02 - M0, np.minimum(M0 - M11, M21 + M0)),
        np.minimum(-M02 - M0, np.minimum(M0 - M21, M11 + M0)),
        np.minimum(M11 - M0, np.minimum(M12 - M0, half_T(1, 1, Dp))),
        np.minimum(-M11 - M0, np.minimum(-M12 - M0, half_T(-1, -1, Dp))),
        np.minimum(-M21 - M0, np.minimum(M22 - M0, half_T(-1, 1, Dm))),
        np.minimum(M21 - M0, np.minimum(-M22 - M0, half_T(1, -1, Dm))),
        -(M0 + c0 * (np.abs(psi1) + np.abs(psi2))),
    ], axis=-1)
    # candidate corner angles: single corners (1.176), double corners (1.183), slack delta = psi
    d1 = np.stack([zero, (M01 - M0) / k1, (M01 + M0) / k1, zero, zero,
                   (M11 - M0) / Dp, (M11 + M0) / Dp, (M21 + M0) / Dm, (M21 - M0) / Dm, psi1], axis=-1)
    d2 = np.stack([zero, zero, zero, (M02 - M0) / k1, (M02 + M0) / k1,
                   (M12 - M0) / Dp, (M12 + M0) / Dp, (M22 - M0) / Dm, (M22 + M0) / Dm, psi2], axis=-1)
    return margins, np.stack([d1, d2], axis=-1)


def _per_plate(eps: np.ndarray, *params) -> list[np.ndarray]:
    """The plate parameters broadcast to the plates' shape ``eps.shape[:-1]``."""
    return [np.broadcast_to(np.asarray(p, float), eps.shape[:-1]) for p in params]


def classify(eps: np.ndarray, c: np.ndarray, c1: np.ndarray, c2: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Contact state 1..10 of every plate (A4), exactly one each; (1.175)-(1.185).

    Parameters
    ----------
    eps : ndarray S + (3,)
        ``(psi_1, psi_2, Delta)``: end tilts (rad) and elongation (m).
    c, c1, c2, h : ndarray broadcasting to S
        Tension stiffness (N/m), end-moment stiffnesses ``c_1 > c_2 > 0`` (N m/rad), plate thickness (m).

    The state whose existence conditions hold; on a state boundary (where the
    forces of both states agree) the one nearest to holding, lower number on ties.
    """
    margins, _ = _state_margins(eps, *_per_plate(eps, c, c1, c2, h))
    return np.argmax(margins, axis=-1) + 1


def _state_jacobian(state, s, c0, c1, c2, h):
    """``A`` of (1.205)-(1.208) for each plate's state (S + (3, 3))."""
    s1, s2 = s[..., 0], s[..., 1]
    one, zero = np.ones_like(c0), np.zeros_like(c0)
    k1 = c0 + c1
    A23 = np.stack([np.stack([c0, -c2, s1 * 2 / h * c0], -1),
                    np.stack([zero, k1, zero], -1),
                    np.stack([s1 * h / 2 * c1, s1 * h / 2 * c2, c1], -1)], -2) / k1[..., None, None]
    A45 = np.stack([np.stack([k1, zero, zero], -1),
                    np.stack([-c2, c0, s2 * 2 / h * c0], -1),
                    np.stack([s2 * h / 2 * c2, s2 * h / 2 * c1, c1], -1)], -2) / k1[..., None, None]
    ss = s1 * s2
    D = 2 * c0 + c1 + ss * c2
    A69 = np.stack([np.stack([c0, ss * c0, s1 * 2 / h * c0], -1),
                    np.stack([ss * c0, c0, s2 * 2 / h * c0], -1),
                    np.stack([h / 2 * (s1 * c1 + s2 * c2), h / 2 * (s2 * c1 + s1 * c2), c1 + ss * c2], -1)],
                   -2) / D[..., None, None]
    eye = np.eye(3) * one[..., None, None]
    st = state[..., None, None]
    return np.select([st == 1, st <= 3, st <= 5, st <= 9], [eye, A23, A45, A69], 0.0 * eye)


def plate_state(eps: np.ndarray, c: np.ndarray, c1: np.ndarray, c2: np.ndarray, h: np.ndarray) -> PlateState:
    """State, tension and moments of every plate of model A4 (bounded moment, tension only); (1.168)-(1.185).

    Arguments as :func:`classify`.  ``T >= 0`` and ``|M_a| <= h T / 2`` hold
    in every state; ``delta`` minimises the convex plate energy (spec section 4.3).
    """
    c, c1, c2, h = _per_plate(eps, c, c1, c2, h)
    margins, candidates = _state_margins(eps, c, c1, c2, h)
    idx = np.argmax(margins, axis=-1)
    delta = np.take_along_axis(candidates, idx[..., None, None], axis=-2)[..., 0, :]
    state = idx + 1
    s = np.where((state == SLACK)[..., None], np.sign(eps[..., :2]), CORNER_SIGNS[idx])
    stretch = eps[..., 2] + h / 2 * np.sum(s * delta, axis=-1)
    zeta = eps[..., :2] - delta
    tension = c * np.maximum(stretch, 0.0)
    moment = _moments(zeta, c1, c2)
    energy = 0.5 * tension * np.maximum(stretch, 0.0) + 0.5 * np.sum(zeta * moment, axis=-1)
    A = _state_jacobian(state, s, h * h * c / 4.0, c1, c2, h)
    return PlateState(state, delta, zeta, stretch, tension, moment, energy, A)


def clamped_plate_state(eps: np.ndarray, c: np.ndarray, c1: np.ndarray, c2: np.ndarray,
                        drop_compressed: bool = True) -> PlateState:
    """Plates rigidly clamped to the pins, model A3 (section 4.8): ``delta = 0``, ``A = I``.

    With ``drop_compressed`` (the default, as (1.190)) a plate with ``Delta <= 0``
    is slack (state 10, no force); otherwise it stays in state 1 and ``T = c Delta``
    may be negative.  Arguments as :func:`classify`.
    """
    c, c1, c2 = _per_plate(eps, c, c1, c2)
    Delta = eps[..., 2]
    active = Delta > 0 if drop_compressed else np.ones(Delta.shape, bool)
    state = np.where(active, 1, SLACK)
    zeta = np.where(active[..., None], eps[..., :2], 0.0)
    stretch = Delta
    tension = np.where(active, c * Delta, 0.0)
    moment = _moments(zeta, c1, c2)
    energy = 0.5 * tension * Delta + 0.5 * np.sum(zeta * moment, axis=-1)
    A = np.eye(3) * active[..., None, None]
    return PlateState(state, eps[..., :2] - zeta, zeta, stretch, tension, moment, energy, A)


def reduced_moment(st: PlateState, h: np.ndarray) -> np.ndarray:
    """Reduced bending moment ``m_a = 2 M_a / (h T)`` at both ends (S + (2,)), (1.357); NaN where ``T = 0``.

    ``|m| <= 1`` in A4, ``|m| = 1`` at a corner contact.
    """
    den = (np.asarray(h) * st.tension)[..., None] * np.ones(2)
    out = np.full(den.shape, np.nan)
    return np.divide(2.0 * st.moment, den, out=out, where=den != 0)


def _shape_functions(xi: np.ndarray, l: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``h_0..h_3(xi)`` (m for i = 2, 3) and ``h_i'(xi)`` (S + (4,)); (1.132)."""
    one, l8 = np.ones_like(xi), l / 8.0
    H = np.stack([one, xi, l8 * (1 - xi) ** 2 * (1 + xi), l8 * (xi - 1) * (1 + xi) ** 2], axis=-1)
    Hp = np.stack([0 * one, one, l8 * (3 * xi ** 2 - 2 * xi - 1), l8 * (3 * xi ** 2 + 2 * xi - 1)], axis=-1)
    return H, Hp


def _linear_maps(xi: np.ndarray, l: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``B`` (S + (3, 20)) with ``V = U_2(xi) - U_1(xi) = B q`` and ``Tt`` (S + (2, 2, 20)) with
    ``t_perp_a = Tt[a] q`` (1.186)-(1.187), over the local coordinates of :data:`N_LOCAL`."""
    H, Hp = _shape_functions(xi, np.broadcast_to(l, xi.shape))
    eye2 = np.eye(2)
    Bperp = (H[..., None, :, None] * eye2[:, None, :]).reshape(xi.shape + (2, 8))        # d V_perp / d u_perp
    Tp = (2.0 / np.asarray(l)[..., None, None] * Hp[..., None, :, None] * eye2[:, None, :]).reshape(xi.shape + (2, 8))
    zero2, zero8 = np.zeros(xi.shape + (2, 2)), np.zeros(xi.shape + (2, 8))
    par = np.stack([np.ones_like(xi), xi], axis=-1)[..., None, :]                          # d V_par / d u_par
    B = np.concatenate([np.concatenate([-Bperp, zero2, Bperp, zero2], -1),
                        np.concatenate([0 * Bperp[..., :1, :], -par, 0 * Bperp[..., :1, :], par], -1)], -2)
    Tt = np.stack([np.concatenate([Tp, zero2, zero8, zero2], -1),
                   np.concatenate([zero8, zero2, Tp, zero2], -1)], axis=-3)
    return B, Tt


def _local(u1perp, u1par, u2perp, u2par) -> np.ndarray:
    """Local coordinate vector ``q`` (S + (20,)) of :data:`N_LOCAL`."""
    S = u1par.shape[:-1]
    return np.concatenate([u1perp.reshape(S + (8,)), u1par, u2perp.reshape(S + (8,)), u2par], axis=-1)


def _geometry(u1perp, u1par, u2perp, u2par, xi, l, L):
    """``q``, ``B``, ``Tt``, ``tau`` (S + (3,)), ``L~``, ``t_a`` (S + (2, 3)), ``eps``."""
    xi = np.asarray(xi, float)
    q = _local(u1perp, u1par, u2perp, u2par)
    B, Tt = _linear_maps(xi, l)
    V = np.einsum("...ij,...j->...i", B, q)
    Lt = np.sqrt(np.sum(V * V, axis=-1))
    tau = V / Lt[..., None]
    tperp = np.einsum("...aij,...j->...ai", Tt, q)
    t = np.concatenate([tperp, np.ones(tperp.shape[:-1] + (1,))], axis=-1)
    psi = np.einsum("...ai,...i->...a", t, tau)
    eps = np.concatenate([psi, (Lt - L)[..., None]], axis=-1)
    return q, B, Tt, tau, Lt, t, eps


def plate_strains(u1perp: np.ndarray, u1par: np.ndarray, u2perp: np.ndarray, u2par: np.ndarray,
                  xi: np.ndarray, l: np.ndarray, L: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rigid-attachment strains of every plate and their gradient; (1.186)-(1.189), (1.199)-(1.202), (1.209).

    Parameters
    ----------
    u1perp, u2perp : ndarray S + (4, 2)
        In-plane coordinates ``u_perp[0..3]`` of the plate's pins ``p`` and ``p + 1`` (m, m, -, -; spec 2.1).
    u1par, u2par : ndarray S + (2,)
        Axial coordinates ``u_par[0..1]`` of the two pins, m.
    xi : ndarray S
        Plate station along the pins, -1 (far end) .. 1 (near end).
    l, L : ndarray broadcasting to S
        Pin axis length and plate pitch, m.

    Returns
    -------
    eps : ndarray S + (3,)
        ``(psi_1, psi_2, Delta)`` (rad, rad, m); ``Delta = |V| - L`` exactly, ``psi_a = tau . t_a``.
    J : ndarray S + (3, 20)
        ``d eps / d q`` over the local coordinates ``q`` (layout :data:`N_LOCAL`); with
        ``1 / L~`` and ``2 h_i' / l`` as corrected in spec section 9, item 11.
    """
    _, B, Tt, tau, Lt, t, eps = _geometry(u1perp, u1par, u2perp, u2par, xi, l, L)
    e = (t - tau[..., None, :] * eps[..., :2, None]) / Lt[..., None, None]          # d psi_a / d V
    Jpsi = np.einsum("...ai,...ij->...aj", e, B) + np.einsum("...i,...aij->...aj", tau[..., :2], Tt)
    JD = np.einsum("...i,...ij->...j", tau, B)
    return eps, np.concatenate([Jpsi, JD[..., None, :]], axis=-2)


def strain_hessians(u1perp: np.ndarray, u1par: np.ndarray, u2perp: np.ndarray, u2par: np.ndarray,
                    xi: np.ndarray, l: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Second derivatives ``d^2 eps / dq^2`` (S + (3, 20, 20)) of the strains of :func:`plate_strains` (same arguments).

    With ``P = E - tau tau``: ``d^2 Delta / dV^2 = P / L~``, ``d^2 psi_a / dV^2 = -(psi_a P / L~ + tau e_a + e_a tau) / L~``,
    ``d^2 psi_a / dV dt_perp_a = P_perp / L~`` (derived from (1.186)-(1.189)).
    """
    _, B, Tt, tau, Lt, t, eps = _geometry(u1perp, u1par, u2perp, u2par, xi, l, L)
    Pm = (np.eye(3) - tau[..., :, None] * tau[..., None, :]) / Lt[..., None, None]     # P / L~
    e = (t - tau[..., None, :] * eps[..., :2, None]) / Lt[..., None, None]
    HD = np.einsum("...ki,...kl,...lj->...ij", B, Pm, B)
    out = []
    for a in range(2):
        ea = e[..., a, :]
        G = -(eps[..., a, None, None] * Pm + tau[..., :, None] * ea[..., None, :]
              + ea[..., :, None] * tau[..., None, :]) / Lt[..., None, None]
        mixed = np.einsum("...ki,...kl,...lj->...ij", B, Pm[..., :, :2], Tt[..., a, :, :])
        out.append(np.einsum("...ki,...kl,...lj->...ij", B, G, B) + mixed + np.swapaxes(mixed, -1, -2))
    return np.stack(out + [HD], axis=-3)


def strain_forces(st: PlateState, epsdot: np.ndarray, c: np.ndarray, c1: np.ndarray, c2: np.ndarray,
                  beta_ext: float, beta_shear: float) -> np.ndarray:
    """Generalised forces on the strains ``eps``: ``A^T f``, ``f = -dPi/deps~ - dPhi/deps~'`` (S + (3,)); (1.203)-(1.204).

    ``epsdot`` (S + (3,)) are the strain rates ``(psi_1', psi_2', Delta')`` (rad/s, m/s);
    ``beta_ext``, ``beta_shear`` the stiffness-proportional damping times (s) of (1.192)-(1.193).
    By the envelope theorem the elastic part is ``-(M_1, M_2, T)``.
    """
    rate = np.einsum("...ij,...j->...i", st.A, epsdot)
    damp = np.concatenate([beta_shear * _moments(rate[..., :2], c1, c2), (beta_ext * c * rate[..., 2])[..., None]],
                          axis=-1)
    stress = np.concatenate([st.moment, st.tension[..., None]], axis=-1) + damp
    return -np.einsum("...ji,...j->...i", st.A, stress)


def rayleigh(st: PlateState, epsdot: np.ndarray, c: np.ndarray, c1: np.ndarray, c2: np.ndarray,
             beta_ext: float, beta_shear: float) -> np.ndarray:
    """Rayleigh function ``Phi`` of every plate (S), W; (1.192)-(1.193) with ``eps~' = A eps'`` (1.198).

    Arguments as :func:`strain_forces`; state-10 plates dissipate nothing.
    """
    rate = np.einsum("...ij,...j->...i", st.A, epsdot)
    shear = np.sum(rate[..., :2] * _moments(rate[..., :2], c1, c2), axis=-1)
    return 0.5 * (beta_shear * shear + beta_ext * c * rate[..., 2] ** 2)


def plate_forces(st: PlateState, J: np.ndarray, qdot: np.ndarray, c: np.ndarray, c1: np.ndarray,
                 c2: np.ndarray, beta_ext: float, beta_shear: float) -> np.ndarray:
    """Generalised forces ``Q = J^T A^T f`` of every plate on its 20 local coordinates (S + (20,)); (1.203)-(1.209).

    ``J`` from :func:`plate_strains`, ``qdot`` (S + (20,)) the local velocities;
    elastic plus damping forces, ``-dPi/dq - dPhi/dqdot``.  Pin ``p`` takes
    entries 0..9, pin ``p + 1`` entries 10..19.
    """
    epsdot = np.einsum("...ij,...j->...i", J, qdot)
    g = strain_forces(st, epsdot, c, c1, c2, beta_ext, beta_shear)
    return np.einsum("...ji,...j->...i", J, g)


def force_jacobians(st: PlateState, J: np.ndarray, Heps: np.ndarray, qdot: np.ndarray, c: np.ndarray,
                    c1: np.ndarray, c2: np.ndarray, beta_ext: float,
                    beta_shear: float) -> tuple[np.ndarray, np.ndarray]:
    """``dQ/dq`` and ``dQ/dqdot`` (S + (20, 20) each) of :func:`plate_forces` within the plate's current state.

    ``Heps`` from :func:`strain_hessians`.  With ``K = diag(C, c)``, ``D = diag(beta_shear C, beta_ext c)``
    and ``g`` of :func:`strain_forces`: ``dQ/dqdot = -J^T A^T D A J`` and
    ``dQ/dq = sum_s g_s Heps_s - J^T A^T K A J - J^T A^T D A (Heps qdot)``.  ``A`` jumps across state
    boundaries, so do these matrices (the forces do not).
    """
    c, c1, c2 = (np.broadcast_to(np.asarray(x, float), st.tension.shape) for x in (c, c1, c2))
    z = np.zeros_like(c)
    K = np.stack([np.stack([c1, c2, z], -1), np.stack([c2, c1, z], -1), np.stack([z, z, c], -1)], -2)
    D = K * np.array([beta_shear, beta_shear, beta_ext])[:, None]
    AJ = np.einsum("...ij,...jk->...ik", st.A, J)
    epsdot = np.einsum("...ij,...j->...i", J, qdot)
    g = strain_forces(st, epsdot, c, c1, c2, beta_ext, beta_shear)
    dQ_dqdot = -np.einsum("...ji,...jk,...kl->...il", AJ, D, AJ)
    Hq = np.einsum("...sij,...j->...si", Heps, qdot)                                   # d(J qdot)/dq
    dQ_dq = (np.einsum("...s,...sij->...ij", g, Heps) - np.einsum("...ji,...jk,...kl->...il", AJ, K, AJ)
             - np.einsum("...ji,...jk,...kl->...il", AJ, D, np.einsum("...ij,...jk->...ik", st.A, Hq)))
    return dQ_dq, dQ_dqdot


def output_specs(n_plates: int) -> tuple[OutputSpec, ...]:
    """Named outputs of the plates (spec section 7): tension, reduced moment, contact state."""
    return (OutputSpec("chain.plate_tension", "N", "Tension T = c Delta~ of each plate.", n_plates),
            OutputSpec("chain.plate_reduced_moment", "1",
                       "Reduced bending moment m = 2M/(hT) at both ends of each plate (end 1, end 2; NaN if slack).",
                       2 * n_plates),
            OutputSpec("chain.plate_state", "1", "Contact state 1..10 of each plate (10 = slack).", n_plates))


def outputs(st: PlateState, h: np.ndarray) -> dict[str, np.ndarray]:
    """Values of :func:`output_specs` for a :class:`PlateState` (flattened in plate order)."""
    return {"chain.plate_tension": st.tension.ravel(),
            "chain.plate_reduced_moment": reduced_moment(st, h).reshape(-1),
            "chain.plate_state": st.state.ravel().astype(float)}
