"""Section meshes (quadratic triangles, curved boundaries) and their meshio files in ``meshes/``.

``disk_mesh`` (solid circle), ``annulus_mesh`` (hollow circle), ``rectangle_mesh``
and ``pin_mesh`` (a chain rocker-pin-like profile: a bar with two circular
rolling faces, star-shaped about its centre) return ``skfem.MeshTri2``;
``load_section_mesh`` reads any meshio file with ``triangle``/``triangle6`` cells.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from cvtfem.errors import InputError

#: The repository's mesh folder (present in a source checkout).
MESH_DIR = Path(__file__).resolve().parents[2] / "meshes"


def _to_p2(m1, project=None):  # noqa: ANN001, ANN202 - skfem meshes
    """Quadratic mesh from a linear one; ``project(points) -> points`` moves boundary mid-nodes."""
    from skfem import MeshTri2

    M = MeshTri2.from_mesh(m1)
    if project is None:
        return M
    D = M.dofs.get_facet_dofs(M.boundary_facets()).flatten()
    doflocs = M.doflocs.copy()
    doflocs[:, D] = project(doflocs[:, D])
    return replace(M, doflocs=doflocs)


def disk_mesh(radius: float = 1.0, nrefs: int = 4):  # noqa: ANN201
    """Solid circle of ``radius`` (m), boundary nodes exactly on the circle."""
    from skfem import MeshTri1

    m = MeshTri1.init_circle(nrefs=nrefs)
    m = m.scaled(radius) if radius != 1.0 else m
    return _to_p2(m, lambda p: p / np.linalg.norm(p, axis=0) * radius)


def annulus_mesh(r_inner: float, r_outer: float, n_radial: int = 6, n_theta: int = 96):  # noqa: ANN201
    """Hollow circle: structured polar grid, both boundaries exactly circular."""
    from skfem import MeshTri1

    if not 0 < r_inner < r_outer:
        raise InputError("r_inner", r_inner, f"must satisfy 0 < r_inner < r_outer = {r_outer}")
    r = np.linspace(r_inner, r_outer, n_radial + 1)
    th = np.linspace(0, 2 * np.pi, n_theta, endpoint=False)
    R, T = np.meshgrid(r, th, indexing="ij")
    p = np.array([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel()])
    idx = np.arange(p.shape[1]).reshape(n_radial + 1, n_theta)
    a, b = idx[:-1], idx[1:]
    a1, b1 = np.roll(a, -1, axis=1), np.roll(b, -1, axis=1)
    t = np.hstack([np.array([a.ravel(), b.ravel(), b1.ravel()]), np.array([a.ravel(), b1.ravel(), a1.ravel()])])
    m = MeshTri1(p, t)

    def project(q: np.ndarray) -> np.ndarray:
        rr = np.linalg.norm(q, axis=0)
        target = np.where(abs(rr - r_inner) < abs(rr - r_outer), r_inner, r_outer)
        return q / rr * target

    return _to_p2(m, project)


def rectangle_mesh(width: float, height: float, n: int = 16):  # noqa: ANN201
    """Rectangle ``width x height`` (m) centred at the origin."""
    from skfem import MeshTri1

    nx = max(2, int(round(n * width / min(width, height))))
    ny = max(2, int(round(n * height / min(width, height))))
    m = MeshTri1.init_tensor(np.linspace(-width / 2, width / 2, nx + 1), np.linspace(-height / 2, height / 2, ny + 1))
    return _to_p2(m)


def pin_boundary_radius(theta: np.ndarray, half_length: float, half_height: float, face_radius: float) -> np.ndarray:
    """Distance from the centre to the pin outline along direction ``theta``.

    Outline: flat sides ``|y| = half_height``; the ends are arcs of radius
    ``face_radius`` centred on the x axis so that they pass through
    ``(+-half_length, 0)``.
    """
    c, s = np.cos(theta), np.sin(theta)
    xc = half_length - face_radius                    # arc centre of the +x face (mirror for -x)
    sgn = np.where(c >= 0, 1.0, -1.0)
    # ray t (c, s) on circle |(t c - sgn xc, t s)| = R
    bq = -2 * sgn * xc * c
    cq = xc**2 - face_radius**2
    t_arc = (-bq + np.sqrt(bq**2 - 4 * cq)) / 2
    t_flat = np.where(np.abs(s) > 1e-15, half_height / np.maximum(np.abs(s), 1e-15), np.inf)
    return np.minimum(t_arc, t_flat)


def pin_mesh(half_length: float = 3.0e-3, half_height: float = 1.2e-3, face_radius: float = 4.0e-3,
             nrefs: int = 4):  # noqa: ANN201
    """Rocker-pin-like profile: the unit-disk mesh mapped radially onto the outline."""
    from skfem import MeshTri1

    if not face_radius >= half_length or not 0 < half_height < half_length:
        raise InputError("pin geometry", (half_length, half_height, face_radius),
                         "needs 0 < half_height < half_length <= face_radius")

    def scale(q: np.ndarray) -> np.ndarray:
        return q * pin_boundary_radius(np.arctan2(q[1], q[0]), half_length, half_height, face_radius)

    m = MeshTri1.init_circle(nrefs=nrefs)
    m = replace(m, doflocs=scale(m.p))

    def project(q: np.ndarray) -> np.ndarray:
        return q / np.linalg.norm(q, axis=0) * pin_boundary_radius(np.arctan2(q[1], q[0]), half_length,
                                                                    half_height, face_radius)

    return _to_p2(m, project)


def load_section_mesh(path: str | Path):  # noqa: ANN201
    """Read a section mesh with meshio (``triangle6`` -> MeshTri2, ``triangle`` -> MeshTri1)."""
    import meshio
    from skfem import MeshTri1

    path = Path(path)
    if not path.is_file():
        raise InputError("mesh", str(path), "must be an existing mesh file meshio can read")
    mesh = meshio.read(path)
    pts = mesh.points[:, :2].T
    for block in mesh.cells:
        if block.type == "triangle6":
            from skfem.io.meshio import from_meshio

            return from_meshio(mesh)
        if block.type == "triangle":
            return MeshTri1(pts, block.data.T)
    raise InputError("mesh", str(path), "must contain triangle or triangle6 cells",
                     f"found {[b.type for b in mesh.cells]}")


__all__ = ["MESH_DIR", "annulus_mesh", "disk_mesh", "load_section_mesh", "pin_mesh", "rectangle_mesh"]
