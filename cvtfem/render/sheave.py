"""Off-screen renderings of a solid sheave: a mode of one nodal-diameter harmonic or a static deflection
(pyvista, imported lazily).

The section's triangles are revolved into wedges; the displacement of harmonic ``n`` is
``U(r, z)`` times ``cos n theta`` / ``sin n theta`` per component (:mod:`cvtfem.elements.sheave_solid`),
exaggerated so that the largest displacement is a fraction of the outer radius, coloured by its magnitude
over the undeformed outline.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.elements.sheave_solid import HarmonicSheave
from cvtfem.render.rotor import plotter


def revolved_grid(model: HarmonicSheave, u: np.ndarray, n_theta: int = 96):  # noqa: ANN201 - pyvista grid
    """Wedge grid of the revolved section with point data ``displacement`` (m, Cartesian) of the amplitudes
    ``u`` (section DOFs) of the model's harmonic."""
    import pyvista as pv

    mesh = model.basis.mesh
    nv = model.basis.nodal_dofs.shape[1]                 # the vertices come first among the mesh's points
    r, z = mesh.p[0, :nv], mesh.p[1, :nv]
    th = 2 * np.pi * np.arange(n_theta) / n_theta
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    ur, ut, uz = (u[model.basis.nodal_dofs[k]] for k in range(3))
    n = model.n
    even, odd = (np.cos(n * th)[:, None], np.sin(n * th)[:, None]) if model.family == "cos" else \
        (np.sin(n * th)[:, None], np.cos(n * th)[:, None])
    a_r, a_t, a_z = ur * even, ut * odd, uz * even                        # (n_theta, nv)
    points = np.column_stack([(r * c).ravel(), (r * s).ravel(), np.tile(z, n_theta)])
    disp = np.column_stack([(a_r * c - a_t * s).ravel(), (a_r * s + a_t * c).ravel(), a_z.ravel()])
    lo = np.arange(n_theta)[:, None] * nv
    hi = ((np.arange(n_theta) + 1) % n_theta)[:, None] * nv
    t = mesh.t
    corners = [(lo + t[k]).ravel() for k in range(3)] + [(hi + t[k]).ravel() for k in range(3)]
    cells = np.hstack([np.full((n_theta * t.shape[1], 1), 6), np.column_stack(corners)])
    grid = pv.UnstructuredGrid(cells.ravel(), np.full(len(cells), pv.CellType.WEDGE, dtype=np.uint8), points)
    grid.point_data["displacement"] = disp
    return grid


def render_sheave(model: HarmonicSheave, u: np.ndarray, path: str | Path, title: str = "",
                  fraction: float = 0.12, size: tuple[int, int] = (1000, 800)) -> Path:
    """PNG of the sheave deformed by ``u`` (exaggerated so that the largest displacement is ``fraction`` of the
    outer radius), cut open along a diameter to show the section, coloured by the displacement magnitude,
    over the undeformed outline."""
    grid = revolved_grid(model, u)
    mag = np.linalg.norm(grid.point_data["displacement"], axis=1)
    peak = max(mag.max(), 1e-300)
    grid.point_data["|u| / max"] = mag / peak
    warped = grid.warp_by_vector("displacement", factor=fraction * model.section.outer_radius / peak)
    half = warped.clip(normal=(0.0, 1.0, 0.0), origin=(0.0, 0.0, 0.0), invert=False).extract_surface(algorithm=None)
    outline = grid.extract_surface(algorithm=None).extract_feature_edges(30)
    p = plotter(size)
    p.add_mesh(outline, color="gray", opacity=0.35)
    p.add_mesh(half, scalars="|u| / max", cmap="viridis", smooth_shading=True,
               scalar_bar_args={"title": "|u| / max", "color": "black"})
    p.view_vector((0.3, -1.0, 0.4), viewup=(0.0, 0.0, 1.0))
    p.camera.zoom(1.3)
    p.add_text(f"{title}\ndisplacement exaggerated to {fraction:.0%} of the outer radius", font_size=10,
               color="black")
    p.screenshot(str(path))
    p.close()
    return Path(path)
