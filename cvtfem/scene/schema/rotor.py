"""Rotor scenes: materials, shaft elements, disks and bearings (issue 3 format).

A file holding only ``[[material]]``, ``[[shaft]]``, ``[[disk]]`` and
``[[bearing]]`` tables is a valid rotor scene.  Nodes are numbered from 0 at
the left end of the first shaft element.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cvtfem.errors import InputError
from cvtfem.scene.schema.base import Key, Table, TableArray

#: Most shaft elements a rotor may have in all (6 DOF per node: 3000 elements -> 18 000 DOF; a Campbell diagram
#: of a 3000-element shaft takes ~10 s here, 6000 elements ~50 s: the cost grows as n^2.5).
MAX_ELEMENTS = 3000

MATERIAL = TableArray("material", "Materials referenced by name.", Table("material", "A material.", (
    Key("name", "str", "Name used by `shaft.material`.", ""),
    Key("E", "float", "Young's modulus (foams to diamond: 1e3 .. 1e13 Pa).", "Pa", ge=1e3, le=1e13),
    Key("G", "float", "Shear modulus (1e3 .. 1e13 Pa).", "Pa", ge=1e3, le=1e13),
    Key("rho", "float", "Density (aerogels to osmium and beyond: 1 .. 1e5 kg/m^3).", "kg/m^3", ge=1.0, le=1e5),
)))

SHAFT = TableArray("shaft", "Shaft elements in order along the axis.", Table("shaft", "A shaft element.", (
    Key("length", "float", "Element length (1 um .. 100 m).", "m", ge=1e-6, le=100.0),
    Key("outer_diameter", "float", "Outer diameter (1 um .. 100 m); at the left end of a tapered element.", "m",
        ge=1e-6, le=100.0),
    Key("inner_diameter", "float", "Inner diameter (0: solid); at the left end of a tapered element.", "m", 0.0,
        ge=0.0),
    Key("outer_diameter_right", "float", "Outer diameter at the right end of a tapered element (the diameters "
        "vary linearly along it; -1: `outer_diameter`, a uniform element).", "m", -1.0, ge=-1.0, le=100.0),
    Key("inner_diameter_right", "float", "Inner diameter at the right end of a tapered element (-1: "
        "`inner_diameter`).", "m", -1.0, ge=-1.0),
    Key("material", "str", "Name of a `[[material]]`.", ""),
    Key("repeat", "int", "Number of identical consecutive elements this entry stands for.", "-", 1, ge=1,
        le=MAX_ELEMENTS),
    Key("parallel", "bool", "A sleeve: this element lies on the two nodes of the element before it (same "
        "length) and adds its mass and stiffness there instead of starting a new node.", "", False),
), checks=(lambda t, p: _check_section(t, p),)))

ROTOR = Table("rotor", "Rotor model options (beam theory, switches, damping, analysis defaults).", (
    Key("theory", "str", "Beam theory of the shaft elements.", "", "timoshenko",
        choices=("timoshenko", "euler-bernoulli")),
    Key("rotary_inertia", "bool", "Rotary inertia of the shaft sections.", "", True),
    Key("gyroscopic", "bool", "Shaft gyroscopic matrix (disks always have theirs).", "", True),
    Key("shear_coefficient", "float", "Timoshenko shear coefficient; 0: Cowper's formula per section.", "-",
        0.0, ge=0.0, le=1.0),
    Key("axial_force", "float", "Axial force in the whole shaft (tension > 0) for the geometric stiffness.",
        "N", 0.0),
    Key("damping_beta", "float", "Stiffness-proportional shaft damping C = beta K_shaft.", "s", 0.0, ge=0.0),
    Key("speed", "float", "Default spin speed of `cvtfem modes`.", "rad/s", 0.0),
    Key("n_modes", "int", "Default number of modes reported.", "-", 12, ge=1),
), optional=True)

#: ``[sheave]`` keys a CVT scene gives its sheaves' section with (the outer radius and face are `cvt.geometry`'s).
CVT_SECTION = (("bore_diameter", "bore diameter"), ("hub_diameter", "hub outer diameter"),
               ("hub_length", "hub length behind the disc"), ("rim_thickness", "thickness at the outer radius"))

SHEAVE = Table("sheave", "Sheave disks (`[[disk]]` with geometry = 'sheave') as rigid bodies or flexible solids.", (
    Key("flexibility", "str", "Rigid: the disk's mass properties only (no sheave FE code runs); reduced: a "
        "solid model per nodal-diameter harmonic n = 0, 1 on the shaft node, Craig-Bampton reduced; full: the "
        "same with every fixed-interface mode (the reference of reduced).", "", "rigid",
        choices=("rigid", "reduced", "full")),
    Key("modes", "int", "Fixed-interface modes kept per harmonic (axial n = 0, torsion, each n = 1 family).",
        "-", 8, ge=1, le=200),
    Key("cells_radial", "int", "Section mesh: quadratic-triangle columns from bore to rim.", "-", 24, ge=4, le=400),
    Key("cells_axial", "int", "Section mesh: layers from the back face to the contact face.", "-", 2, ge=1, le=40),
    Key("diameters", "int", "The sheaves' own waves of n = 2..diameters nodal diameters drawn by `cvtfem campbell` "
        "(forward and backward; they do not couple with the shaft); those in the model (`model_diameters`) are "
        "not drawn again.", "-", 4, ge=1, le=40),
    Key("model_diameters", "int", "Rotor scenes: the waves of n = 2..model_diameters nodal diameters join the rotor "
        "model (bore clamped, Craig-Bampton with their twins, spin stiffening and Coriolis coupling): `modes` and "
        "`campbell` solve and label them forward/backward; 1: only n = 0, 1.", "-", 1, ge=1, le=40),
    Key("damping_ratio", "float", "Rotor scenes: modal damping ratio of each fixed-interface mode of a reduced "
        "or full sheave (C = 2 zeta omega_k on its modal coordinate).", "-", 0.0, ge=0.0, lt=1.0),
    Key("harmonics", "int", "CVT scenes (band-6+2n models): nodal-diameter harmonics 0..harmonics of the sheave "
        "face's compliance under the contact arcs.", "-", 24, ge=1, le=200),
    *(Key(name, "float", f"CVT scenes: {doc} of the sheaves (rotor scenes take their sections from [[disk]]); "
          "required with flexibility = 'reduced'.", "m", 0.0, ge=0.0) for name, doc in CVT_SECTION),
    Key("young_modulus", "float", "CVT scenes: Young's modulus of the sheaves (0: `cvt.young_modulus`).", "Pa",
        0.0, ge=0.0, le=1e13),
    Key("poisson_ratio", "float", "CVT scenes: Poisson's ratio of the sheaves.", "-", 0.3, gt=-1.0, lt=0.5),
    Key("density", "float", "CVT scenes: density of the sheaves.", "kg/m^3", 7850.0, ge=1.0, le=1e5),
), optional=True)

DISK = TableArray("disk", "Rigid disks / sheaves on shaft nodes.", Table("disk", "A rigid disk or sheave.", (
    Key("node", "int", "Shaft node the disk sits on.", "-", ge=0),
    Key("mass", "float", "Mass (0: from `geometry`).", "kg", 0.0, ge=0.0),
    Key("Id", "float", "Diametral moment of inertia (0: from `geometry`).", "kg m^2", 0.0, ge=0.0),
    Key("Ip", "float", "Polar moment of inertia (0: from `geometry`).", "kg m^2", 0.0, ge=0.0),
    Key("geometry", "str", "Compute mass properties from a section: '' (use mass/Id/Ip), 'disc' or 'sheave'.",
        "", "", choices=("", "disc", "sheave")),
    Key("material", "str", "Material of a geometric disk (name of a `[[material]]`).", "", ""),
    Key("width", "float", "Disc width (geometry = 'disc').", "m", 0.0, ge=0.0),
    Key("inner_diameter", "float", "Bore diameter.", "m", 0.0, ge=0.0),
    Key("outer_diameter", "float", "Outer diameter.", "m", 0.0, ge=0.0),
    Key("hub_diameter", "float", "Sheave hub outer diameter.", "m", 0.0, ge=0.0),
    Key("hub_length", "float", "Sheave hub length behind the disc.", "m", 0.0, ge=0.0),
    Key("rim_thickness", "float", "Sheave thickness at the outer diameter.", "m", 0.0, ge=0.0),
    Key("cone_angle", "float", "Sheave face angle from the radial plane.", "rad", 0.192, ge=0.0, lt=1.5),
    Key("face", "str", "Sheave contact face generatrix.", "", "conical", choices=("conical", "toroidal")),
    Key("torus_radius", "float", "Toroidal face arc radius.", "m", 0.0, ge=0.0),
    Key("facing", "str", "Direction the sheave face looks along the axis (the two sheaves of a pulley face "
        "each other).", "", "+z", choices=("+z", "-z")),
    Key("connection", "str", "Sheave-shaft connection: rigid (same node) or elastic (own node, springs).", "",
        "rigid", choices=("rigid", "elastic")),
    Key("c_u", "float", "Elastic connection radial stiffness.", "N/m", 0.0, ge=0.0),
    Key("c_theta", "float", "Elastic connection tilt stiffness.", "N m/rad", 0.0, ge=0.0),
    Key("c_3", "float", "Elastic connection axial stiffness.", "N/m", 0.0, ge=0.0),
    Key("c_phi", "float", "Elastic connection torsional stiffness.", "N m/rad", 0.0, ge=0.0),
), checks=(lambda t, p: _check_disk(t, p),)))

BEARING = TableArray("bearing", "Bearings (supports to ground or between two nodes) on shaft nodes.", Table(
    "bearing", "A bearing.", (
    Key("node", "int", "Shaft node the bearing supports (or a support node, see `link_node`).", "-", ge=0),
    Key("link_node", "int", "Node the bearing connects `node` to (ROSS `n_link`; -1: ground): its coefficients "
        "act on the relative motion u_node - u_link. A shaft node, or a support node numbered "
        "after the shaft's (n_shaft_nodes, n_shaft_nodes + 1, ..: a pedestal, which gets its mass and its own "
        "support from a `[[bearing]]` whose `node` it is).", "-", -1, ge=-1),
    *(Key(f"k{ij}", "float", f"Lateral stiffness coefficient {ij}.", "N/m", 0.0) for ij in ("xx", "yy", "xy", "yx")),
    *(Key(f"c{ij}", "float", f"Lateral damping coefficient {ij}.", "N s/m", 0.0) for ij in ("xx", "yy", "xy", "yx")),
    Key("kzz", "float", "Axial stiffness.", "N/m", 0.0),
    Key("czz", "float", "Axial damping.", "N s/m", 0.0),
    Key("ktt", "float", "Tilting stiffness (both tilts).", "N m/rad", 0.0),
    Key("ctt", "float", "Tilting damping.", "N m s/rad", 0.0),
    Key("kphi", "float", "Torsional stiffness to ground.", "N m/rad", 0.0),
    Key("cphi", "float", "Torsional damping to ground.", "N m s/rad", 0.0),
    Key("mass", "float", "Lumped bearing mass.", "kg", 0.0, ge=0.0),
    Key("Id", "float", "Lumped diametral inertia.", "kg m^2", 0.0, ge=0.0),
    Key("Ip", "float", "Lumped polar inertia.", "kg m^2", 0.0, ge=0.0),
    Key("law", "str", "Lateral law: linear (kxx..) or the isotropic radial law f_r(u) as table or polynomial.",
        "", "linear", choices=("linear", "table", "polynomial")),
    Key("table_u", "float[]", "Radial deflections of the table law, from 0, increasing.", "m", ()),
    Key("table_f", "float[]", "Radial forces of the table law, from 0.", "N", ()),
    Key("coeffs", "float[]", "Polynomial law f_r = c1 u + c2 u^2 + ...", "N/m^n", ()),
    Key("u0", "float[]", "Operating lateral deflection (u1, u2) for the tangent stiffness.", "m", (0.0, 0.0),
        length=2),
    Key("beta", "float", "Radial damping beta f_r'(0) e e^T of a nonlinear law (added to cxx..).", "s", 0.0,
        ge=0.0),
    Key("speeds", "float[]", "Spin speeds of the coefficient tables `kxx_table` .. `cyy_table` (strictly "
        "increasing); interpolated as ROSS 3.1 does: PCHIP, linear for two points, linear extrapolation with the "
        "end slopes.", "rad/s", ()),
    *(Key(f"k{ij}_table", "float[]", f"Lateral stiffness {ij} at each of `speeds` (replaces `k{ij}`).", "N/m", ())
      for ij in ("xx", "xy", "yx", "yy")),
    *(Key(f"c{ij}_table", "float[]", f"Lateral damping {ij} at each of `speeds` (replaces `c{ij}`).", "N s/m", ())
      for ij in ("xx", "xy", "yx", "yy")),
), checks=(lambda t, p: _check_bearing(t, p),)))


def _check_section(table: Mapping[str, Any], path: str) -> None:
    if table["inner_diameter"] >= table["outer_diameter"]:
        raise InputError(f"{path}.inner_diameter", table["inner_diameter"],
                         f"must be smaller than `outer_diameter` = {table['outer_diameter']} m")
    outer, inner = right_diameters(table)
    if table["outer_diameter_right"] != -1.0 and outer < 1e-6:
        raise InputError(f"{path}.outer_diameter_right", outer, "must be -1 (uniform) or 1 um .. 100 m")
    if table["inner_diameter_right"] != -1.0 and inner < 0:
        raise InputError(f"{path}.inner_diameter_right", inner, "must be -1 (uniform) or >= 0")
    if inner >= outer:
        raise InputError(f"{path}.inner_diameter_right", inner,
                         f"must be smaller than the right outer diameter {outer} m")


def right_diameters(table: Mapping[str, Any]) -> tuple[float, float]:
    """Outer and inner diameter at the right end of a `[[shaft]]` entry (its left ones unless tapered), m."""
    outer, inner = table["outer_diameter_right"], table["inner_diameter_right"]
    return (table["outer_diameter"] if outer == -1.0 else outer, table["inner_diameter"] if inner == -1.0 else inner)


def _check_disk(table: Mapping[str, Any], path: str) -> None:
    if not table["geometry"]:
        for key in ("mass", "Id", "Ip"):
            if table[key] <= 0:
                raise InputError(f"{path}.{key}", table[key], "must be > 0 unless `geometry` is given")
        return
    if not table["material"]:
        raise InputError(f"{path}.material", "", "is required with `geometry` (name of a `[[material]]`)")
    if table["outer_diameter"] <= table["inner_diameter"]:
        raise InputError(f"{path}.outer_diameter", table["outer_diameter"],
                         f"must exceed `inner_diameter` = {table['inner_diameter']} m")
    if table["geometry"] == "disc" and table["width"] <= 0:
        raise InputError(f"{path}.width", table["width"], "must be > 0 for geometry = 'disc'")
    if table["geometry"] == "sheave" and not (table["inner_diameter"] < table["hub_diameter"]
                                              < table["outer_diameter"]):
        raise InputError(f"{path}.hub_diameter", table["hub_diameter"],
                         "must lie between `inner_diameter` and `outer_diameter` for geometry = 'sheave'")


def _check_bearing(table: Mapping[str, Any], path: str) -> None:
    tables = [f"{c}{ij}_table" for c in "kc" for ij in ("xx", "xy", "yx", "yy")]
    speeds = table["speeds"]
    if any(b <= a for a, b in zip(speeds, speeds[1:])):
        raise InputError(f"{path}.speeds", speeds, "must be strictly increasing")
    for key in tables:
        if table[key] and len(table[key]) != len(speeds):
            raise InputError(f"{path}.{key}", table[key], f"must have one value per `speeds` entry ({len(speeds)})")
    if speeds and not any(table[k] for k in tables):
        raise InputError(f"{path}.speeds", speeds, "needs at least one coefficient table (`kxx_table` ..)")
    if speeds and table["law"] != "linear":
        raise InputError(f"{path}.speeds", speeds, "works with law = 'linear' only")
    if table["law"] == "table" and (len(table["table_u"]) < 2 or len(table["table_u"]) != len(table["table_f"])):
        raise InputError(f"{path}.table_u", table["table_u"], "needs >= 2 values and as many `table_f` values")
    if table["law"] == "polynomial" and not table["coeffs"]:
        raise InputError(f"{path}.coeffs", table["coeffs"], "needs at least one coefficient for law = 'polynomial'")


def check_rotor(scene: Mapping[str, Any], path: str) -> None:
    """Cross-table checks: materials exist, nodes lie on the shaft."""
    names = [m["name"] for m in scene["material"]]
    for i, shaft in enumerate(scene["shaft"]):
        if shaft["material"] not in names:
            from cvtfem.scene.schema.base import _suggest

            raise InputError(f"shaft[{i}].material", shaft["material"], "must name a `[[material]]`",
                             _suggest(shaft["material"], names) or f"defined: {', '.join(map(repr, names)) or 'none'}")
    for i, disk in enumerate(scene["disk"]):
        if disk["geometry"] and disk["material"] not in names:
            raise InputError(f"disk[{i}].material", disk["material"], "must name a `[[material]]`",
                             f"defined: {', '.join(map(repr, names)) or 'none'}")
    for i, shaft in enumerate(scene["shaft"]):
        if shaft["parallel"] and (i == 0 or shaft["repeat"] != 1 or scene["shaft"][i - 1]["length"] != shaft["length"]):
            raise InputError(f"shaft[{i}].parallel", True, "needs repeat = 1 and an element before it of the same "
                             "`length` (a sleeve lies on that element's nodes)")
    n_nodes = sum(s["repeat"] for s in scene["shaft"] if not s["parallel"]) + 1
    for i, entry in enumerate(scene["disk"]):
        if entry["node"] >= n_nodes:
            raise InputError(f"disk[{i}].node", entry["node"], f"must be a shaft node, 0..{n_nodes - 1}")
    _check_links(scene["bearing"], n_nodes)
    flexibility = (scene.get("sheave") or {}).get("flexibility", "rigid")
    if flexibility != "rigid" and not any(d["geometry"] == "sheave" for d in scene["disk"]):
        raise InputError("sheave.flexibility", flexibility, "needs a [[disk]] with geometry = 'sheave' "
                         "(or flexibility = 'rigid')")
    for name in [n for n, _ in CVT_SECTION] + ["young_modulus"]:
        if (scene.get("sheave") or {}).get(name, 0.0):
            raise InputError(f"sheave.{name}", scene["sheave"][name], "must be left out of a rotor scene: its "
                             "sheaves take their sections from [[disk]] (the key is for CVT scenes)")
    if (scene["disk"] or scene["bearing"]) and not scene["shaft"]:
        raise InputError("shaft", [], "needs at least one entry when disks or bearings are given")


def _check_links(bearings: list, n_nodes: int) -> None:
    """Bearings sit on shaft or support nodes; support nodes n_nodes.. are consecutive and each one linked."""
    supports = sorted({b["link_node"] for b in bearings if b["link_node"] >= n_nodes})
    if supports != list(range(n_nodes, n_nodes + len(supports))):
        raise InputError("bearing[].link_node", supports, f"support nodes must be numbered {n_nodes}, "
                         f"{n_nodes + 1}, .. without gaps (the shaft has nodes 0..{n_nodes - 1})")
    for i, b in enumerate(bearings):
        if b["node"] >= n_nodes and b["node"] not in supports:
            raise InputError(f"bearing[{i}].node", b["node"], f"must be a shaft node, 0..{n_nodes - 1} (or a support "
                             f"node some bearing's `link_node` names: {supports or 'none'})")
        if b["link_node"] == b["node"]:
            raise InputError(f"bearing[{i}].link_node", b["link_node"], "must differ from `node` (or be -1: ground)")
        if b["link_node"] >= 0 and b["speeds"]:
            raise InputError(f"bearing[{i}].speeds", b["speeds"], "must be left out of a bearing between two nodes "
                             "(speed tables act to ground only)")
        if b["link_node"] >= 0 and b["law"] != "linear":
            raise InputError(f"bearing[{i}].law", b["law"], "must be 'linear' for a bearing between two nodes")


ROOT_ITEMS = (ROTOR, MATERIAL, SHAFT, DISK, BEARING, SHEAVE)
ROOT_CHECKS = (check_rotor,)
