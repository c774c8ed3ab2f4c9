"""Off-screen renderings of rotors and their mode shapes (pyvista, imported lazily).

The shaft is drawn as tubes along the axis (e3 is the rendering x axis, u1 the
rendering z axis (up), u2 the rendering y axis), disks as cylinders whose radius and
width follow from their mass properties (uniform steel disc: ``Ip = m r^2 / 2``),
bearings as cones below their node.  A mode shape is the real part of the
complex shape at a phase angle, interpolated inside elements with the
Timoshenko shape functions; the whirl orbits of the nodes are drawn as lines.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.elements.beam import shape_functions
from cvtfem.machines.rotor import RotorModel
from cvtfem.modal.eigen import Modes

#: Density used to turn disk mass properties into a drawn width, kg/m^3.
DRAW_RHO = 7800.0
_SAMPLES = 9


def _to_view(z: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Model (u1, u2, z) -> rendering coordinates (axis along x, u1 up)."""
    return np.column_stack([z, u2, u1])


def centerline(model: RotorModel, shape: np.ndarray | None = None, phase: float = 0.0,
               scale: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Sampled shaft axis: points (p, 3) in view coordinates and the element of each point.

    ``shape`` is a complex mode shape (n_dof,); the drawn displacement is
    ``scale * Re(shape e^{i phase})`` (m).
    """
    b = model.beam
    eta = np.linspace(0, 1, _SAMPLES)
    z0 = model.z[b.nodes[:, 0]][:, None] + b.L[:, None] * eta[None, :]
    if shape is None:
        d = np.zeros(model.n_dof)
    else:
        d = scale * np.real(shape * np.exp(1j * phase))
    q = d[b.dofs]                                            # (n_el, 12)
    Nw, _, _, _ = shape_functions(eta, b.L, b.phi)           # (n_el, g, 4)
    u1 = np.einsum("ngi,ni->ng", Nw, q[:, [0, 4, 6, 10]])
    u2 = np.einsum("ngi,ni->ng", Nw, q[:, [1, 3, 7, 9]] * np.array([1, -1, 1, -1]))
    pts = _to_view(z0.ravel(), u1.ravel(), u2.ravel())
    return pts, np.repeat(np.arange(len(b.L)), _SAMPLES)


def _disk_size(m: float, Ip: float) -> tuple[float, float]:
    r = np.sqrt(2 * Ip / m)
    return r, m / (DRAW_RHO * np.pi * r**2)


def _scene_meshes(model: RotorModel, shape: np.ndarray | None, phase: float, scale: float) -> list:
    """pyvista meshes (shaft tubes, disks, bearings) for one displaced state."""
    import pyvista as pv

    pts, elem = centerline(model, shape, phase, scale)
    meshes = []
    b = model.beam
    for e in range(len(b.L)):
        line = pv.lines_from_points(pts[elem == e])
        meshes.append(("shaft", line.tube(radius=b.Do[e] / 2, n_sides=24, capping=True)))
    d = np.zeros(model.n_dof) if shape is None else scale * np.real(shape * np.exp(1j * phase))
    profiles = model.profiles or (None,) * len(model.disks.m)
    for node, m, Ip, prof in zip(model.disks.nodes, model.disks.m, model.disks.Ip, profiles):
        u1, u2, _, t1, t2, _ = d[6 * node:6 * node + 6]
        axis = np.array([1.0, -t1, t2])     # tilted normal: (z, u2, u1) view components of e3 + theta x e3
        centre = _to_view(np.array([model.z[node]]), np.array([u1]), np.array([u2]))[0]
        if prof is None:
            r, w = _disk_size(m, Ip)
            meshes.append(("disk", pv.Cylinder(center=centre, direction=axis, radius=r, height=w, resolution=48)))
        else:
            meshes.append(("disk", _revolved(prof, centre, axis)))
    for node in model.bearings.nodes if shape is None else ():   # bearings stay on the ground
        u1, u2 = d[6 * node], d[6 * node + 1]
        r = b.Do[min(node, len(b.L) - 1)]
        tip = _to_view(np.array([model.z[node]]), np.array([u1 - r / 2]), np.array([u2]))[0]
        meshes.append(("bearing", pv.Cone(center=tip - np.array([0, 0, r]), direction=(0, 0, 1), height=2 * r,
                                          radius=r, resolution=24)))
    return meshes


def _revolved(profile: tuple[np.ndarray, np.ndarray], centre: np.ndarray, axis: np.ndarray):  # noqa: ANN202
    """Solid of revolution of an (r, z) section polygon about ``axis`` through ``centre``."""
    import pyvista as pv

    r, z = profile
    pts = np.column_stack([np.append(z, z[0]), np.append(r, r[0]), np.zeros(len(r) + 1)])
    grid = pv.lines_from_points(pts).extrude_rotate(resolution=72, rotation_axis=(1, 0, 0), capping=False)
    grid = grid.compute_normals(split_vertices=True, feature_angle=40.0, auto_orient_normals=True)
    a = axis / np.linalg.norm(axis)
    rot = np.eye(3)
    if not np.allclose(a, [1.0, 0.0, 0.0]):
        v = np.cross([1.0, 0.0, 0.0], a)
        c = a[0]
        vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        rot = np.eye(3) + vx + vx @ vx / (1 + c)
    grid.points = grid.points @ rot.T + centre
    return grid


_COLORS = {"shaft": "lightsteelblue", "disk": "goldenrod", "bearing": "dimgray"}


def plotter(size: tuple[int, int]):  # noqa: ANN202
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    pv.OFF_SCREEN = True
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)  # no "bad X server" warning without a display
    p = pv.Plotter(off_screen=True, window_size=size)
    p.set_background("white")
    return p


def render_rotor(model: RotorModel, path: str | Path, size: tuple[int, int] = (1200, 600)) -> Path:
    """PNG of the undeformed rotor: shaft, disks, bearings."""
    p = plotter(size)
    for kind, mesh in _scene_meshes(model, None, 0.0, 0.0):
        p.add_mesh(mesh, color=_COLORS[kind], smooth_shading=True)
    p.view_isometric()
    p.camera.zoom(1.25)
    p.add_text("rotor: shaft (blue), disks (gold), bearings (grey)", font_size=10, color="black")
    p.screenshot(str(path))
    p.close()
    return Path(path)


def mode_scale(model: RotorModel, shape: np.ndarray, fraction: float = 0.08) -> float:
    """Scale so that the largest lateral displacement is ``fraction`` of the shaft length."""
    kind = model.dof_kind[:model.n_node_dofs]                 # node DOFs only (not flexible sheaves' modes)
    lateral = np.abs(shape[:model.n_node_dofs][(kind == 0) | (kind == 1)])
    return fraction * float(model.z.max()) / max(float(lateral.max()), 1e-300)


def _draw_mode(p, model: RotorModel, modes: Modes, k: int, phase: float, scale: float) -> None:  # noqa: ANN001
    import pyvista as pv

    shape = modes.shapes[:, k]
    for kind, mesh in _scene_meshes(model, None, 0.0, 0.0):
        p.add_mesh(mesh, color=_COLORS[kind], opacity=0.15)
    for kind, mesh in _scene_meshes(model, shape, phase, scale):
        p.add_mesh(mesh, color="firebrick" if kind == "shaft" else _COLORS[kind], smooth_shading=True)
    # whirl orbits of the nodes over one period
    ph = np.linspace(0, 2 * np.pi, 65)
    nodes = np.arange(model.n_shaft_nodes)
    for n in nodes:
        u = scale * np.real(np.outer(np.exp(1j * ph), shape[6 * n:6 * n + 2]))
        orbit = _to_view(np.full(len(ph), model.z[n]), u[:, 0], u[:, 1])
        p.add_mesh(pv.lines_from_points(orbit), color="black", line_width=2)
    text = (f"mode {k}: {modes.wd[k]:.2f} rad/s ({modes.wd[k] / (2 * np.pi):.2f} Hz), {modes.whirl[k]}, "
            f"zeta {modes.damping_ratio[k]:.3g}, at {modes.speed * 30 / np.pi:.0f} rpm\n"
            "red: deformed (scaled), faint: undeformed, black: whirl orbits")
    p.add_text(text, font_size=10, color="black")


def render_mode(model: RotorModel, modes: Modes, k: int, path: str | Path, scale: float | None = None,
                phase: float = 0.0, size: tuple[int, int] = (1200, 700)) -> Path:
    """PNG of mode ``k``: deformed (red) over the undeformed rotor (faint), with node orbits."""
    p = plotter(size)
    s = mode_scale(model, modes.shapes[:, k]) if scale is None else scale
    _draw_mode(p, model, modes, k, phase, s)
    p.view_isometric()
    p.camera.zoom(1.6)
    p.screenshot(str(path))
    p.close()
    return Path(path)


def write_mode_gif(model: RotorModel, modes: Modes, k: int, path: str | Path, frames: int = 24,
                   scale: float | None = None, size: tuple[int, int] = (800, 480)) -> Path:
    """Animated GIF of mode ``k`` over one period (frames rendered off-screen, written with Pillow)."""
    from PIL import Image

    s = mode_scale(model, modes.shapes[:, k]) if scale is None else scale
    images = []
    for phase in np.linspace(0, 2 * np.pi, frames, endpoint=False):
        p = plotter(size)
        _draw_mode(p, model, modes, k, phase, s)
        p.view_isometric()
        p.camera.zoom(1.6)
        images.append(Image.fromarray(p.screenshot(return_img=True)))
        p.close()
    images[0].save(path, save_all=True, append_images=images[1:], duration=80, loop=0)
    return Path(path)


def write_mode_vtu(model: RotorModel, modes: Modes, path: str | Path) -> Path:
    """VTU (meshio) of the shaft line with every mode as point data, for ParaView.

    Point data ``mode_K_real`` / ``mode_K_imag`` hold the nodal displacement
    vectors (view coordinates, m per unit modal amplitude); field data hold the
    frequencies.
    """
    import meshio

    n_nodes = model.n_shaft_nodes
    pts = _to_view(model.z[:n_nodes], np.zeros(n_nodes), np.zeros(n_nodes))
    cells = [("line", np.stack([np.arange(n_nodes - 1), np.arange(1, n_nodes)], axis=1))]
    data = {}
    for k in range(modes.shapes.shape[1]):
        x = modes.shapes[:6 * n_nodes, k].reshape(n_nodes, 6)
        vec = _to_view(x[:, 2], x[:, 0], x[:, 1])
        data[f"mode_{k}_real"], data[f"mode_{k}_imag"] = vec.real, vec.imag
    mesh = meshio.Mesh(pts, cells, point_data=data,
                       field_data={"wd_rad_s": np.asarray(modes.wd), "speed_rad_s": np.array([modes.speed])})
    meshio.write(path, mesh)
    return Path(path)
