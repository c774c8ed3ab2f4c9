"""Steady-state start of the band models on the operating grid (issue 18): which regimes start steady.

Sweeps input speed x driving torque x ratio for ``band-6+2n`` and ``band-6+2n+8`` and calls the machine's
``start`` (the start of ``cvtfem run``) at every regime; prints each regime that does not start in steady
running (a NumericalError, or the start without slip with its warning), the largest residual (relative Newton
correction) of the steady starts and the wall time.  Before the fix of issue 18, 16 (band-6+2n) and 22
(band-6+2n+8) of the 2,508 regimes ended in "not making good progress"; now none.

    .venv/bin/python studies/band/steady_start_grid.py [--models band-6+2n,band-6+2n+8] [--coarse]
"""
from __future__ import annotations

import argparse
import logging
import math
import platform
import time

import numpy as np

from cvtfem.errors import NumericalError
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

RPM = math.pi / 30
#: The full grid: 11 speeds x 19 torques x 12 ratios = 2,508 regimes.
SPEEDS = np.arange(1000.0, 6001.0, 500.0)
TORQUES = np.r_[20.0, np.arange(25.0, 451.0, 25.0)]
RATIOS = np.array([0.45, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4, 1.7, 2.0, 2.4])
#: A coarse grid (27 regimes) through the corners and band-6+2n's failure of issue 18 (3000 rpm, 300 N m, 0.8).
COARSE = (np.array([1000.0, 3000.0, 6000.0]), np.array([20.0, 300.0, 450.0]), np.array([0.45, 0.8, 2.4]))


def sweep(model: str, grid=(SPEEDS, TORQUES, RATIOS)) -> list[dict]:
    """One record per regime: ``rpm, torque, ratio, outcome`` ("steady", "no-slip" or "error") and ``detail``
    (the residual of a steady start, the warning or the error)."""
    loop = closed_loop(load_scene(model))
    records = []
    for rpm in grid[0]:
        for torque in grid[1]:
            for ratio in grid[2]:
                lp = loop.with_regime(kind="stationary", input_speed=rpm * RPM, torque=torque, ratio=ratio)
                rec = dict(rpm=float(rpm), torque=float(torque), ratio=float(ratio))
                try:
                    s = lp.start()[1]
                except NumericalError as err:
                    rec.update(outcome="error", detail=str(err))
                else:
                    rec.update(outcome=s["kind"], detail=s.get("residual", s.get("warning")))
                records.append(rec)
    return records


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", default="band-6+2n,band-6+2n+8")
    ap.add_argument("--coarse", action="store_true", help="the 27-regime grid of the default test suite")
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR)
    grid = COARSE if args.coarse else (SPEEDS, TORQUES, RATIOS)
    print(f"{platform.machine()}, {platform.python_version()}; grid {' x '.join(str(len(g)) for g in grid)}")
    for model in args.models.split(","):
        t0 = time.perf_counter()
        recs = sweep(model, grid)
        wall = time.perf_counter() - t0
        bad = [r for r in recs if r["outcome"] != "steady"]
        steady = [r["detail"] for r in recs if r["outcome"] == "steady"]
        print(f"{model}: {len(recs)} regimes, {len(recs) - len(bad)} steady (largest residual "
              f"{max(steady, default=math.nan):.2e}), {sum(r['outcome'] == 'no-slip' for r in bad)} started "
              f"without slip, {sum(r['outcome'] == 'error' for r in bad)} errors; {wall:.1f} s wall "
              f"({1e3 * wall / len(recs):.1f} ms per regime)")
        for r in bad:
            print(f"  {r['rpm']:6.0f} rpm {r['torque']:5.0f} N m ratio {r['ratio']:4.2f}: {r['outcome']}: "
                  f"{r['detail']}")


if __name__ == "__main__":
    main()
