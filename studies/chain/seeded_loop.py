"""Stationary runs with the loops on: the ratio loop's integral started at zero (the source) or seeded.

Run:  .venv/bin/python studies/chain/seeded_loop.py RESULTS.h5 [RESULTS.h5 ...] [--labels a,b] [--every 0.005]
      [--png out/studies/chain/seeded_loop_a.png]
The results files come from ``cvtfem run`` (e.g. ``cvtfem run studies/chain/variant-a-seeded.toml --until 0.05``
and the same scene with ``ratio_loop_start = "zero"``).  Per file: the ratio's and input speed's deviation from
the targets (2.4, 3500 rpm) at every ``--every`` s and their largest value over the run's second half, the driving
clamping force F1 and the ratio loop's integral F11 (from F1, the estimate's F1a and the stored ratio estimate), the
drift of the ratio over the second half (1/s, linear fit), the run's energy balance (residual of input work +
clamping work = output work + dissipated work + change of stored energy, of the input work) and whether any series
holds a NaN.  ``--png`` draws ratio, input speed and F1 over time, one line per file.
"""
from __future__ import annotations

import argparse
import math
import os
import tomllib

import numpy as np

from cvtfem.control.clamping import Clamping
from cvtfem.io.results import read_results
from cvtfem.machines.cvt import band_params
from cvtfem.scene.loader import scene_from_dict

RPM = 30 / math.pi


def series(path):
    """Time s, ratio, input speed rpm, F1 N, the loop's integral F11 N, the energy balance's residual (of the input
    work), whether a series holds a NaN, the regime's targets (ratio, rpm) and F2 N."""
    r = read_results(path)
    s, t = r.series, r.time
    w1 = np.asarray(s["driving.speed"]).reshape(-1)
    ratio = np.asarray(s["ratio"]).reshape(-1)
    F1 = np.asarray(s["driving.clamping_force"]).reshape(-1)
    scene = scene_from_dict(tomllib.loads(r.scene_toml), source=str(path))
    rg, c = scene.cvt.regime, scene.cvt.control
    F1a = Clamping(band_params(scene), rg.clamping_safety, rg.clamping_split, rg.min_clamping_force).forces(
        rg.torque, rg.ratio)[0]
    # the loop's integral from F1 = F1a + c_f0 (i_estimate - i_d) + F11 (exact while the sum is not saturated)
    F11 = F1 - F1a - c.c_f0 * (np.asarray(s["control.ratio_estimate"]).reshape(-1) - rg.ratio)
    W = np.asarray(s["work"])          # cumulative works (input, output, dissipated, clamping), J
    E = np.asarray(s["energy"]).reshape(-1)
    residual = (W[-1, 0] + W[-1, 3] - W[-1, 1] - W[-1, 2] - (E[-1] - E[0])) / W[-1, 0]
    nan = any(np.isnan(np.asarray(v, float)).any() for v in s.values() if np.asarray(v).dtype.kind == "f")
    return dict(t=t, ratio=ratio, rpm=w1 * RPM, F1=F1, F11=F11, residual=float(residual), nan=nan,
                target=(rg.ratio, rg.input_speed * RPM),
                F2=float(np.asarray(s["driven.clamping_force"]).reshape(-1)[0]))


def report(label, d, every):
    """Print the table of one run."""
    t, (i_d, n_d) = d["t"], d["target"]
    dev_i, dev_n = d["ratio"] / i_d - 1, d["rpm"] / n_d - 1
    half = t >= t[-1] / 2
    rate = np.polyfit(t[half], d["ratio"][half], 1)[0] if half.sum() > 2 else np.nan
    print(f"{label}: {t[-1] * 1e3:.1f} ms, F2 {d['F2']:.0f} N; energy balance residual {d['residual']:.2e} of the "
          f"input work; NaN: {d['nan']}")
    print("   t ms   ratio  dev %    rpm   dev %      F1 N   F1/F2     F11 N")
    for tk in np.arange(0.0, t[-1] + 1e-12, every):
        k = int(np.argmin(np.abs(t - tk)))
        print(f"  {1e3 * t[k]:5.1f}  {d['ratio'][k]:.4f} {100 * dev_i[k]:+5.2f}  {d['rpm'][k]:6.1f} "
              f"{100 * dev_n[k]:+5.2f}"
              f"  {d['F1'][k]:8.0f}  {d['F1'][k] / d['F2']:.4f}  {d['F11'][k]:8.0f}")
    print(f"  second half: largest |ratio dev| {100 * np.abs(dev_i[half]).max():.2f} %, |speed dev| "
          f"{100 * np.abs(dev_n[half]).max():.2f} %; ratio drift {rate:+.3f} 1/s (towards the target if its sign is "
          f"opposite to the mean deviation {100 * dev_i[half].mean():+.2f} %)")


def plot(runs, path):
    """Ratio, input speed and F1 over time, one line per run."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for k, (label, d) in enumerate(runs.items()):
        i_d, n_d = d["target"]
        ax[0].plot(1e3 * d["t"], d["ratio"], c=f"C{k}", lw=0.8, label=label)
        ax[1].plot(1e3 * d["t"], d["rpm"], c=f"C{k}", lw=0.8, label=label)
        ax[2].plot(1e3 * d["t"], 1e-3 * d["F1"], c=f"C{k}", lw=0.8, label=label)
    for a, y, tol in ((ax[0], i_d, 0.02), (ax[1], n_d, 0.01)):
        a.axhline(y, c="k", lw=0.6)
        a.axhspan(y * (1 - tol), y * (1 + tol), color="0.9", zorder=0, label=f"acceptance +-{tol:.0%}")
    ax[0].set_ylabel("speed ratio w1 / w2")
    ax[1].set_ylabel("input speed, rpm")
    ax[2].set_ylabel("driving clamping force F1, kN")
    ax[2].set_xlabel("t, ms")
    for a in ax:
        a.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=90)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+")
    ap.add_argument("--labels", default="", help="comma-separated, one per file (default: file names)")
    ap.add_argument("--every", type=float, default=0.005, help="table step, s")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    labels = a.labels.split(",") if a.labels else [os.path.basename(p) for p in a.results]
    runs = {lab: series(p) for lab, p in zip(labels, a.results)}
    for lab, d in runs.items():
        report(lab, d, a.every)
    if a.png:
        plot(runs, a.png)
        print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
