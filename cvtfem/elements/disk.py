"""Rigid disks and CVT sheaves (spec §4, §12.3), vectorised over all disks.

Each disk sits on one node with the 6 DOF ``(u1, u2, u3, theta1, theta2, phi)``:
``M = diag(m, m, m, Id, Id, Ip)`` and the gyroscopic matrix per unit spin
speed ``G = Ip [[0, 1], [-1, 0]]`` on ``(theta1, theta2)`` (spec (1.269),
§12.3).  ``from_geometry`` computes ``m, Id, Ip`` from an axisymmetric
section (a flat disc or a CVT sheave with a conical or toroidal face and a hub)
by exact polygon integration (Green's theorem, Gauss on each edge).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.errors import InputError

_GX, _GW = np.polynomial.legendre.leggauss(6)


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of an axisymmetric body.

    Attributes
    ----------
    m : float, kg
    Id : float, kg m^2
        Diametral moment of inertia about the centre of mass.
    Ip : float, kg m^2
        Polar moment of inertia about the axis.
    zc : float, m
        Axial position of the centre of mass in the profile's z coordinate.
    """

    m: float
    Id: float
    Ip: float
    zc: float


def axisymmetric_properties(r: np.ndarray, z: np.ndarray, rho: float) -> MassProperties:
    """Mass properties of the solid of revolution of a closed (r, z) polygon.

    Uses ``int_A g dA = oint G dz`` with ``dG/dr = g`` (Green's theorem),
    integrated exactly along each straight edge by 6-point Gauss.

    Parameters
    ----------
    r, z : arrays (p,)
        Polygon vertices (radius >= 0 and axial coordinate, m), any orientation.
    rho : float
        Density, kg/m^3.

    Examples
    --------
    >>> p = axisymmetric_properties(np.array([0, 1, 1, 0.]), np.array([0, 0, 1, 1.]), 1.0)
    >>> round(p.m / np.pi, 12), round(p.Ip / np.pi, 12)
    (1.0, 0.5)
    """
    r = np.asarray(r, dtype=float)
    z = np.asarray(z, dtype=float)
    r1, z1 = np.roll(r, -1), np.roll(z, -1)
    t = (_GX + 1) / 2
    rq = r[:, None] + (r1 - r)[:, None] * t       # (edges, gauss)
    zq = z[:, None] + (z1 - z)[:, None] * t
    dz = (z1 - z)[:, None] * (_GW / 2)

    def integral(a: int, b: int) -> float:  # int r^a z^b dA
        return float(np.sum(rq ** (a + 1) / (a + 1) * zq**b * dz))

    sign = np.sign(integral(0, 0))
    scale = 2 * np.pi * rho * sign
    m = scale * integral(1, 0)
    if not m > 0:
        raise InputError("profile", m, "must enclose a positive volume (check the section geometry)")
    zc = scale * integral(1, 1) / m
    Ip = scale * integral(3, 0)
    Id = Ip / 2 + scale * (integral(1, 2) - 2 * zc * integral(1, 1) + zc**2 * integral(1, 0))
    return MassProperties(m, Id, Ip, zc)


def disc_profile(width: float, inner_diameter: float, outer_diameter: float) -> tuple[np.ndarray, np.ndarray]:
    """(r, z) polygon of a flat annular disc centred at z = 0."""
    ri, ro, h = inner_diameter / 2, outer_diameter / 2, width / 2
    return np.array([ri, ro, ro, ri]), np.array([-h, -h, h, h])


def face_arc_centre(r_rim: float, z_rim: float, r_hub: float, z_hub: float, radius: float) -> np.ndarray:
    """``(r, z)`` centre of the convex toroidal face: the arc of ``radius`` (m) through the rim point and the
    hub point of the face, bulging away from the material (towards ``+z``)."""
    chord = np.hypot(r_rim - r_hub, z_hub - z_rim)
    mid = np.array([(r_rim + r_hub) / 2, (z_rim + z_hub) / 2])
    d = np.array([r_hub - r_rim, z_hub - z_rim]) / chord
    normal = np.array([d[1], -d[0]])           # points away from the material (outward, +z side)
    return mid - normal * np.sqrt(radius ** 2 - (chord / 2) ** 2)


