"""Low-order band models of the chain CVT (spec: low-order digest section 4).

Pure kernels: geometry (4.1), the 1-DOF equilibrium (4.2), the 4-DOF model (4.3), the
transversely compressible 6+2n model (4.4) and its shaft-compliant 6+2n+8 extension (4.5).
"""
from __future__ import annotations

from typing import Any


def model_for(name: str, params: Any) -> Any:
    """The dynamic band model called ``name`` ("band-4dof", "band-6+2n", "band-6+2n+8")."""
    from cvtfem.elements.band.compressible import CompressibleBand
    from cvtfem.elements.band.fourdof import FourDofBand

    if name == "band-4dof":
        return FourDofBand(params)
    return CompressibleBand(params, shaft_compliance=name == "band-6+2n+8")


__all__ = ["model_for"]
