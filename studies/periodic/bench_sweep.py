"""Benchmark: sweeps through folds by arclength continuation (issue 18, deliverable 2).

Run:  .venv/bin/python studies/periodic/bench_sweep.py [--repeats 3]
Prints medians of several runs (wall and CPU time) and the machine, for

1. the acceptance oscillator (1 DOF, hardening one-sided stop, N = 16, M = 1024) swept 0.6 -> 1.8
   and 1.8 -> 0.6 rad/s (25 requested points): steps, rejected steps, continuation points, folds,
   continuation time, and the whole `response_sweep` with Floquet stability of every point;
2. the engine gear train, 12 -> 15 Hz, N = 32 (3 requested points): the same without stability,
   and one Floquet integration.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from cvtfem.machines.torsional import build
from cvtfem.periodic.continuation import continuation
from cvtfem.periodic.response import response_sweep
from cvtfem.periodic.stability import floquet
from cvtfem.scene.loader import load_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "periodic"))
from test_continuation_sweep import M, N, stop_oscillator  # noqa: E402  (the acceptance oscillator)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_periodic import machine  # noqa: E402


def timed(fn, repeats: int):
    """Median wall and CPU time (s) of ``fn()`` and its last result."""
    walls, cpus, out = [], [], None
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return float(np.median(walls)), float(np.median(cpus)), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    r = ap.parse_args().repeats
    print(machine())
    net = stop_oscillator()
    for a, b in ((0.6, 1.8), (1.8, 0.6)):
        targets = np.linspace(a, b, 25)
        wall, cpu, br = timed(lambda: continuation(net, a, b, N, samples=M, targets=targets), r)
        print(f"oscillator {a} -> {b} rad/s: {br.steps} steps ({br.rejected} rejected), {len(br.solutions)} points, "
              f"folds at {', '.join(f'{w:.6f}' for w in br.fold_omega)} rad/s; continuation {wall:.2f} s wall, "
              f"{cpu:.2f} s CPU")
        wall, cpu, sw = timed(lambda: response_sweep(net, targets, N, samples=M), r)
        print(f"  response_sweep with Floquet at {len(sw.omega)} points and end checks: {wall:.2f} s wall, "
              f"{cpu:.2f} s CPU")
    eng = build(load_scene("engine_gear_train"))
    targets = 2 * np.pi * np.linspace(12, 15, 3)
    wall, cpu, sw = timed(lambda: response_sweep(eng, targets, 32, stability=False), r)
    br = sw.branch
    print(f"engine 12 -> 15 Hz, N = 32: {br.steps} steps ({br.rejected} rejected), {len(br.solutions)} points, "
          f"{len(br.fold_omega)} folds; response_sweep without stability {wall:.2f} s wall, {cpu:.2f} s CPU")
    wall, cpu, fl = timed(lambda: floquet(sw.nonlinear[0], rtol=1e-8), r)
    print(f"  one Floquet integration (12 Hz): {fl.nfev} RHS calls, {wall:.2f} s wall, {cpu:.2f} s CPU")


if __name__ == "__main__":
    main()
