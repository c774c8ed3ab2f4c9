"""Off-screen renderings of the running chain transmission (pyvista, imported lazily).

Model coordinates are drawn as they are: the chain plane is ``(x1, x2)`` with the driven shaft at the
origin and the driving shaft at ``(L, 0)``, ``x3`` along the shafts.  Each pulley's two sheaves are the
faces ``x3 = side (z_side + s(r))`` of :func:`~cvtfem.elements.chain.sheave_contact.face_profile` between the
shaft and the outer radius (the one at ``x3 > 0`` translucent): both at the pair's ``z`` for the symmetric
chains (S2, S3), the movable sheave at ``z`` and the fixed one at ``fixed_z`` for the whole-pin chains (A1).
Each pin is drawn along its axis from its far end (``x3 < 0``) to its near end: straight from ``-u3`` to
``u3`` (S2, S3; the S3 pin bending is not drawn), through the shape functions (1.132) of its ten
coordinates (A family: two independent ends, bent axis).  Each link is a ribbon between its two pins across
the plate pack (the pin axes at ``xi = +-PACK_FRACTION``), coloured by a per-link output, or by a per-pin or
per-pin-end output interpolated along the link and the pins.  Axial positions (pin axes, sheaves) can be
exaggerated about a reference state: ``x3 = x3_ref + axial_scale (x3 - x3_ref)``.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cvtfem.elements.chain.asymmetric import shape_functions
from cvtfem.elements.chain.sheave_contact import face_profile
from cvtfem.errors import InputError
from cvtfem.render.rotor import plotter

#: Drawn radii as fractions of the sheaves' outer radius: shaft, pin tube.
SHAFT_FRACTION, PIN_FRACTION = 0.12, 0.018
#: Half-width of a link's ribbon as a fraction of the pin's half-length (the plate pack inside the pin ends).
PACK_FRACTION = 0.8
#: Points drawn along each pin axis (a curve for the A family).
PIN_POINTS = 9


def whole_pin(model) -> bool:
    """True for the whole-pin chains (A family: each pin end its own coordinates, a fixed and a movable sheave)."""
    return hasattr(model, "fixed_z")


def pin_axis_points(model, q_chain, xi, z=None) -> np.ndarray:
    """Points (n, len(xi), 3), m, on each pin's axis at the parameters ``xi`` (-1 far end, +1 near end); S1's pin
    ends follow the sheave faces at the sheave positions ``z`` (2,) m (``model.pin_end_axial``)."""
    xi = np.asarray(xi, float)
    fam = model.family
    if whole_pin(model):
        u, w = fam.split(np.asarray(q_chain, float))
        h = shape_functions(xi, getattr(fam.chain, "base", fam.chain).l)          # (4, m)
        perp = np.einsum("im,inc->nmc", h, u)
        axial = w[0][:, None] + xi[None, :] * w[1][:, None]
    else:
        u, u3, _ = fam.split(np.asarray(q_chain, float))
        if u3 is None:                                   # S1: the ends are not coordinates
            u3 = model.pin_end_axial(q_chain, np.asarray(z, float))
        perp = np.repeat(u[:, None, :], xi.size, axis=1)
        axial = xi[None, :] * u3[:, None]
    return np.concatenate([perp, axial[..., None]], axis=2)


def sheave_positions(model, z) -> np.ndarray:
    """Axial positions (2 shafts, 2 sides), m, of the sheaves on the sides ``x3 < 0`` and ``x3 > 0`` of each
    shaft, counted outwards from ``x3 = 0``: the pair's ``z`` on both sides (S), or the movable sheave's ``z``
    on its side and the fixed sheave's position on the other (A)."""
    z = np.asarray(z, float)
    if not whole_pin(model):
        return np.column_stack([z, z])
    out = np.empty((2, 2))
    for k in range(2):
        for j, side in enumerate((-1, 1)):
            out[k, j] = z[k] if model.movable_side[k] == side else model.fixed_z[k]
    return out


@dataclass(frozen=True)
class ChainFrame:
    """What is drawn of the transmission at one state (m): pin axes (n, PIN_POINTS, 3) from the far end to the
    near end, link ribbon corners (n, 4, 3) (pin ``p`` at ``-+PACK``, pin ``p+1`` at ``+-PACK``) and the sheave
    positions (2 shafts, 2 sides) of :func:`sheave_positions`."""

    pin_axes: np.ndarray
    link_corners: np.ndarray
    sheaves: np.ndarray


