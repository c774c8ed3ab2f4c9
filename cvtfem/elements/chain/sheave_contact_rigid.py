"""Rigid pin–sheave contact of the S1 chain: the pin-end axial position is not a coordinate but follows the sheave
face while the pin touches it (chain-models-1 §2.2 and §2.7, (1.89)-(1.91)).

S1 pins carry no axial inertia and an axial spring ``c_p`` only (Fig. 1.15 left).  The end of pin ``p`` sits at
``u3 = l/2`` on a free span and on the face, ``u3 = z_k + s(r)``, while the face lies inside the free end
(``z_k + s(r) < l/2``): the contact is one-sided and continuous, with no discrete state and no impact (S1 cannot
have one).  The pin's potential ``Pi = c_p Delta^2 / 2``, ``Delta = 2 u3 - l``, becomes a function of the in-plane
position and the sheave position, and its generalized forces are those of the dependent coordinate (1.91):
``2 P s'(r) e_r`` on ``u_perp`` and ``2 P`` on ``z_k``, ``P = c_p (l - 2 u3) >= 0`` the compression force (both ends,
mirror symmetry).  The normal reaction does no work on the constrained motion; it sets the friction force:
the massless end is in axial balance, ``-N n_3 + F_fr,3 = -P`` with ``F_fr = -N psi(|w|) w`` (the regularised law of
:mod:`cvtfem.elements.contact.friction`, ``w`` the slip of the end on the face), so ``N = P / (n_3 + psi w_3)``.
Friction acts through the virtual slip ``(delta u_perp - delta phi k x r, s' e_r . delta u_perp)``: on ``u_perp`` it
is ``F_fr,perp + F_fr,3 s' e_r``, on ``phi`` minus its moment about the shaft axis, on ``z_k`` nothing.

The local interface is :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact`'s (9 inputs, 6 outputs):
the input slot of the pin-end axial position carries the pin's axial stiffness ``c_p`` (N/m) instead (a
constant column of the machine's input map, so its output slot acts on nothing), the slot of its rate is unused.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.contact.friction import friction_force


@dataclass(frozen=True)
class RigidSheaveContact(SheaveContact):
    """S1's rigid contact with the sheave pairs of two shafts; ``half_length`` is ``l/2`` of the pins (m).  The
    Hertz stiffness ``c`` is infinite (no penetration: what the wedge estimate of the start reads)."""

    half_length: float = 0.0

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Local outputs ``Y`` (m, 6): generalized forces on the pin's in-plane coordinates (N, both ends), 0 in the
        axial slot, on ``z`` (N) and ``phi`` (N m) of the shaft, and the friction power (W, <= 0); with ``details``
        the per-contact quantities of :class:`SheaveContact` (``delta`` = how far the face lies inside the free
        pin end, m; ``potential`` the pin's strain energy, J).  ``reference`` is not used (one implementation)."""
        m = len(X)
        c_p, z, w_spin = X[:, 2], X[:, 3], X[:, 8]
        arm = X[:, :2] - self.centres[shafts]
        r = np.hypot(arm[:, 0], arm[:, 1])
        e_r = arm / r[:, None]
        s, ds = np.zeros(m), np.zeros(m)
        for k in (0, 1):
            sel = shafts == k
            if sel.any():
                f, fp, _ = self._profiles[k](r[sel])
                s[sel], ds[sel] = -f, -fp
        delta = self.half_length - z - s                      # > 0: the face inside the free end
        P = np.where(delta > 0, 2 * c_p * delta, 0.0)          # compression force of the pin, N
        rdot = np.sum(e_r * X[:, 4:6], axis=1)
        slip = np.zeros((m, 3))
        slip[:, 0] = X[:, 4] + w_spin * arm[:, 1]              # end velocity minus the face point's: omega k x arm
        slip[:, 1] = X[:, 5] - w_spin * arm[:, 0]
        slip[:, 2] = ds * rdot                                 # u3' - z' = s' r'
        n3 = 1.0 / np.sqrt(1.0 + ds * ds)
        unit, _ = friction_force(slip, np.ones(m), self.f0, self.v0, self.law, self.eps)   # -psi w per unit N
        N = P / (n3 - unit[:, 2])
        F_fr = N[:, None] * unit
        F = F_fr.copy()                                        # contact force on the end: N n_in + F_fr
        F[:, :2] += (N * n3 * ds)[:, None] * e_r
        F[:, 2] -= N * n3
        Q_u = (P * ds + F_fr[:, 2] * ds)[:, None] * e_r + F_fr[:, :2]
        Q_phi = arm[:, 1] * F_fr[:, 0] - arm[:, 0] * F_fr[:, 1]   # k . (-(arm x F_fr)) on the sheave
        Y = np.column_stack([2 * Q_u, np.zeros(m), 2 * P, 2 * Q_phi, 2 * np.sum(F_fr * slip, axis=1)])
        if not details:
            return Y
        return Y, {"delta": delta, "N": N, "radius": r, "slip": slip, "F_fr": F_fr, "F": F,
                   "potential": np.where(delta > 0, 2 * c_p * delta ** 2, 0.0)}
