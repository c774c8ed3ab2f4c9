"""Regenerate the section meshes in meshes/ (meshio VTU, quadratic triangles).

    .venv/bin/python studies/rotor/make_section_meshes.py
"""
from pathlib import Path

import meshio
import numpy as np

from cvtfem.sections.meshes import MESH_DIR, annulus_mesh, disk_mesh, pin_mesh

MESHES = {
    "circle_d50mm.vtu": lambda: disk_mesh(0.025, nrefs=4),            # Friswell shaft, solid 50 mm
    "hollow_circle_d80_d48mm.vtu": lambda: annulus_mesh(0.024, 0.040, n_radial=6, n_theta=96),
    "rocker_pin.vtu": lambda: pin_mesh(3.0e-3, 1.2e-3, 4.0e-3, nrefs=4),
}


def main(out: Path = MESH_DIR) -> None:
    from skfem.io.meshio import to_meshio

    out.mkdir(exist_ok=True)
    for name, make in MESHES.items():
        m = to_meshio(make())
        xyz = np.column_stack([m.points[:, :2], np.zeros(len(m.points))])
        meshio.write(out / name, meshio.Mesh(xyz, m.cells), binary=True)
        print(f"wrote {out / name}: {len(m.points)} points")


if __name__ == "__main__":
    main()
