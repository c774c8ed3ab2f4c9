"""Parameters of the band models (one frozen object, built from a scene by ``machines/cvt.py``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.band.geometry import Sheave


@dataclass(frozen=True)
class BandParams:
    """Everything a band model needs, SI units.

    Attributes
    ----------
    length, L, w : float, m
        Band length, centre distance, band half-width.
    mass : float, kg
        Band mass.
    sheaves : tuple of Sheave
        Face of the driving (0) and driven (1) pulley.
    J, m_sheave, Theta : tuple of float
        Axial inertia (kg m^2), sheave-pair mass (kg), sheave-pair transverse inertia (kg m^2) per shaft.
    c_U, c_psi : tuple of float
        Shaft radial (N/m) and tilt (N m/rad) stiffness at the sheaves (6+2n+8).
    f0, v0 : float
        Friction coefficient and saturation slip speed (m/s), eq. (1.48).
    law : str
        "linear-saturated" (1.48), "smoothed" (C1 cubic below v0) or "tanh".
    c : float, N/m^2
        Band transverse stiffness (edge force c eps per unit length), section 4.6.
    damping_ratio : float
        Damping ratio of the band compression modes (6+2n models), beta = 2 nu / omega.
    n_ritz : int
        Ritz functions per arc.
    n_gauss : int
        Gauss-Legendre nodes per arc.
    friction, damping, gyroscopic : bool
        Effects switched on.
    source_literal : bool
        Reproduce the printed factors (kappa = 1, (1.56) as printed) instead of the consistent ones (section 4.6).
    """

    length: float
    L: float
    w: float
    mass: float
    sheaves: tuple[Sheave, Sheave]
    J: tuple[float, float]
    m_sheave: tuple[float, float]
    Theta: tuple[float, float] = (0.015, 0.02)
    c_U: tuple[float, float] = (1e8, 1e8)
    c_psi: tuple[float, float] = (1e6, 1e6)
    f0: float = 0.1
    v0: float = 0.02
    law: str = "linear-saturated"
    c: float = 2e10
    damping_ratio: float = 0.05
    n_ritz: int = 5
    n_gauss: int = 32
    friction: bool = True
    damping: bool = True
    gyroscopic: bool = True
    source_literal: bool = False

    @property
    def kappa(self) -> float:
        """Number of sheaves the clamping force acts on in the generalized forces (2; source: 1)."""
        return 1.0 if self.source_literal else 2.0

    @property
    def rho(self) -> float:
        """Linear density of the band, kg/m."""
        return self.mass / self.length


def gauss_nodes(n: int):
    """Gauss-Legendre nodes and weights on [-1, 1]."""
    return np.polynomial.legendre.leggauss(n)
