"""Off-screen renderings of the running chain transmission (pyvista, imported lazily).

Model coordinates are drawn as they are: the chain plane is ``(x1, x2)`` with the driven shaft at the
origin and the driving shaft at ``(L, 0)``, ``x3`` along the shafts.  Each pulley's two sheaves are the
faces ``x3 = side (z_side + s(r))`` of :func:`~cvtfem.elements.chain.sheave_contact.face_profile` between the
shaft and the outer radius (the one at ``x3 > 0`` translucent): on rigid shafts both at the pair's ``z`` for the
symmetric chains (S2, S3), the movable sheave at ``z`` and the fixed one at ``fixed_z`` for the whole-pin chains
(A family).  On elastic shafts (:mod:`~cvtfem.machines.chain_cvt_elastic`) each face is that surface at its
reference position ``z_ref`` in the frame of its sheave, carried by the sheave's translation ``a`` and tilt
``theta`` about its pivot ``o`` exactly as the contacts see it (``X = o + (I - theta x)(x - o - a)``, inverted),
and each shaft is the polyline of its displaced beam nodes, with its two bearings at their nodes.  Each pin is
drawn along its axis from its far end (``x3 < 0``) to its near end: from ``-u3`` to ``u3``, straight (S2) or bent
by the parabola ``h_1(xi) u'_p`` (S3), through the shape functions (1.132) of its ten coordinates (A family: two
independent ends, bent axis); A5 draws each pin half so (2 axes per pin, half - then half +).  Each link is a
ribbon across the plate pack (the axes at ``xi = +-PACK_FRACTION``) between its two pins, or A5's half - of pin
``p`` and half + of pin ``p + 1``, coloured by a per-link output, or by a per-pin, per-half or per-pin-end output
interpolated along the link and the axes; coloured by a per-plate output, the plates are drawn instead (quads
parallel to the chain plane between their stations on the two axes).  Axial positions (the ``x3`` of every drawn
point: pins, plates, faces, shafts, bearings) can be exaggerated about a reference state:
``x3 = x3_ref + axial_scale (x3 - x3_ref)``; in-plane positions are drawn as they are.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cvtfem.elements.chain.asymmetric import shape_functions
from cvtfem.elements.chain.geometry import h1
from cvtfem.elements.chain.halves import ChainA5
from cvtfem.elements.chain.sheave_contact import face_profile
from cvtfem.errors import InputError
from cvtfem.render.rotor import plotter

#: Drawn radii as fractions of the sheaves' outer radius: shaft, pin tube, bearing (elastic shafts).
SHAFT_FRACTION, PIN_FRACTION, BEARING_FRACTION = 0.12, 0.018, 0.2
#: Half-width of a link's ribbon as a fraction of the pin's half-length (the plate pack inside the pin ends).
PACK_FRACTION = 0.8
#: Points drawn along each pin axis (a curve for the A family).
PIN_POINTS = 9
#: Drawn width of a plate across its link, as a fraction of the distance of its end centres.
PLATE_HEIGHT = 0.45
#: Radial and angular grid points of a drawn sheave face.
FACE_GRID = (12, 96)


def whole_pin(model) -> bool:
    """True for the chains whose pin ends are coordinates (A family: a fixed and a movable sheave per shaft)."""
    return hasattr(model, "fixed_z")


def halves(model) -> bool:
    """True for the chain of independent pin halves (A5): each half is drawn as its own axis."""
    return isinstance(getattr(model.family, "chain", None), ChainA5)


def elastic(model) -> bool:
    """True for a transmission on elastic shafts (beam FE shafts with the sheaves on their nodes)."""
    return hasattr(model, "structure")


def pin_axis_points(model, q_chain, xi, z=None) -> np.ndarray:
    """Points (N, len(xi), 3), m, on each drawn axis at the parameters ``xi`` (-1 far end, +1 near end): one per
    pin, or per pin half of A5 (pin-major: ``2 p + half``, half 0 = ``p-``); S1's pin ends follow the sheave faces
    at the sheave positions ``z`` (2,) m (``model.pin_end_axial``)."""
    xi = np.asarray(xi, float)
    fam = model.family
    q_chain = np.asarray(q_chain, float)
    if halves(model):
        u, w, _ = fam.split(q_chain)                                     # (2, 4, n, 2), (2, 2, n)
        h = shape_functions(xi, fam.chain.l)
        perp = np.einsum("im,hinc->nhmc", h, u).reshape(-1, xi.size, 2)
        axial = (w[:, 0, :, None] + xi * w[:, 1, :, None]).transpose(1, 0, 2).reshape(-1, xi.size)
    elif whole_pin(model):
        u, w = fam.split(q_chain)
        h = shape_functions(xi, getattr(fam.chain, "base", fam.chain).l)          # (4, m)
        perp = np.einsum("im,inc->nmc", h, u)
        axial = w[0][:, None] + xi[None, :] * w[1][:, None]
    else:
        u, u3, up = fam.split(q_chain)
        if u3 is None:                                   # S1: the ends are not coordinates
            u3 = model.pin_end_axial(q_chain, np.asarray(z, float))
        perp = np.repeat(u[:, None, :], xi.size, axis=1)
        if up is not None:                               # S3: the parabola h_1(xi) u'_p through the ends (1.96b)
            perp = perp + h1(xi, fam.geom.l)[None, :, None] * up[:, None, :]
        axial = xi[None, :] * u3[:, None]
    return np.concatenate([perp, axial[..., None]], axis=2)


def link_axes(model) -> np.ndarray:
    """(n, 2) drawn axes each link joins: pins ``p`` and ``p + 1``, or A5's half - of ``p`` and half + of ``p + 1``."""
    p = np.arange(model.family.n)
    nxt = np.roll(p, -1)
    return np.column_stack([2 * p, 2 * nxt + 1]) if halves(model) else np.column_stack([p, nxt])


