"""Friswell et al. (2010) example 5.9.1: cvtfem frequencies against the published ones (Markdown table).

    .venv/bin/python studies/rotor/friswell_table.py   # -> out/studies/rotor/friswell_5_9_1.md
"""
from pathlib import Path

import numpy as np

from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem
from cvtfem.scene.loader import load_scene

#: Published natural frequencies, rad/s (bending pairs and the torsional mode).
REFERENCE = {0: [86.66, 86.66, 274.31, 274.31, 650.41, 716.79, 716.79],
             4000: [85.39, 87.80, 251.78, 294.71, 600.18, 650.41]}
OUT = Path("out/studies/rotor")


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    m = build_model(load_scene("friswell_5_9_1"))
    problem = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)
    rows = ["| speed (rpm) | reference (rad/s) | cvtfem (rad/s) | whirl | deviation |", "|---|---|---|---|---|"]
    for rpm, ref in REFERENCE.items():
        res = problem.solve(rpm * np.pi / 30, len(ref))
        for w, kind, r in zip(res.wd, res.whirl, ref):
            rows.append(f"| {rpm} | {r:.2f} | {w:.3f} | {kind} | {100 * (w - r) / r:+.4f} % |")
    text = "\n".join(rows) + "\n"
    (OUT / "friswell_5_9_1.md").write_text(text)
    print(text + f"wrote {OUT / 'friswell_5_9_1.md'}")


if __name__ == "__main__":
    main()
