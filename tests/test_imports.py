"""`import cvtfem` and its computing packages load neither matplotlib nor pyvista."""
from __future__ import annotations

import subprocess
import sys

MODULES = ["cvtfem", "cvtfem.scene.loader", "cvtfem.integrate", "cvtfem.modal", "cvtfem.periodic.hb",
           "cvtfem.machines.cvt", "cvtfem.analysis.run", "cvtfem.post.band", "cvtfem.cli"]


def test_no_plotting_on_import():
    code = ("import sys\n" + "".join(f"import {m}\n" for m in MODULES)
            + "print(sorted(m for m in ('matplotlib', 'pyvista', 'vtk') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
