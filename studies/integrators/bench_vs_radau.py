"""Wall time at equal error: cvtfem's stiff methods against scipy Radau (issue 19, deliverable 4).

Problems: HIRES (t = 321.8122, published reference), Van der Pol with eps = 1e-6 (t = 2) and Robertson
(t = 1e5), the last two against scipy Radau at rtol 1e-12. Error: max over components of
``|y - y_ref| / |y_ref|`` at the end time. Each method runs a sweep of rtols (atol a fixed fraction of
rtol, per problem); wall time is the median of ``--repeats`` runs, interleaved between the methods; the
time at errors 1e-4/1e-6/1e-8 is interpolated log-log between neighbouring sweep points (``-`` when the
sweep does not bracket it); a sweep stops at the first error below 1e-8.
Analytic Jacobians everywhere. Prints a table and the ratio best cvtfem method / Radau.

Run: ``.venv/bin/python studies/integrators/bench_vs_radau.py [--repeats 3] [--methods radau5,rodas4:...]``
(method specs as ``cvtfem study``: ``NAME[:key=value...]``).
"""
from __future__ import annotations

import argparse
import dataclasses
import statistics

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.commands.study import parse_method
from cvtfem.integrate import solve
from cvtfem.integrate.study import work_precision
from cvtfem.problems import hires, robertson, van_der_pol_stiff

TARGETS = (1e-4, 1e-6, 1e-8)
RTOLS = tuple(10.0 ** -k for k in np.arange(2.0, 11.5, 1.0))
ATOL = {"hires": 1e-3, "vdp": 1.0, "robertson": 1e-8}   # atol = factor * rtol


def with_reference(p, atol):
    """``p`` with ``y_ref`` from scipy Radau at rtol 1e-12 (all components)."""
    ref = solve(**p.solve_kwargs(), method="Radau", rtol=1e-12, atol=atol).y[:, -1]
    return dataclasses.replace(p, y_ref=ref, ref_index=np.arange(len(ref)))


def time_at(rows, target):
    """Wall time at error ``target``, interpolated log-log along the sweep (None if not bracketed)."""
    pts = sorted((r["error"], r["time"]) for r in rows if np.isfinite(r["error"]) and r["error"] > 0)
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if e0 <= target <= e1:
            w = 0.0 if e1 == e0 else np.log(target / e0) / np.log(e1 / e0)
            return float(np.exp(np.log(t0) + w * (np.log(t1) - np.log(t0))))
    return None


def sweeps(p, methods, atol_factor, repeats):
    """``{method: rows}`` along the rtol sweep, each method down to its first error below the smallest target.
    Interleaved: at each rtol every method still sweeping runs once per round, ``repeats`` rounds, so a change
    of the machine's load hits all methods alike (the median is over the rounds)."""
    specs = {m: parse_method(m) for m in methods}
    rows = {m: [] for m in methods}
    active = list(methods)
    for r in RTOLS:
        runs = {m: [] for m in active}
        for _ in range(repeats):
            for m in active:
                _, method, opts = specs[m]
                runs[m] += work_precision(p, [(m, method, {**opts, "rtol": r, "atol": atol_factor * r})], repeats=1)
        for m in active:
            rows[m].append({**runs[m][-1], "time": statistics.median(row["time"] for row in runs[m])})
        active = [m for m in active if rows[m][-1]["error"] >= min(TARGETS)]
        if not active:
            break
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--methods", default="radau5,rodas4,rodas5p")
    ap.add_argument("--problems", default="hires,vdp,robertson", help="subset of hires,vdp,robertson")
    args = ap.parse_args()
    methods = args.methods.split(",") + ["Radau"]
    make = {"hires": hires, "vdp": lambda: with_reference(van_der_pol_stiff(1e-6), 1e-12),
            "robertson": lambda: with_reference(robertson(1e5), 1e-20)}
    problems = {name: make[name]() for name in args.problems.split(",")}
    print(f"median of {args.repeats} runs; {machine()}")
    print(f"{'problem':10s} {'method':18s} " + " ".join(f"t@{e:.0e}".rjust(10) for e in TARGETS))
    for name, p in problems.items():
        rows = sweeps(p, methods, ATOL[name], args.repeats)
        best = {}
        for m in methods:
            times = [time_at(rows[m], e) for e in TARGETS]
            print(f"{name:10s} {m:18s} " + " ".join(("-" if t is None else f"{t:.3f} s").rjust(10) for t in times),
                  flush=True)
            for e, t in zip(TARGETS, times):
                if t is not None and m != "Radau":
                    best[e] = min(best.get(e, np.inf), t)
                elif t is not None:
                    best[("Radau", e)] = t
        ratios = [best[e] / best[("Radau", e)] if e in best and ("Radau", e) in best else None for e in TARGETS]
        print(f"{name:10s} {'best/Radau':18s} " + " ".join(("-" if r is None else f"{r:.2f}x").rjust(10)
                                                         for r in ratios), flush=True)
    print(f"end: {machine()}")


if __name__ == "__main__":
    main()
