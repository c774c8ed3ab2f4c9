"""Equivalent radiated power (ERP) of vibrating faces: ``ERP = rho c sum_panels S |v_n|^2 / 2`` (W).

A face is a set of panels (area S, centre) whose normal displacement is a linear map of the model's DOFs,
``w = N q`` (:class:`Face`).  :func:`rigid_annulus` builds that map for a flat annular face of a rigid disc (its
axial displacement ``u3`` and tilts ``theta1, theta2``: ``w(r, a) = u3 + r (theta1 sin a - theta2 cos a)`` from the
tilt vector ``theta x r e_r``, spec §4.1); a flexible sheave gives its own panels and map (the hook for
:mod:`cvtfem.elements.sheave_solid`).  For complex amplitudes ``q`` of ``Re(q e^{i w t})`` the normal velocity is
``i w N q`` and the time-averaged ERP ``rho c sum S |v_n|^2 / 2``.  Levels in dB re 1 pW.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError

#: Air at 20 degC: density (kg/m^3) and speed of sound (m/s).
RHO_AIR, C_AIR = 1.204, 343.2
#: Reference power of the dB levels, W.
P_REF = 1e-12


@dataclass(frozen=True)
class Face:
    """Radiating panels: areas ``S`` (m^2, (p,)) and the map ``N`` ((p, n) sparse) from DOFs to normal displacement."""

    area: np.ndarray
    N: sp.csr_matrix


def annulus_panels(r_in: float, r_out: float, n_rings: int = 8, n_sectors: int = 16) -> tuple[np.ndarray, ...]:
    """Panels of the annulus ``r_in < r < r_out``: ``n_rings`` x ``n_sectors`` with equal radial and angular steps.

    Returns
    -------
    r, a, area : arrays (n_rings n_sectors,)
        Panel point (radius m, angle rad) and area (m^2).  The point sits at the ring's RMS radius, so the panel
        sum of ``S |w|^2`` is exact for ``w`` linear in x, y (rigid motion) once ``n_sectors >= 3``.
    """
    if not 0 <= r_in < r_out or not np.isfinite(r_out):
        raise InputError("face radii", (r_in, r_out), "must satisfy 0 <= r_in < r_out (m)")
    if n_rings < 1 or n_sectors < 3:
        raise InputError("face panels", (n_rings, n_sectors), "must be >= 1 ring and >= 3 sectors")
    edges = np.linspace(r_in, r_out, n_rings + 1)
    r = np.repeat(np.sqrt((edges[1:] ** 2 + edges[:-1] ** 2) / 2), n_sectors)
    a = np.tile((np.arange(n_sectors) + 0.5) * 2 * np.pi / n_sectors, n_rings)
    area = np.repeat(np.pi * (edges[1:] ** 2 - edges[:-1] ** 2) / n_sectors, n_sectors)
    return r, a, area


def rigid_annulus(n_dof: int, dofs, r_in: float, r_out: float, n_rings: int = 8, n_sectors: int = 16) -> Face:
    """The face ``r_in < r < r_out`` (:func:`annulus_panels`) of a rigid disc whose DOFs ``dofs = (u3, theta1,
    theta2)`` (indices in 0..n_dof-1) carry its motion: ``w = u3 + r (theta1 sin a - theta2 cos a)``."""
    r, a, area = annulus_panels(r_in, r_out, n_rings, n_sectors)
    u3, t1, t2 = (int(d) for d in dofs)
    p = len(area)
    rows = np.repeat(np.arange(p), 3)
    cols = np.tile([u3, t1, t2], p)
    vals = np.column_stack([np.ones(p), r * np.sin(a), -r * np.cos(a)]).ravel()
    return Face(area, sp.csr_matrix((vals, (rows, cols)), shape=(p, n_dof)))


def erp(face: Face, q: np.ndarray, omega, rho: float = RHO_AIR, c: float = C_AIR) -> np.ndarray:
    """ERP (W) of the face for complex DOF amplitudes ``q`` ((n,) or (n, l)) at frequencies ``omega`` (rad/s, (l,))."""
    q = np.asarray(q)
    w = face.N @ (q if q.ndim == 2 else q[:, None])  # (p, l) normal displacement
    vn2 = np.abs(w) ** 2 * np.asarray(omega, dtype=float) ** 2
    return 0.5 * rho * c * face.area @ vn2


def power_db(power) -> np.ndarray:
    """Power level, dB re 1 pW (-inf for 0 W)."""
    with np.errstate(divide="ignore"):
        return 10 * np.log10(np.asarray(power, dtype=float) / P_REF)