def plate_outputs(model) -> int | None:
    """Size of the family's per-plate outputs (links x Kmax for A1 and A5, one per plate for A3/A4), None for the
    chains without plates (S)."""
    chain = getattr(model.family, "chain", None)
    if halves(model):
        return chain.plate_w.size
    if not whole_pin(model):
        return None
    base = getattr(chain, "base", chain)
    return base.plate_mask.size if base is chain else chain.plate_link.size


def plate_stations(model, q_chain):
    """``(ends, slot, size)`` of the chains that have plates (A family, A5), else None: the two end centres
    ``(P, 2, 3)`` m of every plate on the axes its link joins (A1, A3/A4: at the plate's station ``xi^k`` on both
    pins; A5: at the pack coordinate plus the plate's offset ``d^k`` on each half, (1.211)), the index of each
    plate in the family's per-plate outputs and those outputs' size."""
    fam, q = model.family, np.asarray(q_chain, float)
    chain, size = getattr(fam, "chain", None), plate_outputs(model)
    if size is None:
        return None
    if halves(model):
        _, w, qp = fam.split(q)
        mask = chain.plate_w > 0
        e, k = np.nonzero(mask)
        nxt = chain._next[e]
        xi_a = 2 / chain.l * (qp[e] - w[0, 0, e] + chain.plate_d[e, k])
        xi_b = 2 / chain.l * (qp[nxt] - w[1, 0, nxt] + chain.plate_d[e, k])
        ends = np.stack([chain.axis_points(q, e, np.zeros_like(e), xi_a),
                         chain.axis_points(q, nxt, np.ones_like(e), xi_b)], axis=1)
        return ends, e * chain.kmax + k, size
    base = getattr(chain, "base", chain)
    if base is chain:                                     # A1: links x Kmax outputs
        e, k = np.nonzero(base.plate_mask)
        xi, slot = base.plate_xi[e, k], e * base.plate_xi.shape[1] + k
    else:                                                 # A3/A4: one output per plate
        e, xi = chain.plate_link, chain.xi
        slot = np.arange(e.size)
    nxt = (e + 1) % base.n_pins
    ends = np.stack([base.axis_points(q, e, xi), base.axis_points(q, nxt, xi)], axis=1)
    return ends, slot, size


