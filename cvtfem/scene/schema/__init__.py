"""The scene schema: one tree, assembled from one module per kind of machine."""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cvtfem.errors import InputError
from cvtfem.scene.schema import rotor, torsional
from cvtfem.scene.schema.base import REQUIRED, Key, Table, TableArray, validate
from cvtfem.scene.schema.common import IDENTITY, OUTPUT, SOLVER
from cvtfem.scene.schema.cvt import CVT

KINDS = ("cvt", "rotor", "torsional")


def scene_kind(scene: Mapping[str, Any]) -> str:
    """Which machine a validated scene describes: "cvt", "rotor" or "torsional"."""
    found = []
    if scene.get("cvt") is not None:
        found.append("cvt")
    if scene.get("shaft"):
        found.append("rotor")
    if scene.get("torsional"):
        found.append("torsional")
    if len(found) != 1:
        raise InputError("scene", found or "nothing",
                         "must describe exactly one machine: a [cvt] table, [[shaft]] tables "
                         "(rotor) or a [torsional] network")
    return found[0]


def _check_scene(scene: Mapping[str, Any], path: str) -> None:
    kind = scene_kind(scene)
    if kind == "rotor":
        for check in rotor.ROOT_CHECKS:
            check(scene, path)
    if kind == "torsional":
        for check in torsional.ROOT_CHECKS:
            check(scene, path)


SCENE = Table("", "A cvtfem scene.", (
    *IDENTITY, SOLVER, OUTPUT, CVT, *rotor.ROOT_ITEMS, *torsional.ROOT_ITEMS,
), checks=(_check_scene,))

__all__ = ["SCENE", "KINDS", "scene_kind", "validate", "Key", "Table", "TableArray", "REQUIRED"]
