"""Layout of a torsional network scene (filled in by the periodic-response work, issue 6)."""
from __future__ import annotations

from cvtfem.elements.base import Layout
from cvtfem.errors import InputError
from cvtfem.scene.loader import Scene


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of a torsional network."""
    raise InputError("torsional", "network", "is not available yet")
