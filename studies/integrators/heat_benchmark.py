"""Issue-4 benchmark: 1-D heat equation N=1000 to t=0.1 at relative error 1e-4.

For each method the cheapest setting meeting the target is found, then re-run; RHS calls and
the median wall time of 3 runs are printed with the machine and written to
``out/studies/integrators/heat_benchmark.csv``.

Run: ``.venv/bin/python studies/integrators/heat_benchmark.py [--repeats 3]``
(equivalent CLI: ``cvtfem study heat``).
"""
from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

from cvtfem.integrate.study import heat_benchmark
from cvtfem.post.integrators import write_csv

OUT = Path("out/studies/integrators")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    rows = heat_benchmark(N=args.N, repeats=args.repeats)
    print(f"machine: {platform.machine()} {platform.processor()} cores={os.cpu_count()} "
          f"Python {platform.python_version()}; median of {args.repeats} runs")
    print(f"{'method':22s} {'setting':16s} {'rel.err':>9s} {'RHS calls':>10s} {'of them Jac':>11s} {'time, s':>9s}")
    for r in rows:
        setting = ", ".join(f"{k}={r[k]:.3g}" for k in ("h", "rtol") if k in r) or str(r["status"])
        print(f"{r['label']:22s} {setting:16s} {r['error']:9.2e} {r['nfev']:10d} "
              f"{r.get('nfev_jac', 0):11d} {r['time']:9.4f}")
    rk4 = next(r for r in rows if r["method"] == "rk4")
    bdf = next(r for r in rows if r["method"] == "BDF")
    for r in rows:
        if r["method"] in ("rkc", "dumka3", "rock2", "rock4") and r["nfev"] > 0:
            print(f"{r['label']}: {rk4['nfev'] / r['nfev']:.0f}x fewer RHS calls than RK4")
    trap = next(r for r in rows if r["method"] == "trapezoidal")
    print(f"sparse trapezoid vs scipy BDF wall time: {trap['time']:.4f} s vs {bdf['time']:.4f} s "
          f"({bdf['time'] / trap['time']:.1f}x)")
    write_csv(rows, OUT / "heat_benchmark.csv")
    print(f"wrote {OUT / 'heat_benchmark.csv'}")


if __name__ == "__main__":
    main()
