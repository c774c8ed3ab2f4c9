"""Contact of single pin ends, each with its own sheave: the contact of the asymmetric chains (A1, A3, A4), H1 or H2.

Without a symmetry plane every pin end touches the sheave on its own side of each shaft.  The contact
of one end is the mirrored pair's kernel (H1 :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact` or
H2 :class:`~cvtfem.elements.chain.sheave_contact_refined.RefinedSheaveContact`) without the mirror
factor 2 of the symmetric chains: an end at ``x3 < 0`` is passed in the mirrored frame (``x3 -> -x3``,
its sheave's position ``z`` counted outwards), where its sheave is the ``x3 > 0`` sheave of the kernel.
Inputs and outputs per contact as the pair kernel's, for one end (H2: the end slope and the neighbours'
positions are inputs too; the machine maps them, :meth:`~cvtfem.machines.chain_a_cvt.ChainACVT._contact_map`).
Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

from cvtfem.elements.chain.half_contact import CoupledHalvesContact
from cvtfem.elements.chain.half_end_contact import HalfEndContact
from cvtfem.elements.chain.pair_geometry import PairGeometry
from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact


@dataclass(frozen=True)
class EndContact(PairGeometry):
    """H1 or H2 contact of single pin ends (mirrored to ``x3 > 0``) with the sheaves of two shafts.

    Attributes
    ----------
    pair : SheaveContact, RefinedSheaveContact, CoupledHalvesContact (A2: H2 at a pin half's end) or
        HalfEndContact (A5: H2 at an independent half's end)
        The kernel of the mirrored pair; this contact takes half of its outputs (one end, one sheave).
    """

    pair: SheaveContact | RefinedSheaveContact | CoupledHalvesContact | HalfEndContact

    @property
    def refined(self) -> bool:
        """The pair kernel is H2 (refined biconvex kinematics, contact digest §5), at the pin or a half of it."""
        return isinstance(self.pair, (RefinedSheaveContact, CoupledHalvesContact, HalfEndContact))

    def extra_approach(self, k: int, r) -> float:
        """Penetration beyond H1's of an untilted pin end at radius ``r`` (m) on shaft ``k`` (m; 0 for H1)."""
        return float(self.pair.extra_approach(k, r)) if self.refined else 0.0

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Local outputs of single ends (H1: (m, 6), the force on the end (N), on ``z`` (N), on ``phi`` (N m) and the
        friction power (W); H2: the pair kernel's layout); ``details`` as the pair's (its ``F`` is one end's
        already; ``moment`` too)."""
        out = self.pair.local(X, shafts, details, reference)
        if not details:
            return 0.5 * out
        Y, d = out
        return 0.5 * Y, dict(d, potential=0.5 * d["potential"])

    def local_jacobian(self, X, shafts):
        """``dY/dX`` (m, n_out, n_in) of :meth:`local`."""
        return 0.5 * self.pair.local_jacobian(X, shafts)