def sheave_profile(inner_diameter: float, outer_diameter: float, hub_diameter: float, hub_length: float,
                   rim_thickness: float, cone_angle: float, face: str = "conical",
                   torus_radius: float = 0.0, n_arc: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """(r, z) polygon of a CVT sheave: hub sleeve plus a disc with a conical or toroidal face.

    The back face is the plane z = 0; the hub sleeve occupies ``r`` in
    [inner, hub] radius and ``z`` in [-hub_length, 0]; the contact face rises
    from ``rim_thickness`` at the outer radius towards the hub at ``cone_angle``
    (rad, from the radial plane).  A toroidal face is the circular arc of radius
    ``torus_radius`` (convex) through the same end points.

    Parameters
    ----------
    inner_diameter, outer_diameter, hub_diameter, hub_length, rim_thickness : float, m
    cone_angle : float, rad
    face : {"conical", "toroidal"}
    torus_radius : float, m
        Generatrix arc radius (toroidal face only); at least half the chord.
    """
    ri, ro, rh = inner_diameter / 2, outer_diameter / 2, hub_diameter / 2
    if not 0 <= ri < rh < ro:
        raise InputError("sheave diameters", (inner_diameter, hub_diameter, outer_diameter),
                         "must satisfy inner < hub < outer diameter")
    zh = rim_thickness + (ro - rh) * np.tan(cone_angle)
    if face == "conical":
        fr, fz = np.array([ro, rh]), np.array([rim_thickness, zh])
    elif face == "toroidal":
        chord = np.hypot(ro - rh, zh - rim_thickness)
        if not torus_radius >= chord / 2:
            raise InputError("torus_radius", torus_radius, f"must be >= half the face chord, {chord / 2:g} m")
        centre = face_arc_centre(ro, rim_thickness, rh, zh, torus_radius)
        a0 = np.arctan2(rim_thickness - centre[1], ro - centre[0])
        a1 = np.arctan2(zh - centre[1], rh - centre[0])
        a = np.linspace(a0, a1 if a1 > a0 else a1 + 2 * np.pi, n_arc + 1)
        fr, fz = centre[0] + torus_radius * np.cos(a), centre[1] + torus_radius * np.sin(a)
    else:
        raise InputError("face", face, "must be 'conical' or 'toroidal'")
    r = np.concatenate([[ri, rh, rh, ro], fr, [ri]])
    z = np.concatenate([[-hub_length, -hub_length, 0.0, 0.0], fz, [zh]])
    return r, z


@dataclass(frozen=True)
class DiskFamily:
    """Rigid disks (sheaves) on nodes.

    Parameters
    ----------
    nodes : int array (n,)
        Node of each disk.
    m, Id, Ip : arrays (n,)
        Mass (kg), diametral and polar inertia (kg m^2).
    """

    nodes: np.ndarray
    m: np.ndarray
    Id: np.ndarray
    Ip: np.ndarray

    @classmethod
    def from_geometry(cls, nodes: np.ndarray, profiles: list[tuple[np.ndarray, np.ndarray]],
                      rho: np.ndarray) -> DiskFamily:
        """Disks whose mass properties come from their (r, z) section polygons."""
        props = [axisymmetric_properties(r, z, float(d)) for (r, z), d in zip(profiles, np.atleast_1d(rho))]
        return cls(np.asarray(nodes), np.array([p.m for p in props]), np.array([p.Id for p in props]),
                   np.array([p.Ip for p in props]))

    @property
    def dofs(self) -> np.ndarray:
        """Global DOF map, shape (n, 6)."""
        return np.asarray(self.nodes, dtype=np.int64)[:, None] * 6 + np.arange(6)

    def mass(self) -> np.ndarray:
        """(n, 6, 6) diagonal mass blocks."""
        d = np.stack([self.m, self.m, self.m, self.Id, self.Id, self.Ip], axis=1)
        return d[:, :, None] * np.eye(6)

    def gyroscopic(self) -> np.ndarray:
        """(n, 6, 6) skew gyroscopic blocks per unit spin speed (spec §12.3)."""
        G = np.zeros((len(self.m), 6, 6))
        G[:, 3, 4], G[:, 4, 3] = self.Ip, -self.Ip
        return G


def connection_stiffness(cu: np.ndarray, ctheta: np.ndarray, c3: np.ndarray, cphi: np.ndarray) -> np.ndarray:
    """(n, 12, 12) stiffness of elastic sheave-shaft connections (spec §6.2, §12.5).

    A linear spring between a shaft node (first 6 DOF) and the sheave's own
    node (last 6) at the sheave centre (support point ``z_i = 0``):
    radial ``cu`` (N/m), tilt ``ctheta`` (N m/rad), axial ``c3`` (N/m),
    torsional ``cphi`` (N m/rad).
    """
    k = np.stack([cu, cu, c3, ctheta, ctheta, cphi], axis=1)[:, :, None] * np.eye(6)
    return np.block([[k, -k], [-k, k]])
