"""Benchmark: wall time for 1 s of simulated time of the reference stationary regime, per dynamic band model.

Default: ``cvtfem run`` as users run it (``run_scene`` with the preset's solver and its 1 ms output
step), once with a results file (every output sampled and written) and once without, alternating so
that both see the same load; wall time of the whole ``run_scene`` call (closed loop, steady start,
stepping, outputs, file closed) and process CPU time, median of ``--repeat`` runs, per simulated second.
Target (issue 12, not asserted): <= 0.1 s wall per simulated second for band-4dof and band-6+2n with
the results file on.

``--integrators`` instead times the bare closed loop under several integrator settings (no outputs):
scipy's ``solve_ivp`` with ``BandCVT.jac`` or cvtfem's methods through ``cvtfem.integrate.solve``
with the loop's ``n2`` structure.  BDF is slow on the compressible models (lightly damped elastic modes;
BDF orders > 2 are not A-stable): pass ``--methods Radau`` for them.  ``--settings Radau:1e-3:1e-5``
replaces the list of settings, ``--nodes 8`` overrides the Gauss nodes per arc, ``--numpy`` runs the
numpy twin of the compiled right-hand side, ``--fd-jac`` the finite-difference Jacobian of the whole loop.

Prints the machine and the load average (1 min) before and after each model.

    .venv/bin/python studies/lowered/bench_realtime.py [--repeat 5] [--until 1.0] [--integrators]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

from scipy.integrate import solve_ivp

from cvtfem.analysis.run import run_scene
from cvtfem.integrate import METHODS, solve
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

SETTINGS = [("Radau", 1e-6, 1e-8), ("Radau", 1e-4, 1e-6), ("Radau", 1e-3, 1e-5), ("BDF", 1e-3, 1e-5),
            ("LSODA", 1e-3, 1e-5)]


def load() -> float:
    """Load average over the last minute (nan where the OS has none)."""
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")


def bench_run(name: str, until: float, repeat: int, out: Path) -> dict[bool, tuple]:
    """``run_scene`` with (True) and without (False) a results file: medians of wall and CPU time (s) and the
    last summary, keyed by whether the file was on."""
    scene = load_scene(name)
    run_scene(scene, until=min(until, 0.01), results=out / f"{name}-warm.h5", show_progress=False)  # compile, import
    times: dict[bool, list] = {False: [], True: []}
    last = {}
    for i in range(repeat):
        for results in (False, True):
            path = out / f"{name}-{i}.h5" if results else None
            t0, c0 = time.perf_counter(), time.process_time()
            last[results] = run_scene(scene, until=until, results=path, show_progress=False)
            times[results].append((time.perf_counter() - t0, time.process_time() - c0))
    return {r: (statistics.median(w for w, _ in ts), statistics.median(c for _, c in ts), last[r])
            for r, ts in times.items()}


def bench(name: str, method: str, rtol: float, atol: float, until: float, repeat: int, numpy: bool = False,
          fd_jac: bool = False, **over):
    """Bare closed loop under one integrator setting: medians of wall and CPU time (s), counters, final ratio."""
    loop = closed_loop(load_scene(name), **over)
    if numpy and hasattr(loop.model, "use_numba"):
        loop = dataclasses.replace(loop, model=dataclasses.replace(loop.model, use_numba=False))
    walls, cpus, last = [], [], None
    for _ in range(repeat):
        x0 = loop.initial_state()
        t0, c0 = time.perf_counter(), time.process_time()
        jac = loop.jac_fd if fd_jac else loop.jac
        if method in METHODS:
            sol = solve(loop.rhs, (0, until), x0, method=method, rtol=rtol, atol=atol, jac=jac, n2=loop.model.n2)
            nfev, njev, steps = sol.stats["nfev"], sol.stats["njev"], sol.stats["nsteps"]
        else:
            sol = solve_ivp(loop.rhs, (0, until), x0, method=method, rtol=rtol, atol=atol, jac=jac)
            nfev, njev, steps = sol.nfev, sol.njev, len(sol.t) - 1
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        last = sol
    k1, k2 = loop.model.speed_indices()
    n = loop.model.n2
    return statistics.median(walls), statistics.median(cpus), nfev, njev, steps, last.y[n + k1, -1] / last.y[n + k2, -1]


def main_run(args) -> None:
    print(f"{'model':<13} {'method':<8} {'rtol':>7} {'results':>8} {'wall/s_sim':>11} {'cpu/s_sim':>10} "
          f"{'steps':>6} {'nfev':>6} {'ratio':>7} {'x real time':>11} {'load':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.models:
            before = load()
            res = bench_run(name, args.until, args.repeat, Path(tmp))
            after = load()
            for results in (False, True):
                wall, cpu, s = res[results]
                per = wall / args.until
                print(f"{name:<13} {s.solver['name']:<8} {s.solver['rtol']:>7.0e} {'file' if results else 'none':>8} "
                      f"{per:>11.3f} {cpu / args.until:>10.3f} {s.solver['steps']:>6} {s.solver['nfev']:>6} "
                      f"{s.ratio:>7.4f} {1 / per:>11.1f} {before:>5.1f}-{after:<5.1f}", flush=True)


def main_integrators(args) -> None:
    settings = SETTINGS if args.settings is None else [
        (m, float(r), float(a)) for m, r, a in (e.split(":") for e in args.settings)]
    print(f"{'model':<13} {'method':<12} {'rtol':>7} {'wall/s_sim':>11} {'cpu/s_sim':>10} {'steps':>6} {'nfev':>6} "
          f"{'njev':>5} {'ratio':>7} {'x real time':>11}")
    for name in args.models:
        over = {"n_gauss": args.nodes} if args.nodes and name != "band-4dof" else {}
        for method, rtol, atol in settings:
            if args.methods and method not in args.methods:
                continue
            wall, cpu, nfev, njev, steps, ratio = bench(name, method, rtol, atol, args.until, args.repeat,
                                                        args.numpy, args.fd_jac, **over)
            per = wall / args.until
            print(f"{name:<13} {method:<12} {rtol:>7.0e} {per:>11.3f} {cpu / args.until:>10.3f} {steps:>6} {nfev:>6} "
                  f"{njev:>5} {ratio:>7.4f} {1 / per:>11.2f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--until", type=float, default=1.0)
    ap.add_argument("--models", nargs="*", default=["band-4dof", "band-6+2n", "band-6+2n+8"])
    ap.add_argument("--integrators", action="store_true", help="bare loop under integrator settings, no outputs")
    ap.add_argument("--methods", nargs="*", default=None, help="only these methods (e.g. Radau BDF)")
    ap.add_argument("--settings", nargs="*", default=None, help="METHOD:RTOL:ATOL entries replacing the defaults")
    ap.add_argument("--nodes", type=int, default=0, help="Gauss nodes per arc (compressible models; 0: preset)")
    ap.add_argument("--numpy", action="store_true", help="numpy twin instead of the compiled right-hand side")
    ap.add_argument("--fd-jac", action="store_true", help="finite-difference Jacobian of the whole loop")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"python {platform.python_version()}, load average {load():.1f}; median of {args.repeat}")
    (main_integrators if args.integrators else main_run)(args)
    print(f"load average at the end {load():.1f}")


if __name__ == "__main__":
    main()