def chain_frame(model, q_chain, z, reference=None, axial_scale: float = 1.0) -> ChainFrame:
    """The drawn geometry at chain coordinates ``q_chain`` and sheave positions ``z`` (2,); with ``reference``
    ``(q_chain_ref, z_ref)`` the axial coordinates are exaggerated by ``axial_scale`` about those."""
    xi = np.concatenate([np.linspace(-1.0, 1.0, PIN_POINTS), [-PACK_FRACTION, PACK_FRACTION]])
    pts = pin_axis_points(model, q_chain, xi, z)
    sheaves = sheave_positions(model, z)
    if reference is not None and axial_scale != 1.0:
        ref = pin_axis_points(model, reference[0], xi, reference[1])
        pts[..., 2] = ref[..., 2] + axial_scale * (pts[..., 2] - ref[..., 2])
        ref_sheaves = sheave_positions(model, reference[1])
        sheaves = ref_sheaves + axial_scale * (sheaves - ref_sheaves)
    pack = pts[:, PIN_POINTS:]
    nxt = np.roll(np.arange(len(pts)), -1)
    corners = np.stack([pack[:, 0], pack[:, 1], pack[nxt, 1], pack[nxt, 0]], axis=1)
    return ChainFrame(pts[:, :PIN_POINTS], corners, sheaves)


def chain_state(model, x) -> tuple[np.ndarray, np.ndarray]:
    """Chain coordinates and sheave positions ``z`` (2,) m of a full model state."""
    q = model.split(np.asarray(x, float))[0]
    nc, _, iz, _ = model._idx
    return np.array(q[:nc]), np.array(q[iz])


def sheave_surface(face, centre, z: float, side: float, r_in: float, r_out: float, n_r: int = 12,
                   n_theta: int = 96):
    """The face ``x3 = side (z + s(r))`` of one sheave as a pyvista StructuredGrid (m)."""
    import pyvista as pv

    X, Y, Z = sheave_face_points(face, centre, z, side, r_in, r_out, n_r, n_theta)
    return pv.StructuredGrid(X, Y, Z)


def sheave_face_points(face, centre, z: float, side: float, r_in: float, r_out: float, n_r: int = 12,
                       n_theta: int = 96) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid ``(x1, x2, x3)`` arrays (n_r, n_theta), m, of the face ``x3 = side (z + s(r))``."""
    r = np.linspace(r_in, r_out, n_r)
    theta = np.linspace(0.0, 2 * np.pi, n_theta)
    R, T = np.meshgrid(r, theta, indexing="ij")
    s = -face_profile(face)(R)[0]
    return centre[0] + R * np.cos(T), centre[1] + R * np.sin(T), side * (z + s)


def chain_meshes(frame: ChainFrame, pin_radius: float):
    """Pins (polylines along their axes, tubes, one polydata) and links (ribbons: one quad cell per link)."""
    import pyvista as pv

    n, m, _ = frame.pin_axes.shape
    lines = np.column_stack([np.full(n, m), np.arange(n * m).reshape(n, m)]).ravel()
    axes = pv.PolyData(frame.pin_axes.reshape(-1, 3), lines=lines)
    faces = np.column_stack([np.full(n, 4), 4 * np.arange(n)[:, None] + np.arange(4)]).ravel()
    return axes, pv.PolyData(frame.link_corners.reshape(-1, 3), faces=faces)


# ----- colours ---------------------------------------------------------------------------------------------
def colour_kind(model, spec) -> str | None:
    """How output ``spec`` colours the chain: ``"link"`` (one value per link), ``"pin"`` (per pin), ``"end"``
    (per pin end and shaft, ``contact.*``), or None (not drawable)."""
    n = model.family.n
    if spec.name.startswith("contact.") and spec.size == 2 * model.n_ends:
        return "end"
    if spec.size != n:
        return None
    doc = spec.doc.lower()
    return "link" if "link" in spec.name or doc.startswith("link") or "per link" in doc else "pin"


def check_colour(model, name: str, stored=None, option: str = "--color") -> str:
    """The unit of output ``name`` if it colours the chain (:func:`colour_kind`) and, with ``stored`` (names in a
    results file), is stored; else InputError listing the outputs that would."""
    allowed = {s.name: s.unit for s in model.output_specs if colour_kind(model, s) is not None
               and (stored is None or s.name in stored)}
    if name not in allowed:
        where = " stored in the results file" if stored is not None else ""
        raise InputError(option, name, f"must be an output{where} with one value per link, per pin or per pin end "
                         "and shaft: " + ", ".join(sorted(allowed)))
    return allowed[name]


def colour_values(model, name: str, values) -> tuple[np.ndarray, str]:
    """``(values, kind)``: per link or per pin (n,), or per pin end (n, 2) (far, near; A family) for an output
    per pin end and shaft, summed over the two shafts (a pin end touches one shaft at a time); a symmetric
    chain's contact outputs (one end per pin, the mirror end implied) become per pin."""
    spec = next(s for s in model.output_specs if s.name == name)
    kind = colour_kind(model, spec)
    v = np.asarray(values, float).reshape(-1)
    if kind == "end":
        v = v.reshape(-1, 2).sum(axis=1)
        if not whole_pin(model):
            return v, "pin"
        return v.reshape(-1, 2), "end"
    return v, kind


