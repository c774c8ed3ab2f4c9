"""Impact of a pin end on a sheave at contact onset (contact-models digest §3, (1.299)–(1.305)).

Perfectly inelastic in the normal direction, Coulomb-type tangential impulse, "stick if possible".
Vectorised over impacts: vectors ``(n, 3)``, tensors ``(n, 3, 3)``.
"""
from __future__ import annotations

import numpy as np

FREE, SLIDING, STUCK = 0, 1, 2  # discrete contact states F, S, K (digest §7)


def _outer(a, b):
    return a[..., :, None] * b[..., None, :]


def impact_compliance(m_p, m, J, rho, k=(0.0, 0.0, 1.0)):
    """``A_p = m_p^-1 + M_s`` (1/kg) of (1.304): ``v_r+ = v_r- + A_p P``.

    ``m_p`` pin-end mass (kg, axial mass ``m_p/3``, (1.302)), ``m`` sheave mass (kg), ``J`` its
    moment of inertia about the shaft axis (kg m^2), ``rho`` ``(n, 3)`` moment arm from the shaft
    axis (m), ``k`` the shaft-axis unit vector.
    """
    rho = np.asarray(rho, dtype=float)
    k = np.broadcast_to(np.asarray(k, dtype=float), rho.shape)
    m_p, m, J = (np.asarray(x, dtype=float)[..., None, None] for x in (m_p, m, J))
    kk = _outer(k, k)
    kr = np.cross(k, rho)
    return (np.eye(3) + 2 * kk) / m_p + kk / m + _outer(kr, kr) / J


def impact_impulse(v_r, normal, A, f):
    """Impulse ``P`` (N s) on the pin end and the state after impact (digest §3 algorithm).

    ``v_r`` ``(n, 3)`` relative velocity pin minus sheave before impact (m/s), ``normal``
    ``(n, 3)`` unit outward sheave normals, ``A`` ``(n, 3, 3)`` from :func:`impact_compliance`,
    ``f`` friction coefficients (scalar or (n,)). Stick (``v_r+ = 0``) when the stick impulse satisfies (1.301)
    (``|tau| <= 1``, ``tau . tau- >= 0``), else sliding with (1.305) and ``alpha = E_t``.
    Where ``n . v_r >= 0`` (separating) ``P = 0`` and the state is ``FREE``; where the sliding
    denominator of (1.305) is not positive, stick (digest §3, edge cases).
    Returns ``(P (n, 3), state (n,) in {FREE, SLIDING, STUCK})``.
    """
    v_r, normal = np.asarray(v_r, dtype=float), np.asarray(normal, dtype=float)
    A, f = np.asarray(A, dtype=float), np.asarray(f, dtype=float)
    proj = np.eye(3) - _outer(normal, normal)
    vn = np.sum(normal * v_r, axis=-1)
    vt = np.einsum("...ij,...j->...i", proj, v_r)
    vt_norm = np.linalg.norm(vt, axis=-1)
    tau_minus = vt / np.where(vt_norm > 0.0, vt_norm, 1.0)[..., None]  # 0 for a normal impact

    P_st = -np.linalg.solve(A, v_r[..., None])[..., 0]
    Pn_st = np.sum(normal * P_st, axis=-1)
    Pt_st = np.einsum("...ij,...j->...i", proj, P_st)
    # (1.301) with tau_st = -Pt_st / (f Pn_st): |Pt_st| <= f Pn_st and Pt_st . tau- <= 0
    stick = (Pn_st > 0.0) & (np.linalg.norm(Pt_st, axis=-1) <= f * Pn_st) \
        & (np.sum(Pt_st * tau_minus, axis=-1) <= 0.0)

    d = normal - f[..., None] * tau_minus
    denom = np.sum(normal * np.einsum("...ij,...j->...i", A, d), axis=-1)
    stick |= denom <= 0.0
    Pn = -vn / np.where(denom > 0.0, denom, 1.0)
    P = np.where(stick[..., None], P_st, Pn[..., None] * d)
    hit = vn < 0.0
    P = np.where(hit[..., None], P, 0.0)
    state = np.where(hit, np.where(stick, STUCK, SLIDING), FREE)
    return P, state


def impact_jumps(P, m_p, m, J, rho, k=(0.0, 0.0, 1.0)):
    """Velocity jumps of (1.304) for impulses ``P`` ``(n, 3)`` (N s) on the pin ends.

    Returns ``(dv_pin (n, 3) m/s, dz_dot (n,) m/s, dphi_dot (n,) rad/s)``: the pin end gains
    ``m_p^-1 P`` with ``m_p^-1 = (E + 2 k k)/m_p``; the sheave gets ``-P`` at arm ``rho``.
    Per-impact sheave jumps; a sheave hit by several pins at once sums them.
    """
    P, rho = np.asarray(P, dtype=float), np.asarray(rho, dtype=float)
    k = np.broadcast_to(np.asarray(k, dtype=float), P.shape)
    kP = np.sum(k * P, axis=-1)
    dv_pin = (P + 2 * k * kP[..., None]) / np.asarray(m_p, dtype=float)[..., None]
    return dv_pin, -kP / m, -np.sum(np.cross(k, rho) * P, axis=-1) / J
