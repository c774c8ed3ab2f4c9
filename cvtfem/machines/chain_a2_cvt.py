"""Variant (v) on rigid shafts: the whole-pin chain with coupled pin halves in the sheave contact (A2,
chain-models-2 §3, eq. (1.210)): :class:`ChainA2CVT`.

The chain is A1 (coordinates, energies, dissipation); each pin has two halves whose axes are the pin axis
offset in-plane by ``-+ h_pin tau_p``, and each half end touches the sheave on its side of each shaft with the
refined contact H2 (:class:`~cvtfem.elements.chain.half_contact.CoupledHalvesContact`): four contact ends per
pin, ``e = 4 p + 2 half + near``.  The contact map is A1's with H2 (the end, its slope, the neighbours'
chords) plus the half sign as a constant input.  Everything else (fixed and movable sheaves, loops, start) is
:class:`~cvtfem.machines.chain_a_cvt.ChainACVT`'s.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.half_contact import CoupledHalvesContact
from cvtfem.errors import InputError
from cvtfem.machines.chain_a_cvt import ChainACVT

#: Half the distance between the centroids of the two halves (m): assumed, two 1.2 mm halves of the reference
#: 2.4 mm pin (``sqrt(12 pin_I_min / pin_area)``; the source gives no value).
H_PIN = 0.6e-3


@dataclass(frozen=True, eq=False)
class ChainA2CVT(ChainACVT):
    """A1 chain with coupled pin halves in the H2 sheave contact (A2) on two rigid shafts."""

    @property
    def n_ends(self) -> int:
        return 4 * self.family.n

    def pin_of(self, ends):
        return ends // 4

    def half_of(self, ends):
        """Half sign (-1, +1) of each contact end."""
        return np.where((ends // 2) % 2 == 1, 1.0, -1.0)

    def _candidates(self, q):
        u = self.family.split(q[:self._idx[0]])[0]
        ends = np.stack([u[0] - u[1], u[0] + u[1]] * 2, axis=1).reshape(-1, 2)
        return self.contact.candidates(ends)

    @property
    def _constants(self) -> np.ndarray:
        return np.append(super()._constants, 1.0)

    def _build_contact_map(self, ends, shafts):
        """A1's H2 map with the half sign (constant 1 times the sign) before the spin rate."""
        cols, coef = super()._build_contact_map(ends, shafts)
        sign_col = np.full((len(ends), 1, 2), 2 * self.n2 + 3)
        sign = np.zeros((len(ends), 1, 2))
        sign[:, 0, 0] = self.half_of(ends)
        return (np.concatenate([cols[:, :-1], sign_col, cols[:, -1:]], axis=1),
                np.concatenate([coef[:, :-1], sign, coef[:, -1:]], axis=1))

    @classmethod
    def from_parameters(cls, geom, *, contact: str = "hertz-refined", h_pin: float = H_PIN, **kw) -> "ChainA2CVT":
        """:meth:`ChainACVT.from_parameters` with the halves ``h_pin`` (m) apart from the pin axis; the contact
        must be the refined one (Table 1.1 (v))."""
        if contact != "hertz-refined":
            raise InputError("cvt.effects.contact", contact, "must be 'hertz-refined' for chain-A2: its halves touch "
                             "the sheaves with their biconvex end faces (Table 1.1 (v))")
        model = super().from_parameters(geom, contact=contact, **kw)
        return replace(model, contact=EndContact(CoupledHalvesContact(model.contact.pair, h_pin)))._settled()
