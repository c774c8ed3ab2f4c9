"""Dense against sparse eigen-solves per block size: where ``ModalProblem(method="auto")`` should switch (issue 15).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/rotor/bench_backend.py   # -> out/studies/rotor/bench_backend.txt

A steel shaft of N Timoshenko elements (lateral block 4 (N + 1) DOF) with two disks and two damped anisotropic
cross-coupled bearings, spinning at 300 rad/s (gyroscopic, non-symmetric: the general path of both backends);
median wall time of one ``solve`` per backend for 6, 12 and 24 modes, plus ROSS's compressor (tests/data/ross).
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, wall_times
from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/rotor")
SIZES = (10, 20, 40, 60, 80, 100)


def shaft(n: int):  # noqa: ANN201 - RotorModel
    text = f"""
[[material]]
name = "steel"
E = 2.11e11
G = 8.12e10
rho = 7810.0
[[shaft]]
length = {1.5 / n}
outer_diameter = 0.05
material = "steel"
repeat = {n}
[[disk]]
node = {n // 3}
mass = 32.6
Id = 0.178
Ip = 0.330
[[disk]]
node = {2 * n // 3}
mass = 51.5
Id = 0.424
Ip = 0.805
[[bearing]]
node = 0
kxx = 1e6
kyy = 0.8e6
kxy = 1e5
cxx = 300.0
cyy = 250.0
[[bearing]]
node = {n}
kxx = 1e6
kyy = 0.8e6
kyx = -1e5
cxx = 300.0
cyy = 250.0
"""
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "shaft.toml"
        path.write_text(text)
        return build_model(load_scene(str(path)))


def per_solve(model, method: str, n_modes: int, calls: int = 5) -> float:
    """Median seconds of one solve at a new speed (speed-dependent blocks are never cached)."""
    p = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, method, speed_terms=model.speed_terms)
    speeds = iter(np.linspace(100.0, 500.0, calls + 1))
    return float(np.median(wall_times(lambda: p.solve(next(speeds), n_modes), calls, warm_up=True)))


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    lines = [f"machine: {machine()}", f"load average: {os.getloadavg()}",
             "lateral DOF | modes | dense (ms) | sparse (ms) | dense / sparse"]
    cases = [(f"shaft {n}", lambda n=n: shaft(n)) for n in SIZES]
    cases.append(("ROSS compressor", lambda: build_model(load_scene("tests/data/ross/compressor.toml"))))
    for label, build in cases:
        model = build()
        m = int(np.sum(np.isin(model.dof_kind, (0, 1, 3, 4))))
        for k in (6, 12, 24):
            d, s = per_solve(model, "dense", k), per_solve(model, "sparse", k)
            lines.append(f"{label:>16} {m:5d} | {k:3d} | {1e3 * d:9.2f} | {1e3 * s:9.2f} | {d / s:6.2f}")
            print(lines[-1], flush=True)
    lines.append(f"load average after: {os.getloadavg()}")
    (OUT / "bench_backend.txt").write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT / 'bench_backend.txt'}")


if __name__ == "__main__":
    main()
