"""What a pin-end contact wrapper takes unchanged from the mirrored-pair kernel it wraps (``self.pair``, H1
:class:`~cvtfem.elements.chain.sheave_contact.SheaveContact` or H2
:class:`~cvtfem.elements.chain.sheave_contact_refined.RefinedSheaveContact`): the sheaves' geometry and the
broad phase.  Units SI."""
from __future__ import annotations

import numpy as np


class PairGeometry:
    """Mixin of the contact wrappers (single ends, coupled halves, independent half ends) over a kernel ``pair``."""

    @property
    def centres(self) -> np.ndarray:
        """Shaft centres (2, 2), m."""
        return self.pair.centres

    @property
    def faces(self) -> tuple:
        """The two pulleys' sheave faces."""
        return self.pair.faces

    @property
    def c(self) -> np.ndarray:
        """Hertz constants (2,), N/m^1.5."""
        return self.pair.c

    @property
    def r_outer(self) -> float:
        """Outer radius of the sheaves, m."""
        return self.pair.r_outer

    def candidates(self, u):
        """Broad phase: ``(end, shaft)`` index arrays of the end positions ``u`` (m, 2) within the outer radius."""
        return self.pair.candidates(u)
