"""Layout of a rotor scene: shaft beam elements, disks, bearings (6 DOF per node)."""
from __future__ import annotations

from cvtfem.elements.base import Layout, OutputSpec
from cvtfem.scene.loader import Scene


def layout(scene: Scene) -> tuple[Layout, ...]:
    """Components of a rotor model: the beam carries all nodal DOFs."""
    n_elements = sum(s.repeat for s in scene.shaft)
    nodes = n_elements + 1
    parts = [Layout("shaft", "timoshenko-beam", 6 * nodes,
                    outputs=(OutputSpec("shaft.displacement", "m", "Nodal displacements and rotations.", 6 * nodes),),
                    note=f"{nodes} nodes x 6")]
    if scene.disk:
        parts.append(Layout("disks", "rigid-disk", 0, note=f"{len(scene.disk)} disks on shaft nodes"))
    if scene.bearing:
        parts.append(Layout("bearings", "linear-bearing", 0,
                            outputs=(OutputSpec("bearing.force", "N", "Bearing forces x, y.", 2 * len(scene.bearing)),),
                            note=f"{len(scene.bearing)} bearings on shaft nodes"))
    return tuple(parts)
