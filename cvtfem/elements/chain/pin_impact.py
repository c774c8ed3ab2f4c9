"""Impact of pin ends on the sheaves at contact onset (contact-models digest §3, C2), for mirrored pairs of ends (S2,
S3) and single ends (A1).

The local interface is :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact`'s (wrapped per end by
:class:`~cvtfem.elements.chain.end_contact.EndContact` for A1): a contact reads 9 local inputs
``X = (u1, u2, u3, z, u1', u2', u3', z', omega)`` (pin-axis end, sheave reference position, their rates, the shaft's
spin rate; an A1 end in the mirrored frame of its side).  The pin end ``R = (u_perp, u3)`` meets the face
``x3 = z + s(r)`` where the penetration ``Delta = u3 - z - s(r)`` rises through zero (the event indicator,
:func:`input_gaps`).  Its velocity relative to the sheave material point it meets is ``w = B X[4:9]`` with
``B = [E | -k | -k x arm]`` (:func:`relative_velocity_map`, ``arm`` from the shaft axis point at the sheave's reference
plane), the same slip the Hertz contact's friction reads.

The impulse ``P`` (N s) on a pin end acts with ``-P`` on the sheave; on a mirrored chain the mirror end gets the mirror
impulse (chain-models-1 §2.7).  With ``G`` = ``B`` times the contact map (``w = G v``), ``e`` ends per contact (2
mirrored, 1 single) and ``M`` the model's mass matrix, the generalized impulse is ``e G^T P``, the velocities jump by
``e M^-1 G^T P`` and ``w`` by ``A P``, ``A = e G M^-1 G^T`` (the machine assembles it).  For S2 on rigid shafts ``A``
is the digest's (1.304) with the per-end masses ``m_p / 2`` (axial ``m_p / 6``), ``m_z / 2`` and ``J / 2``; S3 and A1
have their own pin-end inertia (:func:`end_compliance`).  ``P`` is (1.305) with the stick check
(:func:`~cvtfem.elements.contact.impact.impact_impulse`); the kinetic energy changes by ``(e / 2) P . (w- + w+)``
(:func:`impact_energy_change`, <= 0).  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.contact.impact import impact_compliance, impact_impulse

K = np.array([0.0, 0.0, 1.0])
#: Indicator value (m) of a pin end outside a sheave's outer radius (never in contact there).
OUTSIDE = -1.0


def _kernel(contact):
    """The H1 pair kernel of a contact (itself, or the one a single-end wrapper carries)."""
    return getattr(contact, "pair", contact)


def friction_coefficient(contact) -> float:
    """Saturated friction coefficient ``f0`` of the contact's kernel (the impact's Coulomb ``f``)."""
    return float(_kernel(contact).f0)


def input_gaps(contact, X, shafts) -> np.ndarray:
    """Penetration ``Delta = u3 - z - s(r)`` (m,) m of the contacts with position inputs ``X[:, :4] = (u1, u2, u3, z)``
    on ``shafts`` (m,); :data:`OUTSIDE` where the end lies beyond the outer radius."""
    pair = _kernel(contact)
    d = X[:, :2] - pair.centres[shafts]
    r = np.hypot(d[:, 0], d[:, 1])
    e = np.full(len(X), OUTSIDE)
    for k in (0, 1):
        sel = (shafts == k) & (r < pair.r_outer)
        e[sel] = pair._profiles[k](r[sel])[0] + X[sel, 2] - X[sel, 3]
    return e


def gap_indicators(contact, u, u3, z) -> np.ndarray:
    """Penetration (n, 2) m of every pin end ``(u (n, 2), u3 (n,))`` against the sheave of each shaft at reference
    positions ``z`` (2,) m (:func:`input_gaps` of the mirrored pin ends)."""
    n = len(u)
    X = np.column_stack([np.repeat(u, 2, axis=0), np.repeat(u3, 2), np.tile(z, n)])
    return input_gaps(contact, X, np.tile(np.arange(2), n)).reshape(n, 2)


def end_geometry(contact, X, shafts):
    """``(arm (m, 3), normal (m, 3))``: the pin end from the shaft-axis point on the sheave's reference plane (m) and
    the outward unit face normal there (pointing from the sheave to the pin: ``n . w < 0`` approaches)."""
    pair = _kernel(contact)
    arm = X[:, :3].copy()
    arm[:, :2] -= pair.centres[shafts]
    arm[:, 2] -= X[:, 3]
    r = np.hypot(arm[:, 0], arm[:, 1])
    fp = np.empty(len(X))
    for k in (0, 1):
        sel = shafts == k
        if sel.any():
            fp[sel] = pair._profiles[k](r[sel])[1]
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


def end_compliance(inplane, axial, m_z, J, arm) -> np.ndarray:
    """``A`` (m, 3, 3) 1/kg of a pin end with the inverse effective masses ``inplane`` and ``axial`` (1/kg) on a sheave
    of axial mass ``m_z`` (kg; ``inf`` for a fixed sheave) on a shaft of inertia ``J`` (kg m^2), all per end:
    ``diag(inplane, inplane, axial) + k k / m_z + (k x arm)(k x arm) / J`` (the structure of (1.304))."""
    arm = np.asarray(arm, float)
    kr = np.cross(K, arm)
    A = np.zeros((len(arm), 3, 3))
    A[:, [0, 1], [0, 1]] = np.asarray(inplane, float)[..., None]
    A[:, 2, 2] = np.asarray(axial, float) + 1.0 / np.asarray(m_z, float)
    return A + kr[:, :, None] * kr[:, None, :] / np.asarray(J, float)[..., None, None]


def pin_end_impulses(w, normal, A, f):
    """``(P (m, 3) N s, state (m,))`` of the impacts with relative velocities ``w`` (m/s), normals, compliances
    ``A`` and friction coefficient ``f``: :func:`~cvtfem.elements.contact.impact.impact_impulse` (state FREE where
    separating)."""
    return impact_impulse(w, normal, A, np.broadcast_to(np.asarray(f, float), (len(w),)))


def impact_energy_change(P, w_before, w_after, ends: int = 2) -> np.ndarray:
    """Kinetic energy change (m,) J of an impulse ``P`` on each of ``ends`` pin ends (2: a mirrored pair, 1: a single
    end): ``(ends / 2) P . (w- + w+)``."""
    return 0.5 * ends * np.sum(P * (w_before + w_after), axis=-1)
