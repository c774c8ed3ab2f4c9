"""Scene -> model (:class:`~cvtfem.assembly.model.Model`) and layout, one module per kind of machine.

``build_model(scene)`` builds the model of any machine kind in one pass (band CVT: ``cvt.closed_loop``,
rotor and torsional network: their ``build_model``); ``layout(scene)`` answers *what* a scene's
model consists of (components, coordinate counts, discrete states, outputs) without building its
physics; ``describe(scene)`` is that answer as text (``cvtfem describe`` prints it).
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


def describe(scene: Scene) -> str:
    """The scene's effects and its model's components, coordinates and outputs, as text."""
    parts = layout(scene)
    lines = [f"scene: {scene.title or scene.source} ({scene.kind}; from {scene.source})"]
    if scene.description:
        lines.append(f"  {scene.description}")
    if scene.kind == "cvt":
        lines.append(f"model: {scene.cvt.model}")
        effects = scene.cvt.effects
        lines.append("effects: " + ", ".join(f"{k}={'on' if v is True else 'off' if v is False else v}"
                                             for k, v in effects.items()))
    lines += ["", "components:",
              f"  {'name':<16} {'family':<24} {'coords':>7} {'states':>7} {'discrete':>9}  how"]
    for part in parts:
        lines.append(f"  {part.name:<16} {part.kind:<24} {part.n2:>7} {part.n1:>7} {part.discrete:>9}  {part.note}")
    n2 = sum(p.n2 for p in parts)
    n1 = sum(p.n1 for p in parts)
    lines.append(f"  {'total':<16} {'':<24} {n2:>7} {n1:>7} {sum(p.discrete for p in parts):>9}"
                 f"  ODE size 2 x {n2} + {n1} = {2 * n2 + n1}")
    lines += ["", "outputs:"]
    for part in parts:
        for out in part.outputs:
            size = f"[{out.size}]" if out.size > 1 else ""
            lines.append(f"  {out.name + size:<34} {out.unit:<6} {out.doc}")
    return "\n".join(lines)


__all__ = ["BUILDERS", "build_model", "describe", "layout"]
