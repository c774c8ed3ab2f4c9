"""Accuracy of fast integrator settings against a tight reference (Radau rtol 1e-8, atol 1e-10).

1 s of the reference stationary regime (3500 rpm, 200 N m, ratio 2.4), started in steady running
(``--start steady``, the benchmark's start) or at ratio 2.3 and 4 % slow (``--start away``: the loops
work).  Prints ratio, speeds and output/input work at the end of each run, and their differences to
the reference (and the largest difference of the normal force along the arcs, relative to its
maximum, where the node counts agree); the reference is kept in ``out/studies/lowered/reference-MODEL-START.json``.

    .venv/bin/python studies/lowered/accuracy_realtime.py --model band-6+2n --start away \
        --settings Radau:1e-3:1e-5 Radau:1e-4:1e-6
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/lowered")


def run(loop, start: str, method: str, rtol: float, atol: float, until: float) -> dict:
    x0 = loop.initial_state(**({"ratio": 2.3, "speed_factor": 0.96} if start == "away" else {}))
    t0 = time.perf_counter()
    sol = solve_ivp(loop.rhs, (0, until), x0, method=method, rtol=rtol, atol=atol, jac=loop.jac)
    wall = time.perf_counter() - t0
    q, v, _, W = loop.split(sol.y[:, -1])
    k1, k2 = loop.model.speed_indices()
    N = loop.evaluate(sol.t[-1], sol.y[:, -1])[1].get("N", np.zeros(0))  # (2, nodes) N/m; none for 4-DOF
    return {"method": method, "rtol": rtol, "atol": atol, "wall_s": wall, "steps": len(sol.t) - 1, "nfev": sol.nfev,
            "ratio": v[k1] / v[k2], "omega1": v[k1], "omega2": v[k2], "work_ratio": W[1] / W[0], "status": sol.status,
            "N": np.asarray(N).tolist()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="band-6+2n")
    ap.add_argument("--start", choices=("steady", "away"), default="steady")
    ap.add_argument("--until", type=float, default=1.0)
    ap.add_argument("--nodes", type=int, default=0, help="Gauss nodes per arc (0: preset)")
    ap.add_argument("--settings", nargs="*", default=["Radau:1e-3:1e-5", "Radau:1e-4:1e-6", "Radau:1e-6:1e-8"])
    args = ap.parse_args()
    loop = closed_loop(load_scene(args.model), **({"n_gauss": args.nodes} if args.nodes else {}))
    OUT.mkdir(parents=True, exist_ok=True)
    ref_file = OUT / f"reference-{args.model}-{args.start}-{args.until:g}s.json"
    if ref_file.exists():
        ref = json.loads(ref_file.read_text())
    else:
        ref = run(closed_loop(load_scene(args.model)), args.start, "Radau", 1e-8, 1e-10, args.until)
        ref_file.write_text(json.dumps(ref, indent=1))
    keys = ("ratio", "omega1", "omega2", "work_ratio")
    print(f"reference Radau 1e-8/1e-10 ({ref['steps']} steps, {ref['wall_s']:.1f} s wall): "
          + ", ".join(f"{k} {ref[k]:.9f}" for k in keys))
    for entry in args.settings:
        m, r, a = entry.split(":")
        res = run(loop, args.start, m, float(r), float(a), args.until)
        print(f"{m} {float(r):.0e}/{float(a):.0e} nodes {loop.model.p.n_gauss}: {res['steps']} steps, "
              f"{res['nfev']} nfev, {res['wall_s']:.3f} s wall; "
              + ", ".join(f"{k} {res[k]:.9f} ({res[k] - ref[k]:+.1e})" for k in keys)
              + (f"; normal force max |dN| / max N {np.abs(np.subtract(res['N'], ref['N'])).max() / np.max(ref['N']):.1e}"
                 if 0 < len(res["N"]) == len(ref["N"]) else ""), flush=True)


if __name__ == "__main__":
    main()
