"""Scene -> model (:class:`~cvtfem.assembly.model.Model`) and layout, one module per kind of machine.

``build_model(scene)`` builds the model of any machine kind in one pass (band CVT: ``cvt.closed_loop``,
rotor and torsional network: their ``build_model``); ``layout(scene)`` answers *what* a scene's
model consists of (components, coordinate counts, discrete states, outputs) without building its
physics; ``cvtfem describe`` prints it.
"""
from __future__ import annotations

from importlib import import_module
from typing import Any

from cvtfem.elements.base import Layout
from cvtfem.scene.loader import Scene


#: The model builder of each machine kind (module attribute names).
BUILDERS = {"cvt": "closed_loop", "rotor": "build_model", "torsional": "build_model"}


def build_model(scene: Scene, **options: Any) -> Any:
    """The :class:`~cvtfem.assembly.model.Model` of a scene (``options``: the machine kind's builder's keywords)."""
    module = import_module(f"cvtfem.machines.{scene.kind}")
    return getattr(module, BUILDERS[scene.kind])(scene, **options)


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of the model a scene calls for, in DOF order."""
    module = import_module(f"cvtfem.machines.{scene.kind}")
    return module.layout(scene)  # type: ignore[no-any-return]


__all__ = ["BUILDERS", "build_model", "layout"]
