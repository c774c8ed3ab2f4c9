"""Study: normal force along the arcs of the 6+2n model for Ritz orders n = 1..9 (steady running).

Reference stationary regime (3500 rpm, 200 N m, ratio 2.4); writes
out/studies/lowered/normal_force_convergence.png and prints the relative L2 difference to n = 9
and the spread (max - min) / mean on each arc.

    .venv/bin/python studies/lowered/normal_force_convergence.py [--nodes 32]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from cvtfem.machines.cvt import band_model, closed_loop
from cvtfem.post.band import convergence_table, plot_normal_force
from cvtfem.scene.loader import load_scene


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=32)
    ap.add_argument("--out", default="out/studies/lowered")
    args = ap.parse_args()
    scene = load_scene("band-6+2n")
    loop = closed_loop(scene)
    F, phi = loop.clamping.forces(200.0, 2.4), loop.clamping.span_angle(2.4)
    curves = {}
    for n in range(1, 10):
        m = band_model(scene, n_ritz=n, n_gauss=args.nodes)
        curves[n] = m.steady_state(phi, 366.5, F, 200.0)[3]["N"]
    xi = m.arc_nodes(phi)[0] / (math.pi / 2 + phi)
    print(f"clamping F1 = {F[0] / 1e3:.2f} kN, F2 = {F[1] / 1e3:.2f} kN, phi = {phi:.4f} rad, {args.nodes} nodes/arc")
    print(f"{'n':>2} {'diff to n=9':>12} {'spread arc1':>12} {'spread arc2':>12} {'N1 entry/exit kN/m':>20}")
    for n, err in convergence_table(xi, curves):
        N = curves[n]
        spread = (N.max(axis=1) - N.min(axis=1)) / N.mean(axis=1)
        print(f"{n:>2} {err:>12.2e} {spread[0]:>12.3f} {spread[1]:>12.3f} {N[0, 0] / 1e3:>9.1f} / {N[0, -1] / 1e3:.1f}")
    out = plot_normal_force(xi, {f"n = {n}": curves[n] for n in (1, 2, 3, 5, 9)},
                            Path(args.out) / "normal_force_convergence.png",
                            "6+2n model: normal force per sheave, steady running, n = 1..9")
    print(f"figure: {out}")
    assert np.all(np.isfinite(curves[9]))


if __name__ == "__main__":
    main()
