"""Rigid, reduced and full sheaves on the `cvt_sheave_shaft` rotor: frequencies below 10 kHz against the full
sheaves, the cost of the eigen-solves and of the right-hand side, and the wedge opening at the reference
clamping force.

Run: ``python studies/sheaves/flexible_rotor.py`` (a few minutes; the full sheaves dominate).
"""
import numpy as np

from cvtfem.analysis.timing import machine, median_us, wall_times
from cvtfem.machines.rotor import build_model
from cvtfem.machines.sheave import sheave_indices, sheave_section
from cvtfem.modal import ModalProblem, campbell
from cvtfem.modal.sheave import wedge_opening
from cvtfem.scene.loader import load_scene

SPEED = 6000 * np.pi / 30                 # rad/s, the operating point of the Campbell range's middle
SPEEDS = np.linspace(0.0, 12000 * np.pi / 30, 13)
CLAMPING = 26e3                           # N, the reference clamping force (reference_cvt: 200 N m, 26 kN)
CASES = (("rigid", "rigid", 6, 12), ("reduced 4", "reduced", 4, 12), ("reduced 6", "reduced", 6, 12),
         ("reduced 10", "reduced", 10, 12), ("full", "full", 6, 12), ("reduced 6, 24x2", "reduced", 6, 24))

print(machine())
results = {}
for name, flexibility, modes, cells in CASES:
    scene = load_scene("cvt_sheave_shaft", {"sheave": {"flexibility": flexibility, "modes": modes,
                                                        "cells_radial": cells, "cells_axial": 2}})
    build = float(np.median(wall_times(lambda: build_model(scene), 1 if flexibility == "full" else 3)))
    model = build_model(scene)
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind)
    solve = float(np.median(wall_times(lambda: problem.solve(SPEED, 20), 3)))
    curves = campbell(problem, SPEEDS, 20).wd / (2 * np.pi)
    x = np.zeros(2 * model.n_dof)
    x[:model.n_dof] = np.random.default_rng(1).standard_normal(model.n_dof) * 1e-6
    rhs = median_us(lambda: model.rhs(0.0, x), 200 if flexibility != "full" else 20)
    results[name] = curves
    print(f"{name:>16}: {model.n_dof:5d} DOF ({problem.method}), build {build:6.2f} s, modes at 6000 rpm "
          f"{solve * 1e3:7.1f} ms, rhs {rhs:8.1f} us")
band = results["full"] < 10e3
for name in results:
    if name not in ("rigid", "full") and "24x2" not in name:          # the same 12 x 2 section mesh as "full"
        gap = np.abs(results[name][band] / results["full"][band] - 1).max()
        print(f"{name:>16}: Campbell (13 speeds, 0..12000 rpm, modes below 10 kHz) against full: {gap:.2e}")
scene = load_scene("cvt_sheave_shaft")
total = 0.0
for i in sheave_indices(scene):
    model, u = wedge_opening(sheave_section(scene, i), CLAMPING)
    total += -model.rim_mean(u)
    print(f"disk {i}: the rim moves back {-model.rim_mean(u) * 1e6:.1f} um under {CLAMPING / 1e3:.0f} kN (bore clamped)")
print(f"the wedge opens by {total * 1e6:.1f} um at the rim, both sheaves")

# the extra right-hand-side cost of the default reduced sheaves (8 modes), rigid and reduced calls interleaved
pair = {f: build_model(load_scene("cvt_sheave_shaft", {"sheave": {"flexibility": f, "cells_radial": 12}}))
        for f in ("rigid", "reduced")}
states = {f: np.random.default_rng(1).standard_normal(2 * m.n_dof) * 1e-6 for f, m in pair.items()}
times = {f: [] for f in pair}
for _ in range(7):
    for f, m in pair.items():
        times[f].append(median_us(lambda: m.rhs(0.0, states[f]), 2000, warm_up=True))
rigid_us, reduced_us = np.median(times["rigid"]), np.median(times["reduced"])
print(f"rhs: rigid {rigid_us:.1f} us ({pair['rigid'].n_dof} DOF), reduced (8 modes) {reduced_us:.1f} us "
      f"({pair['reduced'].n_dof} DOF): {100 * (reduced_us / rigid_us - 1):+.0f} %")
