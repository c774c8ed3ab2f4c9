"""Benchmark: harmonic balance vs time integration on the engine gear train, and block-sweep scaling.

Run:  .venv/bin/python studies/periodic/bench_periodic.py [--quick] [--reuse-ti] [--engine-only]
Prints medians of several runs and the machine; writes out/studies/periodic/bench.json.

1. Time integration (DOP853, rtol 1e-7, from rest, period by period until the state repeats
   within 1e-6): periods, wall and CPU time, RHS calls, probe-link peak and RMS moment.
2. HB continued in N = 24 .. 192 (cumulative cost, median of 3 runs) and its difference from 1.
   ``--reuse-ti`` takes 1. from the previous ``bench.json``; ``--engine-only`` skips 3.
3. Block sweep (full Toeplitz blocks, as in a Newton step) on chains and branched trees of
   10 .. 10,000 masses.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.assembly.numbering import through_numbering
from cvtfem.blas import single_thread_blas
from cvtfem.elements.torsional import build_network
from cvtfem.machines.torsional import build
from cvtfem.periodic import blocktri, hb, transient
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/periodic")


def median_time(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


def probe_stats(moment: np.ndarray) -> np.ndarray:
    return np.array([np.abs(moment).max(), np.sqrt((moment ** 2).mean())])


def hb_chain(net, omega, probe, ti_stats) -> list[dict]:
    """HB continued in N (each N starts from the previous, padded); cumulative wall and CPU per N."""
    rows, prev, wall, cpu_total = [], None, 0.0, 0.0
    for N in (24, 48, 96, 144, 192):
        a0 = None
        if prev is not None:  # continuation in N: pad the previous harmonics
            a0 = np.zeros((net.n_nodes, 2 * N + 1), complex)
            a0[:, N - prev.N:N + prev.N + 1] = prev.a
        cpu = time.process_time()
        t, sol = median_time(lambda: hb.solve_periodic(net, omega, N, a0=a0, raise_on_failure=True), 1)
        cpu_total += time.process_time() - cpu
        wall += t
        got = probe_stats(sol.link_moments(4096)[probe])
        diff = np.abs(got - ti_stats) / ti_stats
        rows.append({"N": N, "wall": wall, "cpu": cpu_total, "iterations": sol.iterations,
                     "peak": got[0], "rms": got[1], "diff": diff.tolist()})
        prev = sol
    return rows


def engine(quick: bool, hz: float = 12.5, reuse_ti: bool = False, repeats: int = 3) -> dict:
    """Time integration from rest to periodic steady state vs HB continued in N, same network.

    ``reuse_ti``: take the time-integration reference from an earlier ``bench.json`` (it costs
    minutes; HB is what changes).  HB: median over ``repeats`` runs of the whole N chain.
    """
    net = build(load_scene("engine_gear_train"))
    probe = net.link_names.index("crank_gear-idler_gear")
    r_probe = net.radius[net.i[probe]]
    omega = 2 * np.pi * hz
    rows: dict = {"frequency_hz": hz}
    old = OUT / "bench.json"
    if reuse_ti and old.exists():
        rows["ti"] = json.loads(old.read_text())["engine"]["ti"]
        rows["ti"]["reused"] = True
        ti = rows["ti"]
        print(f"time integration (reused from {old}): {ti['periods']} periods, {ti['wall']:.1f} s wall, "
              f"{ti['cpu']:.1f} s CPU; probe peak {ti['peak']:.2f} N m, RMS {ti['rms']:.3f} N m")
    else:
        cpu = time.process_time()
        ti = transient.steady_state(net, omega, rtol=1e-7, atol=1e-13, tol=1e-6, max_periods=400, samples=4096)
        ti_cpu = time.process_time() - cpu
        stats = probe_stats(ti.link_forces[probe] * r_probe)
        print(f"time integration DOP853 rtol 1e-7 from rest: {ti.periods} periods to repeat within 1e-6, "
              f"{ti.wall:.1f} s wall, {ti_cpu:.1f} s CPU, {ti.nfev} RHS calls; probe peak {stats[0]:.2f} N m, "
              f"RMS {stats[1]:.3f} N m")
        rows["ti"] = {"periods": ti.periods, "wall": ti.wall, "cpu": ti_cpu, "nfev": ti.nfev,
                      "peak": stats[0], "rms": stats[1]}
    ti_stats = np.array([rows["ti"]["peak"], rows["ti"]["rms"]])
    runs = [hb_chain(net, omega, probe, ti_stats) for _ in range(1 if quick else repeats)]
    hb_rows = []
    for k, row in enumerate(runs[0]):
        row = dict(row)
        for key in ("wall", "cpu"):
            row[key] = float(np.median([run[k][key] for run in runs]))
            row[key + "_runs"] = [run[k][key] for run in runs]
        hb_rows.append(row)
        print(f"HB N={row['N']:3d}: {row['iterations']:3d} Newton iterations, cumulative {row['wall']:6.2f} s wall, "
              f"{row['cpu']:6.2f} s CPU (median of {len(runs)}); probe peak {row['peak']:.2f}, RMS {row['rms']:.3f}; "
              f"vs time integration {row['diff'][0]:.1e} (peak), {row['diff'][1]:.1e} (RMS); speed-up "
              f"{rows['ti']['cpu'] / row['cpu']:.0f}x CPU, {rows['ti']['wall'] / row['wall']:.0f}x wall")
    rows["hb"] = hb_rows
    return rows


def scaling(quick: bool) -> dict:
    rng = np.random.default_rng(0)
    N = 8
    K = 2 * N + 1
    rows = {}
    for shape in ("chain", "tree"):
        for S in (10, 100, 1000, 10_000):
            if shape == "chain":
                parents = np.arange(-1, S - 1)
            else:  # random tree: each node hangs on one of the previous 5
                parents = np.array([-1] + [max(0, s - 1 - int(rng.integers(0, 5))) for s in range(1, S)])
            i = np.concatenate([np.arange(1, S), [0]])
            j = np.concatenate([parents[1:], [-1]])
            Nb = np.zeros((S, 1, K, K), complex)
            Nb[:, 0, np.arange(K), np.arange(K)] = -(np.arange(-N, N + 1) * 50.0) ** 2 + 5j * np.arange(-N, N + 1)
            L = rng.normal(size=(S, 1, K, K)) * 1e2 + np.eye(K) * 1e5
            L = (L + L.conj().transpose(0, 1, 3, 2)) / 2
            g = rng.normal(size=(S, 1, K)) + 0j
            topo = through_numbering(S, i, j)
            with single_thread_blas():
                t, a = median_time(lambda: blocktri.block_sweep(topo, Nb, L, i, j, g), 1 if quick and S > 1000 else 3)
            res = np.linalg.norm(blocktri.apply(Nb, L, i, j, a) - g) / np.linalg.norm(g)
            print(f"block sweep {shape:5s} S={S:6d}, blocks {K}x{K}: {t:8.4f} s median, "
                  f"{t / S * 1e6:7.1f} us per mass, residual {res:.1e}")
            rows[f"{shape}_{S}"] = {"time": t, "per_mass_us": t / S * 1e6, "residual": res}
    return rows


def main() -> None:
    quick = "--quick" in sys.argv
    print(f"machine: {machine()}")
    results = {"machine": machine(), "engine": engine(quick, reuse_ti="--reuse-ti" in sys.argv)}
    if "--engine-only" not in sys.argv:
        results["scaling"] = scaling(quick)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench.json").write_text(json.dumps(results, indent=1))
    print(f"wrote {OUT / 'bench.json'}")


if __name__ == "__main__":
    main()
