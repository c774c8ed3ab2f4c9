"""Rotor-scene sheaves -> solid sheave sections (issue 20): the ``[[disk]]`` tables with ``geometry = "sheave"``.

The section is the one :func:`cvtfem.elements.disk.sheave_profile` draws for the rigid disk's mass
properties (bore, hub sleeve, conical or toroidal face), with the disk's material; Poisson's ratio
follows from the material's ``E`` and ``G``.
"""
from __future__ import annotations

from cvtfem.elements.sheave_solid import SheaveSection
from cvtfem.errors import InputError
from cvtfem.scene.loader import Scene


def sheave_indices(scene: Scene) -> list[int]:
    """Positions of the scene's ``[[disk]]`` tables that describe a sheave by its section."""
    return [i for i, d in enumerate(scene.disk) if d.geometry == "sheave"]


def sheave_section(scene: Scene, index: int | None = None) -> SheaveSection:
    """The section of ``[[disk]]`` number ``index`` (default: the first sheave) of a rotor scene."""
    found = sheave_indices(scene)
    if not found:
        raise InputError("disk", None, "needs a [[disk]] with geometry = \"sheave\" in the scene")
    index = found[0] if index is None else index
    if index not in found:
        raise InputError("--disk", index, f"must be the index of a sheave disk: {found}")
    d = scene.disk[index]
    mat = {m.name: m for m in scene.material}[d.material]
    return SheaveSection(bore_radius=d.inner_diameter / 2, hub_radius=d.hub_diameter / 2,
                         outer_radius=d.outer_diameter / 2, hub_length=d.hub_length, rim_thickness=d.rim_thickness,
                         flank_angle=d.cone_angle, face=d.face, torus_radius=d.torus_radius, E=mat.E,
                         nu=mat.E / (2 * mat.G) - 1.0, rho=mat.rho)
