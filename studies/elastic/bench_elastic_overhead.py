"""What the elastic structure costs in variants (b), (e) and (zh): one RHS and one Jacobian on elastic against rigid
shafts, the compiled mapped-contact pass against its numpy twin, and (``--runs``) `cvtfem run` per simulated ms.

    OPENBLAS_NUM_THREADS=1 nice .venv/bin/python studies/elastic/bench_elastic_overhead.py [--calls 200]
        [--jac-calls 6] [--scenes variant-b,regime-stationary:variant-e,regime-stationary:variant-zh,regime-stationary]
        [--runs]

Per scene the transmission on the scene's elastic shafts and on rigid shafts (its ``rigid()``), made running states
(chain offsets 0.2 um, velocities 0.05 m/s, sheave tilts 0.2 mrad on the elastic shafts) from the rigid placement
on the undeformed shafts (A5: ``placed``; A1 (b): the quasi-static start, whose rigid and elastic solves take some
seconds); medians of the wall and CPU time (``time.process_time``) of single calls alternating between two states, so
that no cached block is reused.  ``--runs``: `cvtfem run` of ``variant-e --until 2e-4`` and ``variant-b --until 1e-3``
with the preset's rock4 and with fixed-step RK4 at 1e-6 s (``studies/elastic/variant-*-rk4.toml``), results file and
outputs on; per run the wall and CPU time of the process, the integration's wall time (the summary's) and CPU time (the
process's less that of a run to 1 us: start, build, imports; and RHS calls times the benchmark's RHS CPU time where
the scene was benchmarked: (e)'s start, 40 s CPU, swamps the difference of a 0.2 ms run), steps, RHS calls, and the
projection to 1 s.  The machine and its load are printed before
and after.  docs/transmission.md, "Variant (b)" and "Variants (e) and (zh) on elastic shafts".
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene

HERE = Path(__file__).resolve().parent
RUNS = (("variant-e", "2e-4", ("variant-e", str(HERE / "variant-e-rk4.toml"))),
        ("variant-b", "1e-3", ("variant-b", str(HERE / "variant-b-rk4.toml"))))


def running(model, x0, seed: int, tilt: float):
    """``x0`` with random chain offsets (0.2 um), velocities (0.05 m/s) and, on elastic shafts, sheave tilts."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    s = getattr(model, "structure", None)
    if s is not None:
        tilts = nc + s.sheave_dofs[:, :, 3:5].ravel()
        x[tilts] += rng.normal(0.0, tilt, tilts.size)
    return x


def medians(fn, states, calls: int) -> tuple[float, float]:
    """Median wall and CPU time (s) of ``calls`` single calls ``fn(state)`` alternating between ``states`` (after one
    untimed call on each)."""
    for x in states:
        fn(x)
    wall, cpu = np.empty(calls), np.empty(calls)
    for k in range(calls):
        x = states[k % len(states)]
        c0, t0 = time.process_time(), time.perf_counter()
        fn(x)
        wall[k], cpu[k] = time.perf_counter() - t0, time.process_time() - c0
    return float(np.median(wall)), float(np.median(cpu))


def models(name: str):
    """``(elastic, x0, rigid, x0r)``: the scene's transmission on elastic shafts with the faces' references of the
    rigid placement (A5) or start (A1), and the same on rigid shafts."""
    model = chain_loop(load_scene(name))
    rigid = model.rigid()
    w1, _, ratio = model.regime.targets(0.0)
    if hasattr(model, "placed"):
        elastic, x0 = model.placed(ratio, w1)
        return elastic, x0, rigid, rigid.placed_state(ratio, w1)
    x0, rep = model.start()
    elastic = rep["model"]
    return elastic, x0, rigid, elastic.rigid_start[2]


