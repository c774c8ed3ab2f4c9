"""Scene -> layout of element families, one module per kind of machine.

``layout(scene)`` answers *what* a scene's model consists of (components,
coordinate counts, discrete states, outputs) without building its physics;
``cvtfem describe`` prints it.
"""
from __future__ import annotations

from importlib import import_module

from cvtfem.elements.base import Layout
from cvtfem.scene.loader import Scene


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of the model a scene calls for, in DOF order."""
    module = import_module(f"cvtfem.machines.{scene.kind}")
    return module.layout(scene)  # type: ignore[no-any-return]


__all__ = ["layout"]
