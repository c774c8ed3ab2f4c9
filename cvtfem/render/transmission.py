"""Off-screen renderings of the running chain transmission (pyvista, imported lazily).

Model coordinates are drawn as they are: the chain plane is ``(x1, x2)`` with the driven shaft at the
origin and the driving shaft at ``(L, 0)``, ``x3`` along the shafts.  Each pulley's two sheaves are the
faces ``x3 = +-(z_k + s(r))`` of :func:`~cvtfem.elements.chain.sheave_contact.face_profile` between the
shaft and the outer radius (the front one translucent), the pins are tubes from ``-u3`` to ``u3``, and each
link is a ribbon between its two pins across the plate pack, coloured by a per-link or per-pin output of
the model (for example ``chain.link_tension``, or ``contact.normal_force`` summed over both shafts).  Axial positions (pin ends, sheaves) can be exaggerated
about a reference state: ``x3 = x3_ref + axial_scale (x3 - x3_ref)``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.elements.chain.sheave_contact import face_profile
from cvtfem.errors import InputError
from cvtfem.render.rotor import plotter

#: Drawn radii as fractions of the sheaves' outer radius: shaft, pin tube.
SHAFT_FRACTION, PIN_FRACTION = 0.12, 0.018
#: Half-width of a link's ribbon as a fraction of the pin's half-length (the plate pack inside the pin ends).
PACK_FRACTION = 0.8


def axial_positions(model, x, reference=None, axial_scale: float = 1.0):
    """Pin positions ``u`` (n, 2), pin end axial positions ``u3`` (n,) and sheave positions ``z`` (2,), m,
    with the axial ones exaggerated about ``reference`` (a state of the same model)."""
    q = model.split(np.asarray(x, float))[0]
    nc, _, iz, _ = model._idx
    u, u3, _ = model.family.split(q[:nc])
    z = q[iz]
    if reference is not None and axial_scale != 1.0:
        q_ref = model.split(np.asarray(reference, float))[0]
        u3_ref, z_ref = model.family.split(q_ref[:nc])[1], q_ref[iz]
        u3 = u3_ref + axial_scale * (u3 - u3_ref)
        z = z_ref + axial_scale * (z - z_ref)
    return np.array(u), np.array(u3), np.array(z)


def sheave_surface(face, centre, z: float, side: float, r_in: float, r_out: float, n_r: int = 12,
                   n_theta: int = 96):
    """The face ``x3 = side (z + s(r))`` of one sheave as a pyvista StructuredGrid (m)."""
    import pyvista as pv

    r = np.linspace(r_in, r_out, n_r)
    theta = np.linspace(0.0, 2 * np.pi, n_theta)
    R, T = np.meshgrid(r, theta, indexing="ij")
    s = -face_profile(face)(R)[0]
    return pv.StructuredGrid(centre[0] + R * np.cos(T), centre[1] + R * np.sin(T), side * (z + s))


def chain_meshes(u, u3, pin_radius: float):
    """Pins (tubes, one polydata) and links (ribbons: one quad cell per link ``p -> p+1``)."""
    import pyvista as pv

    n = len(u)
    ends = np.empty((2 * n, 3))
    ends[0::2, :2], ends[1::2, :2] = u, u
    ends[0::2, 2], ends[1::2, 2] = -u3, u3
    lines = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1]).ravel()
    pins = pv.PolyData(ends, lines=lines).tube(radius=pin_radius, n_sides=12, capping=True)
    w = PACK_FRACTION * u3
    corners = np.empty((4 * n, 3))
    nxt = np.roll(np.arange(n), -1)
    for j, (pin, sign) in enumerate(((np.arange(n), -1), (np.arange(n), 1), (nxt, 1), (nxt, -1))):
        corners[j::4, :2] = u[pin]
        corners[j::4, 2] = sign * w[pin]
    faces = np.column_stack([np.full(n, 4), 4 * np.arange(n)[:, None] + np.arange(4)]).ravel()
    return pins, pv.PolyData(corners, faces=faces)


def render_transmission(model, x, path: str | Path, color_by: str = "chain.link_tension", t: float = 0.0,
                        reference=None, axial_scale: float = 1.0, size: tuple[int, int] = (1400, 800),
                        title: str | None = None) -> Path:
    """PNG of the chain transmission in state ``x`` at time ``t`` (s): sheaves, shafts, pins and links,
    the links (or pins) coloured by the model output ``color_by`` (one value per link or per pin)."""
    unit = check_colour(model, color_by)
    values, per_link = colour_values(model, model.outputs(t, x), color_by)
    u, u3, z = axial_positions(model, x, reference, axial_scale)
    contact = model.contact
    r_out = contact.r_outer
    pins, links = chain_meshes(u, u3, PIN_FRACTION * r_out)
    p = plotter(size)
    if per_link:
        links.cell_data[color_by] = values
    else:   # a pin's value on the two corners of each link at that pin, interpolated along the link
        links.point_data[color_by] = np.column_stack([values, values, np.roll(values, -1), np.roll(values, -1)]).ravel()
    p.add_mesh(links, scalars=color_by, cmap="viridis", show_edges=False,
               scalar_bar_args={"title": f"{color_by} ({unit})", "color": "black", "position_x": 0.25,
                                "width": 0.5, "fmt": "%.4g"})
    p.add_mesh(pins, color="dimgray", smooth_shading=True)
    for k in range(2):
        c = contact.centres[k]
        for side, opacity in ((-1.0, 1.0), (1.0, 0.25)):
            p.add_mesh(sheave_surface(contact.faces[k], c, z[k], side, SHAFT_FRACTION * r_out, r_out),
                       color="lightsteelblue", opacity=opacity, smooth_shading=True)
        length = 2 * abs(z[k] - face_profile(contact.faces[k])(r_out)[0]) + 0.5 * r_out
        p.add_mesh(_shaft(c, SHAFT_FRACTION * r_out, length), color="slategray", smooth_shading=True)
    p.add_point_labels(np.column_stack([contact.centres, np.full(2, 0.5 * r_out)]), ["driving", "driven"],
                       font_size=14, text_color="black", shape_opacity=0.0, always_visible=True)
    p.view_vector((0.35, -0.55, 1.0), viewup=(0.0, 1.0, 0.0))
    p.camera.zoom(1.15)
    note = f", axial positions x{axial_scale:g}" if axial_scale != 1.0 else ""
    p.add_text(title or f"chain transmission at t = {t:.4g} s: links coloured by {color_by}{note}",
               font_size=10, color="black")
    p.screenshot(str(path))
    p.close()
    return Path(path)


def check_colour(model, name: str) -> str:
    """``name`` if it is an output of ``model`` with one value per link, per pin, or per pin end and shaft
    (``2 n``), else InputError listing those outputs; returns the output's unit."""
    n = model.family.n
    allowed = {s.name: s.unit for s in model.output_specs if s.size in (n, 2 * n)}
    if name not in allowed:
        raise InputError("--color", name, "must be an output with one value per link, per pin or per pin end and "
                         "shaft: " + ", ".join(sorted(allowed)))
    return allowed[name]


def colour_values(model, values: dict, name: str) -> tuple[np.ndarray, bool]:
    """The values of output ``name`` per link (``True``) or per pin (``False``); per pin end and shaft
    (``contact.*``, ``2 n``) summed over the two shafts."""
    v = np.asarray(values[name], float)
    if v.size == 2 * model.family.n:
        return v.reshape(-1, 2).sum(axis=1), False
    return v, "link" in name


def _shaft(centre, radius: float, length: float):
    import pyvista as pv

    return pv.Cylinder(center=(centre[0], centre[1], 0.0), direction=(0, 0, 1), radius=radius, height=length,
                       resolution=48)
