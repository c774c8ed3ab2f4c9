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

MATERIAL = TableArray("material", "Materials referenced by name.", Table("material", "A material.", (
    Key("name", "str", "Name used by `shaft.material`.", ""),
    Key("E", "float", "Young's modulus.", "Pa", gt=0.0),
    Key("G", "float", "Shear modulus.", "Pa", gt=0.0),
    Key("rho", "float", "Density.", "kg/m^3", gt=0.0),
)))

SHAFT = TableArray("shaft", "Shaft elements in order along the axis.", Table("shaft", "A shaft element.", (
    Key("length", "float", "Element length.", "m", gt=0.0),
    Key("outer_diameter", "float", "Outer diameter.", "m", gt=0.0),
    Key("inner_diameter", "float", "Inner diameter (0: solid).", "m", 0.0, ge=0.0),
    Key("material", "str", "Name of a `[[material]]`.", ""),
    Key("repeat", "int", "Number of identical consecutive elements this entry stands for.", "-", 1, ge=1),
), checks=(lambda t, p: _check_section(t, p),)))

DISK = TableArray("disk", "Rigid disks on shaft nodes.", Table("disk", "A rigid disk.", (
    Key("node", "int", "Shaft node the disk sits on.", "-", ge=0),
    Key("mass", "float", "Mass.", "kg", gt=0.0),
    Key("Id", "float", "Diametral moment of inertia.", "kg m^2", gt=0.0),
    Key("Ip", "float", "Polar moment of inertia.", "kg m^2", gt=0.0),
)))

BEARING = TableArray("bearing", "Linear bearings on shaft nodes.", Table("bearing", "A linear bearing.", (
    Key("node", "int", "Shaft node the bearing supports.", "-", ge=0),
    *(Key(f"k{ij}", "float", f"Stiffness coefficient {ij}.", "N/m", 0.0) for ij in ("xx", "yy", "xy", "yx")),
    *(Key(f"c{ij}", "float", f"Damping coefficient {ij}.", "N s/m", 0.0) for ij in ("xx", "yy", "xy", "yx")),
)))


def _check_section(table: Mapping[str, Any], path: str) -> None:
    if table["inner_diameter"] >= table["outer_diameter"]:
        raise InputError(f"{path}.inner_diameter", table["inner_diameter"],
                         f"must be smaller than `outer_diameter` = {table['outer_diameter']} m")


def check_rotor(scene: Mapping[str, Any], path: str) -> None:
    """Cross-table checks: materials exist, nodes lie on the shaft."""
    names = [m["name"] for m in scene["material"]]
    for i, shaft in enumerate(scene["shaft"]):
        if shaft["material"] not in names:
            from cvtfem.scene.schema.base import _suggest

            raise InputError(f"shaft[{i}].material", shaft["material"], "must name a `[[material]]`",
                             _suggest(shaft["material"], names) or f"defined: {', '.join(names) or 'none'}")
    n_nodes = sum(s["repeat"] for s in scene["shaft"]) + 1
    for table in ("disk", "bearing"):
        for i, entry in enumerate(scene[table]):
            if entry["node"] >= n_nodes:
                raise InputError(f"{table}[{i}].node", entry["node"],
                                 f"must be a shaft node, 0..{n_nodes - 1}")
    if (scene["disk"] or scene["bearing"]) and not scene["shaft"]:
        raise InputError("shaft", [], "needs at least one entry when disks or bearings are given")


ROOT_ITEMS = (MATERIAL, SHAFT, DISK, BEARING)
ROOT_CHECKS = (check_rotor,)