def colour_meshes(pins, links, values: np.ndarray, kind: str, name: str) -> None:
    """Attach ``values`` of :func:`colour_values` as scalars ``name`` to the pin polylines and link ribbons
    (links only for per-link values; the other kinds interpolate per pin or per pin end)."""
    n = len(values)
    m = pins.n_points // n
    if kind == "link":
        links.cell_data[name] = values
        return
    ends = np.column_stack([values, values]) if kind == "pin" else values            # (n, 2): far, near
    xi = np.linspace(-1.0, 1.0, m)
    pins.point_data[name] = (ends[:, :1] + (ends[:, 1:] - ends[:, :1]) * (xi + 1) / 2).ravel()
    at = ends[:, 0] + (ends[:, 1] - ends[:, 0]) * (1 + np.array([-1.0, 1.0])[:, None] * PACK_FRACTION) / 2
    nxt = np.roll(np.arange(n), -1)
    links.point_data[name] = np.column_stack([at[0], at[1], at[1][nxt], at[0][nxt]]).ravel()


def colour_limits(values) -> tuple[float, float]:
    """Finite ``(lo, hi)`` of the values (a degenerate range widened so a colour map can span it)."""
    v = np.asarray(values, float)
    lo, hi = float(np.min(v)), float(np.max(v))
    if hi - lo <= 1e-12 * max(1.0, abs(lo), abs(hi)):
        pad = max(1.0, abs(lo)) * 1e-6
        lo, hi = lo - pad, hi + pad
    return lo, hi


# ----- drawing ---------------------------------------------------------------------------------------------
def draw_frame(p, model, frame: ChainFrame, name: str, values, unit: str, clim=None) -> None:
    """Add the sheaves, shafts, pins and links of ``frame`` to plotter ``p``, coloured by ``values`` of output
    ``name`` (:func:`colour_values`) with the colour limits ``clim`` (default: the values' range)."""
    v, kind = colour_values(model, name, values)
    contact = model.contact
    r_out = contact.r_outer
    axes, links = chain_meshes(frame, pin_radius=PIN_FRACTION * r_out)
    colour_meshes(axes, links, v, kind, name)
    clim = colour_limits(v) if clim is None else clim
    bar = {"title": f"{name} ({unit})", "color": "black", "position_x": 0.25, "width": 0.5, "fmt": "%.4g"}
    p.add_mesh(links, scalars=name, cmap="viridis", clim=clim, show_edges=False, scalar_bar_args=bar)
    tubes = axes.tube(radius=PIN_FRACTION * r_out, n_sides=12, capping=True)
    if kind == "link":
        p.add_mesh(tubes, color="dimgray", smooth_shading=True)
    else:
        p.add_mesh(tubes, scalars=name, cmap="viridis", clim=clim, smooth_shading=True, show_scalar_bar=False)
    for k in range(2):
        c = contact.centres[k]
        for j, (side, opacity) in enumerate(((-1.0, 1.0), (1.0, 0.25))):
            p.add_mesh(sheave_surface(contact.faces[k], c, frame.sheaves[k, j], side, SHAFT_FRACTION * r_out, r_out),
                       color="lightsteelblue", opacity=opacity, smooth_shading=True)
        length = 2 * abs(frame.sheaves[k].max() - face_profile(contact.faces[k])(r_out)[0]) + 0.5 * r_out
        p.add_mesh(_shaft(c, SHAFT_FRACTION * r_out, length), color="slategray", smooth_shading=True)
    p.add_point_labels(np.column_stack([contact.centres, np.full(2, 0.5 * r_out)]), ["driving", "driven"],
                       font_size=14, text_color="black", shape_opacity=0.0, always_visible=True)


def set_view(p) -> None:
    """The oblique view of every rendering: the chain plane seen from the front, slightly from below."""
    p.view_vector((0.35, -0.55, 1.0), viewup=(0.0, 1.0, 0.0))
    p.camera.zoom(1.15)


def render_transmission(model, x, path: str | Path, color_by: str = "chain.link_tension", t: float = 0.0,
                        reference=None, axial_scale: float = 1.0, size: tuple[int, int] = (1400, 800),
                        title: str | None = None) -> Path:
    """PNG of the chain transmission in state ``x`` at time ``t`` (s): sheaves, shafts, pins and links,
    coloured by the model output ``color_by`` (per link, per pin, or per pin end and shaft)."""
    unit = check_colour(model, color_by)
    q_chain, z = chain_state(model, x)
    ref = None if reference is None else chain_state(model, reference)
    frame = chain_frame(model, q_chain, z, ref, axial_scale)
    p = plotter(size)
    draw_frame(p, model, frame, color_by, model.outputs(t, x)[color_by], unit)
    set_view(p)
    note = f", axial positions x{axial_scale:g}" if axial_scale != 1.0 else ""
    p.add_text(title or f"chain transmission at t = {t:.4g} s: coloured by {color_by}{note}",
               font_size=10, color="black")
    p.screenshot(str(path))
    p.close()
    return Path(path)


def _shaft(centre, radius: float, length: float):
    import pyvista as pv

    return pv.Cylinder(center=(centre[0], centre[1], 0.0), direction=(0, 0, 1), radius=radius, height=length,
                       resolution=48)
