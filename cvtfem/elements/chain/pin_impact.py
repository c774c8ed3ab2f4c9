"""Impact of the pin ends of a symmetric chain on the sheaves at contact onset (contact-models digest §3, C2).

The local interface is :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact`'s: a contact reads 9 local inputs
``X = (u1, u2, u3, z, u1', u2', u3', z', omega)`` (pin-axis end, sheave reference position, their rates, the shaft's
spin rate).  The pin end ``R = (u_perp, u3)`` meets the face ``x3 = z + s(r)`` where the penetration
``Delta = u3 - z - s(r)`` rises through zero (the event indicator, :func:`gap_indicators`).  Its velocity relative to
the sheave material point it meets is ``w = B X[4:9]`` with ``B = [E | -k | -k x arm]`` (:func:`relative_velocity_map`,
``arm`` from the shaft axis point at the sheave's reference plane), the same slip the Hertz contact's friction reads.

The impulse ``P`` (N s) on the ``x3 > 0`` pin end acts with ``-P`` on the sheave; the mirror end gets the mirror
impulse (chain-models-1 §2.7), so the generalized impulse is ``2 B^T P`` on the local inputs' coordinates (the virtual
work of the contact's ``Y``).  With ``M`` the model's mass matrix the velocity jump is ``2 M^-1 G^T P`` and the
relative velocity jumps by ``A P``, ``A = 2 G M^-1 G^T`` (``G`` = ``B`` times the contact map; the machine assembles
it).  For S2 on rigid shafts ``A`` is the digest's (1.304) with the per-end masses ``m_p / 2`` (axial ``m_p / 6``),
``m_z / 2`` and ``J / 2`` (:func:`symmetric_compliance`).  ``P`` is (1.305) with the stick check
(:func:`~cvtfem.elements.contact.impact.impact_impulse`); the kinetic energy changes by ``P . (w- + w+)``
(:func:`impact_energy_change`, <= 0).  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.contact.impact import impact_compliance, impact_impulse

K = np.array([0.0, 0.0, 1.0])
#: Indicator value (m) of a pin end outside a sheave's outer radius (never in contact there).
OUTSIDE = -1.0


def gap_indicators(contact, u, u3, z) -> np.ndarray:
    """Penetration ``Delta = u3 - z_k - s(r)`` (n, 2) m of every pin end ``(u (n, 2), u3 (n,))`` against the sheave of
    each shaft at reference positions ``z`` (2,) m; :data:`OUTSIDE` where the end lies beyond the outer radius."""
    e = np.full((len(u), 2), OUTSIDE)
    for k in (0, 1):
        d = u - contact.centres[k]
        r = np.hypot(d[:, 0], d[:, 1])
        near = r < contact.r_outer
        e[near, k] = contact._profiles[k](r[near])[0] + u3[near] - z[k]
    return e


def end_geometry(contact, X, shafts):
    """``(arm (m, 3), normal (m, 3))``: the pin end from the shaft-axis point on the sheave's reference plane (m) and
    the outward unit face normal there (pointing from the sheave to the pin: ``n . w < 0`` approaches)."""
    arm = X[:, :3].copy()
    arm[:, :2] -= contact.centres[shafts]
    arm[:, 2] -= X[:, 3]
    r = np.hypot(arm[:, 0], arm[:, 1])
    fp = np.empty(len(X))
    for k in (0, 1):
        sel = shafts == k
        if sel.any():
            fp[sel] = contact._profiles[k](r[sel])[1]
    grad = np.column_stack([fp / r * arm[:, 0], fp / r * arm[:, 1], np.ones(len(X))])   # d Delta / d R
    return arm, -grad / np.sqrt(1.0 + fp * fp)[:, None]


def relative_velocity_map(arm) -> np.ndarray:
    """``B`` (m, 3, 5): ``w = B (u1', u2', u3', z', omega)``, the pin end's velocity minus that of the sheave point it
    meets (``z' k + omega k x arm``), m/s."""
    B = np.zeros((len(arm), 3, 5))
    B[:, [0, 1, 2], [0, 1, 2]] = 1.0
    B[:, 2, 3] = -1.0
    B[:, 0, 4] = arm[:, 1]          # -(k x arm) = (arm_2, -arm_1, 0)
    B[:, 1, 4] = -arm[:, 0]
    return B


def symmetric_compliance(m_pin, m_z, J, arm) -> np.ndarray:
    """``A`` (m, 3, 3) 1/kg of a mirrored S2 pin end on a rigid shaft: (1.304) with the per-end masses (the pin's
    ``m_pin / 2``, axially ``m_pin / 6``; ``m_z / 2``, ``J / 2`` of the coordinate ``z`` and of the shaft)."""
    return impact_compliance(np.asarray(m_pin) / 2, np.asarray(m_z) / 2, np.asarray(J) / 2, arm)


def pin_end_impulses(w, normal, A, f):
    """``(P (m, 3) N s, state (m,))`` of the impacts with relative velocities ``w`` (m/s), normals, compliances
    ``A`` and friction coefficient ``f``: :func:`~cvtfem.elements.contact.impact.impact_impulse` (state FREE where
    separating)."""
    return impact_impulse(w, normal, A, np.broadcast_to(np.asarray(f, float), (len(w),)))


def impact_energy_change(P, w_before, w_after) -> np.ndarray:
    """Kinetic energy change (m,) J of an impulse ``P`` on a mirrored pin end: ``P . (w- + w+)`` (both ends)."""
    return np.sum(P * (w_before + w_after), axis=-1)
