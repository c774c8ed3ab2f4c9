"""Benchmark: harmonic balance vs time integration on the engine gear train, and block-sweep scaling.

Run:  .venv/bin/python studies/periodic/bench_periodic.py [--quick]
Prints medians of several runs and the machine; writes out/studies/periodic/bench.json.

1. Reference: HB with N = 96 at tol 1e-12 (checked against the time-integrated steady state).
2. HB cost at the smallest N whose probe-link peak and RMS moment are within 1e-3 of the reference.
3. Time integration (DOP853, from rest, period by period until the state repeats within 1e-6)
   at rtol chosen so its probe peak and RMS are within 1e-3 of the reference too.
4. Block sweep (full Toeplitz blocks, as in a Newton step) on chains and branched trees of
   10 .. 10,000 masses.
"""
from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from cvtfem.elements.torsional import build_network
from cvtfem.machines.torsional import build
from cvtfem.periodic import hb, sweep, transient
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/periodic")


def machine() -> str:
    return (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"load {os.getloadavg()[0]:.1f}, Python {platform.python_version()}, numpy {np.__version__}")


def median_time(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


def probe_stats(moment: np.ndarray) -> np.ndarray:
    return np.array([np.abs(moment).max(), np.sqrt((moment ** 2).mean())])


def engine(quick: bool, hz: float = 12.5) -> dict:
    """HB (continued in N) and time integration against a tight time-integration reference."""
    net = build(load_scene("engine_gear_train"))
    probe = net.link_names.index("crank_gear-idler_gear")
    r_probe = net.radius[net.i[probe]]
    omega = 2 * np.pi * hz
    rows: dict = {"frequency_hz": hz}
    ref_ti = transient.steady_state(net, omega, rtol=1e-9, atol=1e-15, tol=1e-7, max_periods=400, samples=4096)
    ref = probe_stats(ref_ti.link_forces[probe] * r_probe)
    print(f"reference: DOP853 rtol 1e-9 from rest, {ref_ti.periods} periods, {ref_ti.wall:.1f} s, "
          f"{ref_ti.nfev} RHS calls: probe peak {ref[0]:.2f} N m, RMS {ref[1]:.3f} N m")
    rows["reference"] = {"peak": ref[0], "rms": ref[1], "time": ref_ti.wall, "periods": ref_ti.periods}
    hb_rows = []
    prev, total = None, 0.0
    for N in ((48, 96) if quick else (48, 96, 144, 192)):
        a0 = None
        if prev is not None:  # continuation in N: pad the previous harmonics
            a0 = np.zeros((net.n_nodes, 2 * N + 1), complex)
            a0[:, N - prev.N:N + prev.N + 1] = prev.a
        t, sol = median_time(lambda: hb.solve_periodic(net, omega, N, a0=a0, raise_on_failure=True),
                             1 if quick else 3)
        total += t
        err = np.abs(probe_stats(sol.link_moments(4096)[probe]) - ref) / ref
        print(f"HB N={N:3d}: {t:7.3f} s median ({total:.2f} s cumulative), {sol.iterations} Newton iterations, "
              f"rel. error peak {err[0]:.1e}, RMS {err[1]:.1e}")
        hb_rows.append({"N": N, "time": t, "cumulative": total, "iterations": sol.iterations, "err": err.tolist()})
        prev = sol
    rows["hb"] = hb_rows
    ti_rows = []
    for rtol in ((1e-6,) if quick else (1e-5, 1e-6, 1e-7)):
        ss = transient.steady_state(net, omega, rtol=rtol, atol=rtol * 1e-6, tol=1e-6, max_periods=400,
                                    samples=4096)
        err = np.abs(probe_stats(ss.link_forces[probe] * r_probe) - ref) / ref
        print(f"time integration DOP853 rtol={rtol:.0e}: {ss.wall:8.1f} s, {ss.periods} periods, "
              f"{ss.nfev} RHS calls, rel. error peak {err[0]:.1e}, RMS {err[1]:.1e}")
        ti_rows.append({"rtol": rtol, "time": ss.wall, "periods": ss.periods, "nfev": ss.nfev, "err": err.tolist()})
    rows["ti"] = ti_rows
    for h in hb_rows:
        ok = [t for t in ti_rows if max(t["err"]) <= max(h["err"])]
        if ok:
            t = min(ok, key=lambda r: r["time"])
            print(f"==> equal accuracy {max(h['err']):.1e}: HB N={h['N']} {h['cumulative']:.2f} s vs time "
                  f"integration rtol {t['rtol']:.0e} {t['time']:.1f} s: speed-up {t['time'] / h['cumulative']:.0f}x")
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
            topo = sweep.through_numbering(S, i, j)
            with hb.single_thread_blas():
                t, a = median_time(lambda: sweep.block_sweep(topo, Nb, L, i, j, g), 1 if quick and S > 1000 else 3)
            res = np.linalg.norm(sweep.apply(Nb, L, i, j, a) - g) / np.linalg.norm(g)
            print(f"block sweep {shape:5s} S={S:6d}, blocks {K}x{K}: {t:8.4f} s median, "
                  f"{t / S * 1e6:7.1f} us per mass, residual {res:.1e}")
            rows[f"{shape}_{S}"] = {"time": t, "per_mass_us": t / S * 1e6, "residual": res}
    return rows


def main() -> None:
    quick = "--quick" in sys.argv
    print(f"machine: {machine()}")
    results = {"machine": machine(), "engine": engine(quick), "scaling": scaling(quick)}
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench.json").write_text(json.dumps(results, indent=1))
    print(f"wrote {OUT / 'bench.json'}")


if __name__ == "__main__":
    main()
