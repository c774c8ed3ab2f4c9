"""H1 contact of single pin ends, each with its own sheave: the contact of the asymmetric chains (A1, A3, A4).

Without a symmetry plane every pin end touches the sheave on its own side of each shaft.  The contact
of one end is :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact`'s kernel without the mirror
factor 2 of the symmetric chains: an end at ``x3 < 0`` is passed in the mirrored frame (``x3 -> -x3``,
its sheave's position ``z`` counted outwards), where its sheave is the ``x3 > 0`` sheave of the kernel.
Inputs and outputs per contact as :data:`~cvtfem.elements.chain.sheave_contact.N_IN` and ``N_OUT``, for
one end.  Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.chain.sheave_contact import SheaveContact


@dataclass(frozen=True)
class EndContact:
    """H1 contact of single pin ends (mirrored to ``x3 > 0``) with the sheaves of two shafts.

    Attributes
    ----------
    pair : SheaveContact
        The kernel of the mirrored pair; this contact takes half of its outputs (one end, one sheave).
    """

    pair: SheaveContact

    @property
    def centres(self) -> np.ndarray:
        return self.pair.centres

    @property
    def faces(self) -> tuple:
        return self.pair.faces

    @property
    def c(self) -> np.ndarray:
        return self.pair.c

    @property
    def r_outer(self) -> float:
        return self.pair.r_outer

    def candidates(self, u):
        """Broad phase: ``(end, shaft)`` index arrays of the end positions ``u`` (m, 2) within the outer radius."""
        return self.pair.candidates(u)

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Local outputs (m, 6) of single ends: the force on the end (N), on ``z`` (N), on ``phi`` (N m) and the
        friction power (W); ``details`` as :meth:`SheaveContact.local` (its ``F`` is one end's already)."""
        out = self.pair.local(X, shafts, details, reference)
        if not details:
            return 0.5 * out
        Y, d = out
        return 0.5 * Y, dict(d, potential=0.5 * d["potential"])

    def local_jacobian(self, X, shafts):
        """``dY/dX`` (m, 6, 9) of :meth:`local`."""
        return 0.5 * self.pair.local_jacobian(X, shafts)
