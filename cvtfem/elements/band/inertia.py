"""Band inertia in the span angle: the corrected A(phi) of eq. (1.45).

Spec: low-order digest section 4.3; erratum 1 of section 8 (the printed (1.45)
misses the span-rotation term +1/6).  ``T_band = A(phi) phi_dot^2 / 2 + m sigma_dot^2 / 2``.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.band.geometry import radii


def band_inertia(phi, length: float, L: float, mass: float, r=None):
    """Band inertia ``A(phi)`` of eq. (1.45, corrected), kg m^2/rad^2.

    Parameters
    ----------
    phi : float or array (may be complex), rad
    length, L : float, m
        Band length and centre distance.
    mass : float, kg
        Band mass (``rho = mass / length``).
    r : array (2, ...), optional
        The radii ``radii(phi)[0]`` when already computed.
    """
    phi = np.asarray(phi)
    rho = mass / length
    if r is None:
        r, _, _ = radii(phi, length, L)
    p1, p2 = np.pi + 2 * phi, np.pi - 2 * phi
    arcs = (r[0] * (p1 + p1 ** 3 / 12) * (0.5 - phi / np.pi) ** 2
            + r[1] * (p2 + p2 ** 3 / 12) * (0.5 + phi / np.pi) ** 2)
    spans = L * np.cos(phi) * (1 / 6 + np.pi ** 2 / 8 - (1 - 2 / np.pi ** 2) * phi ** 2 + 2 * phi ** 4 / np.pi ** 2)
    return rho * L ** 2 * np.cos(phi) ** 2 * (arcs + spans)


def complex_step(fun, x: float, h: float = 1e-30):
    """Derivative of a real-analytic ``fun`` at real ``x`` by the complex step (exact to rounding)."""
    return np.imag(fun(x + 1j * h)) / h