def sheave_positions(model, z) -> np.ndarray:
    """Axial positions (2 shafts, 2 sides), m, of the sheaves on the sides ``x3 < 0`` and ``x3 > 0`` of each
    rigid shaft, counted outwards from ``x3 = 0``: the pair's ``z`` on both sides (S), or the movable sheave's
    ``z`` on its side and the fixed sheave's position on the other (A)."""
    z = np.asarray(z, float)
    if not whole_pin(model):
        return np.column_stack([z, z])
    out = np.empty((2, 2))
    for k in range(2):
        for j, side in enumerate((-1, 1)):
            out[k, j] = z[k] if model.movable_side[k] == side else model.fixed_z[k]
    return out


def _cross_matrix(th) -> np.ndarray:
    """``[theta x]`` (3, 3) of a tilt vector ``th`` (3,)."""
    return np.array([[0.0, -th[2], th[1]], [th[2], 0.0, -th[0]], [-th[1], th[0], 0.0]])


def sheave_pose(model, q_structure, k: int, jj: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(o, a, theta)`` (3,) each of sheave ``jj`` (0 fixed, 1 movable) of elastic shaft ``k``: pivot (m), translation
    (m; the symmetric chains' axial part from the pair's mid-plane) and tilt (rad), as the contacts map them."""
    s, q = model.structure, np.asarray(q_structure, float)
    dofs = s.sheave_dofs[k, jj]
    o = np.append(model.contact.centres[k], s.sheave_x3[k, jj])
    a = q[dofs[:3]].copy()
    if model.axial_relative:
        a[2] = 0.5 * (a[2] - q[s.sheave_dofs[k, 1 - jj, 2]])
    return o, a, np.array([q[dofs[3]], q[dofs[4]], 0.0])


def sheave_faces(model, placement) -> np.ndarray:
    """Points (2 shafts, 2 sides, 3, *FACE_GRID), m, of the four faces (side 0: ``x3 < 0``): on rigid shafts at the
    sheave positions of ``placement = z`` (2,); on elastic shafts at ``z_ref`` in their sheaves' frames, carried by
    the poses (:func:`sheave_pose`) of ``placement = q_structure``."""
    contact = model.contact
    r_in, r_out = SHAFT_FRACTION * contact.r_outer, contact.r_outer
    out = np.empty((2, 2, 3) + FACE_GRID)
    for k in range(2):
        face, c = contact.faces[k], contact.centres[k]
        if not elastic(model):
            pos = sheave_positions(model, placement)[k]
            for j, side in enumerate((-1.0, 1.0)):
                out[k, j] = sheave_face_points(face, c, pos[j], side, r_in, r_out, *FACE_GRID)
            continue
        for jj in range(2):
            side = float(model._sides[k, jj])
            X = np.stack(sheave_face_points(face, c, model.face_ref[k, jj], side, r_in, r_out, *FACE_GRID))
            o, a, th = sheave_pose(model, placement, k, jj)
            back = np.linalg.inv(np.eye(3) - _cross_matrix(th))                # x - o - a = A^-1 (X - o)
            out[k, int(side > 0)] = (o + a)[:, None, None] + np.einsum("ij,jrt->irt", back, X - o[:, None, None])
    return out


def shaft_lines(model, placement) -> tuple[np.ndarray, np.ndarray]:
    """Each shaft's drawn axis (points, 3), m: on rigid shafts a straight line through its sheaves; on elastic
    shafts the polyline of its beam nodes displaced by ``placement = q_structure``."""
    contact, out = model.contact, []
    for k in range(2):
        c = contact.centres[k]
        if elastic(model):
            s, q = model.structure, np.asarray(placement, float)
            x = np.asarray(s.x[k], float)
            idx = s.offset[k] + 6 * np.arange(x.size)[:, None] + np.arange(3)
            u = q[idx]
            out.append(np.column_stack([c[0] + u[:, 0], c[1] + u[:, 1], x - s.params[k].length / 2 + u[:, 2]]))
            continue
        half = abs(sheave_positions(model, placement)[k].max() - face_profile(contact.faces[k])(contact.r_outer)[0]) \
            + 0.25 * contact.r_outer
        out.append(np.array([[c[0], c[1], -half], [c[0], c[1], half]]))
    return tuple(out)


def bearing_points(model, placement) -> np.ndarray | None:
    """Centres (2 shafts, 2 bearings, 3), m, of the bearings of elastic shafts: their beam nodes as displaced by
    ``placement = q_structure`` (the points of :func:`shaft_lines` there); None on rigid shafts (no bearings
    modelled)."""
    return None if not elastic(model) else _bearings_on(model, shaft_lines(model, placement))


def _bearings_on(model, lines) -> np.ndarray:
    """The bearing nodes' points (2, 2, 3) of the shafts' drawn axes ``lines`` (:func:`shaft_lines`)."""
    s = model.structure
    nodes = (s.bearing_dofs[:, :, 0] - s.offset[:, None]) // 6
    return np.stack([lines[k][nodes[k]] for k in range(2)])


@dataclass(frozen=True)
class ChainFrame:
    """What is drawn of the transmission at one state (m): the axes (N, PIN_POINTS, 3) of the pins (or pin halves)
    from the far end to the near end, the axes each link joins (n, 2), link ribbon corners (n, 4, 3) (first axis
    at ``-+PACK``, second at ``+-PACK``), the sheave positions (2 shafts, 2 sides) of :func:`sheave_positions`
    (rigid shafts; elastic: the faces' reference positions ``z_ref`` in their sheaves' frames), the face grids of
    :func:`sheave_faces`, the shafts' axes of :func:`shaft_lines`, for chains with plates the plates' end centres
    (P, 2, 3) and output slots of :func:`plate_stations`, and on elastic shafts the bearings of
    :func:`bearing_points`."""

    pin_axes: np.ndarray
    link_ends: np.ndarray
    link_corners: np.ndarray
    sheaves: np.ndarray
    faces: np.ndarray
    shafts: tuple
    plate_ends: np.ndarray | None = None
    plate_slots: np.ndarray | None = None
    bearings: np.ndarray | None = None


def sheave_reference(model, placement) -> np.ndarray:
    """:attr:`ChainFrame.sheaves` of ``placement``."""
    if not elastic(model):
        return sheave_positions(model, placement)
    ref = np.empty((2, 2))
    for k in range(2):
        for jj in range(2):
            ref[k, int(model._sides[k, jj] > 0)] = model.face_ref[k, jj]
    return ref


def chain_frame(model, q_chain, placement, reference=None, axial_scale: float = 1.0) -> ChainFrame:
    """The drawn geometry at chain coordinates ``q_chain`` and ``placement`` (rigid shafts: the sheave positions
    ``z`` (2,); elastic shafts: the structure's coordinates); with ``reference`` ``(q_chain_ref, placement_ref)``
    the axial coordinates of every drawn point are exaggerated by ``axial_scale`` about those."""
    xi = np.concatenate([np.linspace(-1.0, 1.0, PIN_POINTS), [-PACK_FRACTION, PACK_FRACTION]])

    def points(q, place):
        plates, lines = plate_stations(model, q), shaft_lines(model, place)
        return (pin_axis_points(model, q, xi, place), sheave_faces(model, place), lines,
                (None, None) if plates is None else plates[:2], _bearings_on(model, lines) if elastic(model) else None)
    pts, faces, shafts, (plate_ends, slots), bearings = points(q_chain, placement)
    sheaves = sheave_reference(model, placement)
    if reference is not None and axial_scale != 1.0:
        ref = points(*reference)

        def exaggerate(x, x_ref):
            x[..., 2] = x_ref[..., 2] + axial_scale * (x[..., 2] - x_ref[..., 2])
        exaggerate(pts, ref[0])
        exaggerate(faces.swapaxes(2, -1), ref[1].swapaxes(2, -1))
        for line, r_line in zip(shafts, ref[2]):
            exaggerate(line, r_line)
        if plate_ends is not None:
            exaggerate(plate_ends, ref[3][0])
        if bearings is not None:
            exaggerate(bearings, ref[4])
        ref_sheaves = sheave_reference(model, reference[1])
        sheaves = ref_sheaves + axial_scale * (sheaves - ref_sheaves)
    pack = pts[:, PIN_POINTS:]
    a, b = link_axes(model).T
    corners = np.stack([pack[a, 0], pack[a, 1], pack[b, 1], pack[b, 0]], axis=1)
    return ChainFrame(pts[:, :PIN_POINTS], np.column_stack([a, b]), corners, sheaves, faces, shafts, plate_ends,
                      slots, bearings)


def chain_state(model, x) -> tuple[np.ndarray, np.ndarray]:
    """Chain coordinates and the placement of :func:`chain_frame` (rigid: sheave positions ``z`` (2,) m; elastic:
    the structure's coordinates) of a full model state."""
    q = model.split(np.asarray(x, float))[0]
    nc, _, iz, _ = model._idx
    if elastic(model):
        return np.array(q[:nc]), np.array(q[nc:nc + model.structure.n])
    return np.array(q[:nc]), np.array(q[iz])


def sheave_face_points(face, centre, z: float, side: float, r_in: float, r_out: float, n_r: int = 12,
                       n_theta: int = 96) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid ``(x1, x2, x3)`` arrays (n_r, n_theta), m, of the face ``x3 = side (z + s(r))``."""
    r = np.linspace(r_in, r_out, n_r)
    theta = np.linspace(0.0, 2 * np.pi, n_theta)
    R, T = np.meshgrid(r, theta, indexing="ij")
    s = -face_profile(face)(R)[0]
    return centre[0] + R * np.cos(T), centre[1] + R * np.sin(T), side * (z + s)


def chain_meshes(frame: ChainFrame):
    """Pins (polylines along their axes, one polydata) and links (ribbons: one quad cell per link)."""
    import pyvista as pv

    n, m, _ = frame.pin_axes.shape
    lines = np.column_stack([np.full(n, m), np.arange(n * m).reshape(n, m)]).ravel()
    axes = pv.PolyData(frame.pin_axes.reshape(-1, 3), lines=lines)
    return axes, _quads(frame.link_corners)


def _quads(corners):
    """A pyvista PolyData of one quad cell per corner set ``corners`` (k, 4, 3)."""
    import pyvista as pv

    k = len(corners)
    return pv.PolyData(corners.reshape(-1, 3), faces=np.column_stack([np.full(k, 4), 4 * np.arange(k)[:, None]
                                                                      + np.arange(4)]).ravel())


def plate_corners(frame: ChainFrame) -> np.ndarray:
    """Corners (P, 4, 3), m, of the drawn plates: quads parallel to the chain plane between their two end centres,
    ``PLATE_HEIGHT`` of the centre distance wide across it (a drawing size)."""
    a, b = frame.plate_ends[:, 0], frame.plate_ends[:, 1]
    d = b[:, :2] - a[:, :2]
    across = np.column_stack([-d[:, 1], d[:, 0], np.zeros(len(d))]) * (PLATE_HEIGHT / 2)
    return np.stack([a - across, a + across, b + across, b - across], axis=1)


def plate_mesh(frame: ChainFrame):
    """The plates of :func:`plate_corners` as one pyvista PolyData (a quad cell each)."""
    return _quads(plate_corners(frame))


# ----- colours ---------------------------------------------------------------------------------------------
def colour_kind(model, spec) -> str | None:
    """How output ``spec`` colours the chain: ``"link"`` (one value per link), ``"plate"`` (per plate: the plates
    are drawn), ``"pin"`` (per pin), ``"half"`` (per pin half of A5: half - of every pin, then half +), ``"end"``
    (per pin end, or pin-half end, and shaft, ``contact.*``), or None (not drawable)."""
    n = model.family.n
    if spec.name.startswith("contact.") and spec.size == 2 * model.n_ends:
        return "end"
    if spec.name.startswith("chain.plate_") and spec.size == plate_outputs(model):
        return "plate"
    if halves(model) and spec.size == 2 * n and "half" in spec.name:
        return "half"
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
        raise InputError(option, name, f"must be an output{where} with one value per link, per plate, per pin, per "
                         "pin half or per pin end and shaft: " + ", ".join(sorted(allowed)))
    return allowed[name]


def colour_values(model, name: str, values) -> tuple[np.ndarray, str]:
    """``(values, kind)`` as drawn: per link (n,) with kind ``"link"``; the per-plate outputs as they are, kind
    ``"plate"`` (:attr:`ChainFrame.plate_slots` picks the drawn plates' values); per drawn axis (N,) with kind
    ``"pin"`` (a pin's value on both of A5's halves, A5's per-half values on their halves); per axis end (N, 2)
    (far, near) with kind ``"end"`` for an output per pin end and shaft, summed over the two shafts (an end touches
    one shaft at a time; A2's two coupled halves' ends summed on their whole pin's end).  A symmetric chain's
    contact outputs (one end per pin, the mirror end implied) become per pin."""
    spec = next(s for s in model.output_specs if s.name == name)
    kind = colour_kind(model, spec)
    v = np.asarray(values, float).reshape(-1)
    if kind == "end":
        v = v.reshape(-1, 2).sum(axis=1)
        if not whole_pin(model):
            return v, "pin"
        if v.size == 4 * model.family.n and not halves(model):       # A2: both coupled halves' ends on one pin end
            v = v.reshape(-1, 2, 2).sum(axis=1).ravel()
        return v.reshape(-1, 2), "end"
    if kind == "half":
        return v.reshape(2, -1).T.ravel(), "pin"
    if kind == "pin" and halves(model):
        return np.repeat(v, 2), "pin"
    return v, kind


def colour_meshes(pins, links, values: np.ndarray, kind: str, name: str, link_ends: np.ndarray) -> None:
    """Attach ``values`` of :func:`colour_values` as scalars ``name`` to the axis polylines and link ribbons
    (links only for per-link values; the other kinds interpolate per axis or per axis end, and along each ribbon
    between the axes ``link_ends`` (n, 2) it joins)."""
    if kind == "link":
        links.cell_data[name] = values
        return
    n = len(values)
    m = pins.n_points // n
    ends = np.column_stack([values, values]) if kind == "pin" else values            # (N, 2): far, near
    xi = np.linspace(-1.0, 1.0, m)
    pins.point_data[name] = (ends[:, :1] + (ends[:, 1:] - ends[:, :1]) * (xi + 1) / 2).ravel()
    at = ends[:, 0] + (ends[:, 1] - ends[:, 0]) * (1 + np.array([-1.0, 1.0])[:, None] * PACK_FRACTION) / 2
    a, b = link_ends.T
    links.point_data[name] = np.column_stack([at[0][a], at[1][a], at[1][b], at[0][b]]).ravel()


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
    import pyvista as pv

    v, kind = colour_values(model, name, values)
    contact = model.contact
    r_out = contact.r_outer
    axes, links = chain_meshes(frame)
    bar = {"title": f"{name} ({unit})", "color": "black", "position_x": 0.25, "width": 0.5, "fmt": "%.4g"}
    if kind == "plate":
        v = v[frame.plate_slots]
        links = plate_mesh(frame)
        links.cell_data[name] = v
    else:
        colour_meshes(axes, links, v, kind, name, frame.link_ends)
    clim = colour_limits(v) if clim is None else clim
    p.add_mesh(links, scalars=name, cmap="viridis", clim=clim, show_edges=kind == "plate", edge_color="dimgray",
               scalar_bar_args=bar)
    radius = PIN_FRACTION * r_out * (0.6 if halves(model) else 1.0)
    tubes = axes.tube(radius=radius, n_sides=12, capping=True)
    if kind in ("link", "plate"):
        p.add_mesh(tubes, color="dimgray", smooth_shading=True)
    else:
        p.add_mesh(tubes, scalars=name, cmap="viridis", clim=clim, smooth_shading=True, show_scalar_bar=False)
    for k in range(2):
        for j, opacity in enumerate((1.0, 0.25)):
            p.add_mesh(pv.StructuredGrid(*frame.faces[k, j]), color="lightsteelblue", opacity=opacity,
                       smooth_shading=True)
        line = frame.shafts[k]
        shaft = pv.lines_from_points(line).tube(radius=SHAFT_FRACTION * r_out, n_sides=48, capping=True)
        p.add_mesh(shaft, color="slategray", smooth_shading=True)
        for centre in () if frame.bearings is None else frame.bearings[k]:
            p.add_mesh(pv.Cylinder(center=centre, direction=(0, 0, 1), radius=BEARING_FRACTION * r_out,
                                   height=0.15 * r_out, resolution=48), color="darkgoldenrod", smooth_shading=True)
    p.add_point_labels(np.column_stack([contact.centres, np.full(2, 0.5 * r_out)]), ["driving", "driven"],
                       font_size=14, text_color="black", shape_opacity=0.0, always_visible=True)


@dataclass(frozen=True)
class View:
    """Camera of a rendering: ``zoom`` over the view of the whole transmission, aimed at the chain-plane point
    ``look_at`` ``(x1, x2)`` m (None: the transmission's centre)."""

    zoom: float = 1.0
    look_at: tuple | None = None


def set_view(p, view: View = View()) -> None:
    """The oblique view of every rendering (the chain plane seen from the front, slightly from below), moved
    parallel to aim at ``view.look_at`` and zoomed by ``view.zoom``."""
    p.view_vector((0.35, -0.55, 1.0), viewup=(0.0, 1.0, 0.0))
    if view.look_at is not None:
        focal = np.array(p.camera.focal_point)
        shift = np.array([view.look_at[0], view.look_at[1], 0.0]) - focal
        p.camera.position = tuple(np.array(p.camera.position) + shift)
        p.camera.focal_point = tuple(focal + shift)
    p.camera.zoom(1.15 * view.zoom)


def render_transmission(model, x, path: str | Path, color_by: str = "chain.link_tension", t: float = 0.0,
                        reference=None, axial_scale: float = 1.0, size: tuple[int, int] = (1400, 800),
                        title: str | None = None, view: View = View()) -> Path:
    """PNG of the chain transmission in state ``x`` at time ``t`` (s): sheaves, shafts, pins and links,
    coloured by the model output ``color_by`` (per link, per pin, per pin half, or per pin end and shaft)."""
    unit = check_colour(model, color_by)
    q_chain, z = chain_state(model, x)
    ref = None if reference is None else chain_state(model, reference)
    frame = chain_frame(model, q_chain, z, ref, axial_scale)
    p = plotter(size)
    draw_frame(p, model, frame, color_by, model.outputs(t, x)[color_by], unit)
    set_view(p, view)
    note = f", axial positions x{axial_scale:g}" if axial_scale != 1.0 else ""
    p.add_text(title or f"chain transmission at t = {t:.4g} s: coloured by {color_by}{note}",
               font_size=10, color="black")
    p.screenshot(str(path))
    p.close()
    return Path(path)
