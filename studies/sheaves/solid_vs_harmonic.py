"""The 3D quadratic-tetrahedron sheave against the axisymmetric-harmonic model on the same section mesh:
rim deflection under a ring load and the lowest bore-clamped frequencies, with wall times.

Run: ``python studies/sheaves/solid_vs_harmonic.py``
"""
import platform
import time

import numpy as np

from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection, SolidSheave

SHEAVE = SheaveSection(0.0175, 0.03, 0.095, 0.03, 0.008, np.radians(10.0))   # as tests/elements/test_sheave_solid.py
P = 20000.0                                                                    # N, ring load at the rim

t0 = time.perf_counter()
harmonic = []
for n, family, count in ((0, "cos", 1), (0, "sin", 1), (1, "cos", 2), (2, "cos", 1), (3, "cos", 1), (4, "cos", 1)):
    f, _ = HarmonicSheave(SHEAVE, n, family, 12, 2).modes(count)
    harmonic += [(v, f"n={n} {family}") for v in f] * (1 if n == 0 else 2)
axisym = HarmonicSheave(SHEAVE, 0, n_r=12, n_z=2)
w2 = axisym.rim_mean(axisym.static(axisym.rim_load(P)))
t_h = time.perf_counter() - t0
t0 = time.perf_counter()
solid = SolidSheave(SHEAVE, n_r=12, n_z=2, n_theta=48)
u = solid.static(solid.rim_load(P))
p = solid.basis.mesh.p
w3 = u[solid.basis.nodal_dofs[2]][np.hypot(p[0], p[1]) > SHEAVE.outer_radius * (1 - 1e-9)].mean()
f3, _ = solid.modes(12)
t_s = time.perf_counter() - t0
print(f"{platform.processor() or platform.machine()}; harmonic models {t_h:.1f} s, 3D ({solid.matrices[0].shape[0]} DOF) {t_s:.1f} s")
print(f"rim deflection under {P:g} N: harmonic {w2 * 1e6:.3f} um, 3D {w3 * 1e6:.3f} um ({w3 / w2 - 1:+.2%})")
for (fh, label), f in zip(sorted(harmonic), f3):
    print(f"  {label:<9} harmonic {fh:9.1f} Hz   3D {f:9.1f} Hz   {f / fh - 1:+.2%}")
