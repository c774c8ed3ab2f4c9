"""Benchmark: sweep throughput (variants per minute) on 1 and 2 workers, local process pool and dask LocalCluster,
with each engine's fixed start-up cost and per-variant overhead.

Run:  .venv/bin/python studies/sweeps/bench_throughput.py [--repeats 3] [--until 0.05]
Prints medians of ``--repeats`` runs and the machine.

Each run is a fresh sweep of cheap variants (band-4dof, ``--until`` s, distinct input torques) into a new
folder; the engine is started by the sweep (pool or LocalCluster) and closed at its end.  From the wall times
T(n) of sweeps of n1 and n2 variants: marginal time per variant m = (T(n2) - T(n1)) / (n2 - n1), throughput
60 / m variants per minute, fixed cost T(n1) - n1 m (engine start, worker imports, compile-cache loads, shut
down) and per-variant overhead m * workers - c, with c the median compute time of a variant inside its worker
(``wall_s`` of the index: scene parse, model build, run).
"""
from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.analysis.sweep import expand, run_sweep
from cvtfem.scene.loader import load_scene

SIZES = (8, 56)


def sweep_wall(base, engine: str, workers: int, n: int, until: float, offset: float) -> tuple[float, float]:
    """Wall time of one fresh sweep of ``n`` variants, and the median compute time of a variant in its worker."""
    variants = expand([("cvt.regime.torque", list(np.linspace(100.0, 200.0, n) + offset))])
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        index = run_sweep(base, variants, "run", out, engine, workers, options={"until": until}, show_progress=False)
        wall = time.perf_counter() - t
    assert all(e["status"] == "finished" for e in index["variants"])
    return wall, float(np.median([e["wall_s"] for e in index["variants"]]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--until", type=float, default=0.05, help="simulated time of a variant, s")
    args = ap.parse_args()
    base = load_scene("band-4dof")
    print(f"machine: {machine()}")
    print(f"variants: band-4dof, {args.until:g} s simulated each; sweeps of {SIZES[0]} and {SIZES[1]} variants, "
          f"median of {args.repeats}")
    print(f"{'engine':<7}{'workers':>8}{'var/min':>10}{'fixed s':>9}{'compute s':>11}{'overhead s':>12}")
    k = 0
    for engine in ("local", "dask"):
        for workers in (1, 2):
            rows = []
            for _ in range(args.repeats):
                (t1, c1), (t2, c2) = (sweep_wall(base, engine, workers, n, args.until, 1e-3 * (k := k + 1))
                                      for n in SIZES)
                m = (t2 - t1) / (SIZES[1] - SIZES[0])
                c = float(np.median([c1, c2]))
                rows.append((60 / m, t1 - SIZES[0] * m, c, m * workers - c))
            r = np.median(np.array(rows), axis=0)
            print(f"{engine:<7}{workers:>8}{r[0]:>10.0f}{r[1]:>9.2f}{r[2]:>11.3f}{r[3]:>12.3f}", flush=True)
    print(f"machine after: {machine()}")


if __name__ == "__main__":
    main()