def bench_scene(name: str, calls: int, jac_calls: int) -> float:
    """Print the RHS and Jacobian medians on elastic and rigid shafts and the mapped contacts' two paths; return the
    elastic RHS's median CPU time (s)."""
    elastic, x0, rigid, x0r = models(name)
    print(f"\n{name} ({type(elastic).__name__}, {elastic.n2} coordinates; rigid {rigid.n2}):")
    rows = {}
    for label, model, x, tilt in (("elastic", elastic, x0, 2e-4), ("rigid", rigid, x0r, 0.0)):
        states = [running(model, x, seed, tilt) for seed in (1, 2)]
        rows[label] = (medians(lambda y: model.rhs(0.0, y), states, calls),
                       medians(lambda y: model.jac(0.0, y), states, jac_calls))
        if label == "elastic":
            qv = [(y[:model.n2], y[model.n2:2 * model.n2]) for y in states]
            contacts = len(model._candidates(qv[0][0])[0])
            paths = {ref: medians(lambda s, r=ref: model._mapped_forces(*qv[s], np.zeros(model.n2), reference=r),
                                  [0, 1], calls) for ref in (False, True)}
            jpaths = {ref: medians(lambda s, r=ref: model._mapped_contact_jacobian(*qv[s], reference=r), [0, 1],
                                   jac_calls) for ref in (False, True)}
    for label, ((rw, rc), (jw, jc)) in rows.items():
        print(f"  {label:8s} one RHS {1e6 * rw:7.0f} us wall, {1e6 * rc:7.0f} us CPU; one Jacobian {1e3 * jw:7.1f} ms "
              f"wall, {1e3 * jc:7.1f} ms CPU")
    (erw, erc), (ejw, ejc) = rows["elastic"]
    (rrw, rrc), (rjw, rjc) = rows["rigid"]
    print(f"  elastic - rigid: RHS {1e6 * (erc - rrc):+.0f} us CPU ({1e6 * (erw - rrw):+.0f} us wall); Jacobian "
          f"{ejc / rjc:.2f}x CPU ({ejw / rjw:.2f}x wall)")
    mapped = "compiled" if elastic._compiled_mapped is not None else "numpy (no compiled path)"
    print(f"  mapped contacts ({contacts} candidates, {mapped}): forces {1e6 * paths[False][1]:.0f} us CPU against "
          f"the numpy twin's {1e6 * paths[True][1]:.0f} us; local Jacobians and entries "
          f"{1e3 * jpaths[False][1]:.1f} ms CPU against {1e3 * jpaths[True][1]:.1f} ms")
    return erc


def cli_run(scene: str, until: str, out: Path) -> tuple[float, float, dict]:
    """`cvtfem run` of ``scene`` to ``until`` (s) with a results file: ``(wall s, CPU s, summary)`` of the process."""
    summary = out / (Path(scene).stem + ".json")
    cmd = [sys.executable, "-m", "cvtfem.cli", "run", scene, "--until", until, "--overwrite",
           "--results", str(out / (Path(scene).stem + ".h5")), "--summary-json", str(summary)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {proc.returncode}\n{proc.stderr[-2000:]}")
    return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, json.loads(summary.read_text())


def run_costs(preset: str, until: str, scenes, out: Path, rhs_cpu: float | None) -> None:
    """Per scene of ``scenes`` (the preset and its RK4 study scene): `cvtfem run` to ``until``, the integration's
    wall time (the summary's) and CPU time per simulated ms and for 1 s: the process's less that of a run of the
    preset to 1 us (the start, the model build and the imports; within the start's run-to-run noise where the start
    dominates, as for (e)) and, with ``rhs_cpu`` (s, the benchmark's median), RHS calls times it."""
    w0, c0, _ = cli_run(preset, "1e-6", out)
    print(f"  {preset} --until 1e-6 (start, build, imports): {w0:.1f} s wall, {c0:.1f} s CPU")
    ms = 1e3 * float(until)
    for scene in scenes:
        wall, cpu, s = cli_run(scene, until, out)
        sol, integ = s["solver"], s["wall_time_s"]
        cpu_ms = (cpu - c0) / (ms - 1e-3)
        by_rhs = "" if rhs_cpu is None else f" (RHS calls x RHS CPU: {sol['nfev'] / ms * rhs_cpu:.1f} s, 1 s: " \
            f"{sol['nfev'] / ms * rhs_cpu / 3.6:.2f} h)"
        print(f"  {Path(scene).stem} --until {until}: {sol['name']}, {sol['steps']} steps, {sol['nfev']} RHS; process "
              f"{wall:.1f} s wall, {cpu:.1f} s CPU; per simulated ms {integ / ms:.1f} s wall (integration), "
              f"{cpu_ms:.1f} s CPU{by_rhs}, {sol['nfev'] / ms:.0f} RHS; 1 s: {integ / ms / 3.6:.2f} h wall, "
              f"{cpu_ms / 3.6:.2f} h CPU")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--jac-calls", type=int, default=6)
    ap.add_argument("--scenes", default="variant-b,regime-stationary:variant-e,regime-stationary:"
                                        "variant-zh,regime-stationary")
    ap.add_argument("--runs", action="store_true", help="also time `cvtfem run` of (e) and (b), rock4 and RK4")
    a = ap.parse_args()
    print(f"machine: {machine()}")
    rhs_cpu = {}
    for name in filter(None, a.scenes.split(":")):
        rhs_cpu[name.split(",")[0]] = bench_scene(name, a.calls, a.jac_calls)
    if a.runs:
        print("\ncvtfem run (results file and outputs on):")
        with tempfile.TemporaryDirectory() as tmp:
            for preset, until, scenes in RUNS:
                run_costs(preset, until, scenes, Path(tmp), rhs_cpu.get(preset))
    print(f"\nmachine after: {machine()}")


if __name__ == "__main__":
    main()
