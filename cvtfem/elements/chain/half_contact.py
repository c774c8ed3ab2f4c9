"""H2 contact of one half of a whole pin (model A2, chain-models-2 §3, eq. (1.210)): the refined pin–sheave
contact of :class:`~cvtfem.elements.chain.sheave_contact_refined.RefinedSheaveContact` at an end of the half
axis ``U_p(xi) + sigma h_pin tau_p``, offset in-plane from the pin axis along the pin's section axis.

The offset turns with the pin: ``tau_p`` is the unit bisector of the two unit link chords at the pin (the
direction whose turning rate is the pin spin of the H2 kernel; (1.103) with unit chords, equal to first order
in the link strain).  All three pins' positions are shifted by the same offset, so the chords, the pin spin
and the H2 kernel's twist map are unchanged; the kernel's forces on the shifted positions act back by the
exact virtual work ``delta o = sigma h_pin (E - tau tau) / |x| . delta x`` (the spec's "exact" transfer), and
the rates of the shifted positions are ``v + o'`` with the same map, so the friction power of the kernel is
the work rate of the generalized forces and the normal forces are the gradient of its potential.

Local inputs per contact: the refined kernel's positions (10: pins ``p-1, p, p+1`` in-plane, ``u3``, end
slope, ``z``), their rates (10), the half sign ``sigma`` (+-1; a constant the machine's contact map supplies)
and the shaft spin rate; outputs as the kernel's.  Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.chain.pair_geometry import PairGeometry
from cvtfem.elements.chain.sheave_contact import central_local_jacobian
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.errors import InputError


def _unit(v):
    """``(v / |v|, |v|)`` of in-plane vectors (m, 2)."""
    n = np.sqrt(np.sum(v * v, axis=1))
    return v / n[:, None], n


def _project(e, a):
    """``(E - e e) . a`` of in-plane vectors (m, 2)."""
    return a - np.sum(e * a, axis=1)[:, None] * e


def half_offset(um, up, un, sigma, h_pin):
    """Offset ``o = sigma h_pin tau`` (m, 2) of a half axis and the map ``d o / d(u_m, u_p, u_n)`` as three
    functions of a displacement (m, 2) each: the unit bisector ``tau`` of the unit chords ``e_p = (u_p - u_m)/|.|``,
    ``e_n = (u_n - u_p)/|.|``, ``d tau = (E - tau tau)/|x| . (d e_p + d e_n)``, ``d e = (E - e e)/|c| . d c``."""
    ep, lp = _unit(up - um)
    en, ln = _unit(un - up)
    tau, nx = _unit(ep + en)
    k = (sigma * h_pin / nx)[:, None]

    def d_rear(a):                      # chord (u_p - u_m) changed by a
        return k * _project(tau, _project(ep, a) / lp[:, None])

    def d_front(a):                     # chord (u_n - u_p) changed by a
        return k * _project(tau, _project(en, a) / ln[:, None])
    return sigma[:, None] * h_pin * tau, d_rear, d_front


@dataclass(frozen=True)
class CoupledHalvesContact(PairGeometry):
    """H2 contact of the two coupled halves of whole pins (A2) with the sheaves of two shafts, mirrored pair.

    Attributes
    ----------
    pair : RefinedSheaveContact
        The kernel at the half's end (with slopes: the A1 pin's end slope; ``c`` is one half end's Hertz constant).
    h_pin : float, m
        Half the distance between the section centroids of the two halves (spec §3).
    """

    pair: RefinedSheaveContact
    h_pin: float

    def __post_init__(self):
        if not self.h_pin > 0:
            raise InputError("h_pin", self.h_pin, "must be > 0 (half the distance of the halves' centroids, m)")

    @property
    def c(self):
        """Hertz constant of a whole pin end (N/m^1.5): both halves at one penetration, ``2 c_half``."""
        return 2 * self.pair.c

    @property
    def n_pos(self) -> int:
        return self.pair.n_pos

    @property
    def n_in(self) -> int:
        """The kernel's inputs and the half sign (before the spin rate)."""
        return self.pair.n_in + 1

    def extra_approach(self, k: int, r):
        return self.pair.extra_approach(k, r)

    def shifted(self, X):
        """The kernel's inputs (m, n_in - 1) at the half axis, and the offset map of :func:`half_offset`."""
        n = self.n_pos
        P, V, sigma = X[:, :n], X[:, n:2 * n], X[:, 2 * n]
        o, d_rear, d_front = half_offset(P[:, 0:2], P[:, 2:4], P[:, 4:6], sigma, self.h_pin)
        od = d_rear(V[:, 2:4] - V[:, 0:2]) + d_front(V[:, 4:6] - V[:, 2:4])
        Xk = np.concatenate([P, V, X[:, -1:]], axis=1)
        for j in (0, 2, 4):
            Xk[:, j:j + 2] += o
            Xk[:, n + j:n + j + 2] += od
        return Xk, d_rear, d_front

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Outputs of the kernel at the half axis, its forces on the shifted positions mapped back by the
        virtual work of the offset (the friction power and ``details`` as the kernel's)."""
        Xk, d_rear, d_front = self.shifted(X)
        out = self.pair.local(Xk, shafts, details, reference)
        Y = (out[0] if details else out).copy()
        F = Y[:, 0:2] + Y[:, 2:4] + Y[:, 4:6]                  # total in-plane force on the shifted positions
        # o = o(u_p - u_m, u_n - u_p): F . delta o with delta o = d_rear(du_p - du_m) + d_front(du_n - du_p)
        gr, gf = _adjoint(d_rear, F), _adjoint(d_front, F)
        Y[:, 0:2] -= gr
        Y[:, 2:4] += gr - gf
        Y[:, 4:6] += gf
        return (Y, out[1]) if details else Y

    def local_jacobian(self, X, shafts):
        """``dY/dX`` (m, n_out, n_in) by central differences (the half sign's column is not used)."""
        scale = np.full(self.n_in, 1e-6)
        scale[:self.n_pos] = 1e-9
        scale[-1] = 1e-5
        return central_local_jacobian(self.local, X, shafts, scale, self.pair.n_out)


def _adjoint(d, F):
    """``g`` with ``g . a = F . d(a)`` for all ``a`` (m, 2): the map ``d`` is linear per contact."""
    ex = d(np.tile([1.0, 0.0], (len(F), 1)))
    ey = d(np.tile([0.0, 1.0], (len(F), 1)))
    return np.column_stack([np.sum(F * ex, axis=1), np.sum(F * ey, axis=1)])
