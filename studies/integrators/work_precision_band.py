"""Work-precision study on the CVT band models (issue 4 on our own models): PNG + CSV per model.

Error = largest relative error of ratio, input/output speed and output/input work at ``t_end``
against Radau at rtol 1e-9 (:mod:`cvtfem.analysis.study_problem`), vs wall time (median of
``--repeats`` runs; runs longer than ``--slow`` s are timed once and marked) and vs RHS calls.
Implicit and W-methods get the closed loop's analytic Jacobian and its ``n2`` structure; rk4 runs
at fixed steps, fractions of its real stability limit ``2.785 / rho`` (``rho`` = spectral radius
of the Jacobian at the start). Prints the machine and the load average.

    .venv/bin/python studies/integrators/work_precision_band.py [--until 0.02] [--models band-4dof band-6+2n]
"""
from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from cvtfem.analysis.study_problem import scene_problem
from cvtfem.integrate import solve
from cvtfem.post.integrators import write_csv

OUT = Path("out/studies/integrators/band")
RTOLS = (1e-3, 1e-4, 1e-5, 1e-6)
ADAPTIVE = ("Radau", "BDF", "LSODA", "trapezoidal", "sw24", "dopri45", "rock2", "rock4", "rkc", "dumka3")
MAX_STEPS = 300_000


def load() -> float:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")


def spectral_radius(p) -> float:
    J = p.jac(0.0, p.y0)
    J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
    return float(np.max(np.abs(np.linalg.eigvals(J))))


def one(p, method, setting, repeats, slow):
    """Run ``method`` with ``setting``; median wall time; a row for the CSV."""
    kw = dict(p.solve_kwargs(), method=method, t_eval=np.array([p.t_span[1]]), **setting)
    if method not in ("Radau", "BDF", "LSODA"):
        kw["max_steps"] = MAX_STEPS
    times, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = solve(**kw)
        times.append(time.perf_counter() - t0)
        if times[-1] > slow:
            break
    st = res.stats
    row = {"label": method, "method": method, **{k: v for k, v in setting.items() if k in ("rtol", "atol", "h")},
           "error": p.error(res), "time": statistics.median(times), "runs": len(times), "nfev": st["nfev"],
           "njev": st["njev"], "nlu": st["nlu"], "nsteps": st["nsteps"], "nreject": st["nreject"],
           "nnewton": st.get("nnewton", -1), "status": res.status, "message": res.message[:120]}
    return row


def study(model: str, until: float, repeats: int, slow: float, methods) -> list[dict]:
    p = scene_problem(model, until, ref_rtol=1e-9)
    rho = spectral_radius(p)
    print(f"{model}: n = {len(p.y0)}, n2 = {p.n2}, spectral radius at start {rho:.3g} 1/s, "
          f"t_end = {until} s, reference outputs {np.array2string(p.y_ref, precision=8)}", flush=True)
    plan = [(m, {"rtol": r, "atol": 1e-2 * r}) for m in ADAPTIVE if m in methods for r in RTOLS]
    if "rk4" in methods:
        h_lim = 2.785 / rho
        plan += [("rk4", {"h": until / np.ceil(until / (f * h_lim))}) for f in (0.95, 0.5, 0.25)]
    rows = []
    for method, setting in plan:
        row = one(p, method, setting, repeats, slow)
        row["model"] = model
        rows.append(row)
        s = ", ".join(f"{k}={setting[k]:.3g}" for k in ("rtol", "h") if k in setting)
        print(f"  {method:12s} {s:14s} err {row['error']:9.2e}  time {row['time']:8.4f} s ({row['runs']} runs)  "
              f"nfev {row['nfev']:8d}  njev {row['njev']:5d}  steps {row['nsteps']:7d}  rej {row['nreject']:5d}  "
              f"status {row['status']}  load {load():.1f}", flush=True)
    return rows


def plot(rows, path: Path, title: str) -> None:
    """Error vs wall time and vs RHS calls; implicit methods solid, explicit dashed, one marker each."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    labels = list(dict.fromkeys(r["label"] for r in rows))
    colors = plt.get_cmap("tab20")(np.linspace(0, 1, 20))
    for i, label in enumerate(labels):
        sel = [r for r in rows if r["label"] == label and np.isfinite(r["error"]) and r["error"] > 0]
        if not sel:
            continue
        style = dict(color=colors[(2 * i) % 20 + (2 * i) // 20], marker="osD^v<>ph*x"[i % 11], ms=4,
                     ls="-" if label in ("Radau", "BDF", "LSODA", "trapezoidal", "sw24") else "--")
        for ax, key in zip(axes, ("time", "nfev")):
            ax.loglog([r[key] for r in sel], [r["error"] for r in sel], label=label, **style)
    axes[0].set_xlabel("wall time, s (median)")
    axes[1].set_xlabel("RHS calls (Jacobians analytic, not counted)")
    for ax in axes:
        ax.set_ylabel("relative output error")
        ax.grid(True, which="both", lw=0.3)
    axes[1].legend(fontsize=7, ncol=2)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def merge(path: Path, rows: list[dict], methods) -> list[dict]:
    """Rows of the other methods from an earlier CSV, then the new ones (a partial re-run)."""
    import csv

    old = [r for r in csv.DictReader(open(path)) if r["method"] not in methods]
    for r in old:
        r.update(error=float(r["error"]), time=float(r["time"]), nfev=int(r["nfev"]))
    order = {m: i for i, m in enumerate(list(ADAPTIVE) + ["rk4"])}
    return sorted(old + rows, key=lambda r: order.get(r["method"], len(order)))


def replot() -> None:
    """Redraw the PNGs from the CSVs (``--replot``)."""
    import csv

    for path in sorted(OUT.glob("work_precision_*.csv")):
        rows = [{**r, "error": float(r["error"]), "time": float(r["time"]), "nfev": int(r["nfev"])}
                for r in csv.DictReader(open(path))]
        plot(rows, path.with_suffix(".png"), f"{rows[0]['model']}: relative error of ratio, speeds, "
             "work ratio vs cost")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", nargs="*", default=["band-4dof", "band-6+2n"])
    ap.add_argument("--until", type=float, default=0.02, help="simulated time, s")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--slow", type=float, default=5.0, help="runs longer than this (s) are timed once")
    ap.add_argument("--methods", nargs="*", default=list(ADAPTIVE) + ["rk4"])
    ap.add_argument("--replot", action="store_true", help="only redraw the PNGs from the CSVs")
    args = ap.parse_args()
    if args.replot:
        replot()
        return
    OUT.mkdir(parents=True, exist_ok=True)
    print(f"machine: {platform.machine()} {platform.processor() or ''}, {os.cpu_count()} cores, "
          f"python {platform.python_version()}, load average {load():.1f}")
    for model in args.models:
        rows = study(model, args.until, args.repeats, args.slow, args.methods)
        stem = OUT / f"work_precision_{model}"
        if set(args.methods) != set(ADAPTIVE) | {"rk4"} and stem.with_suffix(".csv").exists():
            rows = merge(stem.with_suffix(".csv"), rows, args.methods)
        write_csv(rows, stem.with_suffix(".csv"))
        plot(rows, stem.with_suffix(".png"), f"{model}, {args.until} s of the stationary regime: "
             "relative error of ratio, speeds, work ratio vs cost")
        print(f"wrote {stem}.png, {stem}.csv")
    print(f"load average at the end {load():.1f}")


if __name__ == "__main__":
    main()
