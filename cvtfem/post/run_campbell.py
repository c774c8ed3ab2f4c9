"""Campbell diagram along a run (:mod:`cvtfem.analysis.run_campbell`) with the chain's excitation lines
``k f_chain`` and ``k/3 f_link`` of the run's speeds and geometry: plot (frequency over time or input speed) and CSV."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from cvtfem.analysis.run_campbell import RunCampbell
from cvtfem.post.campbell import spread
from cvtfem.post.figures import pyplot, save

#: Colour and line style of a tracked mode by whirl label (as the rotor code's Campbell plot).
STYLE = {"forward": ("tab:red", "-"), "backward": ("tab:blue", "--"), "torsional": ("tab:green", "-."),
         "axial": ("tab:gray", ":")}


def abscissa(result: RunCampbell, against: str) -> tuple[np.ndarray, str]:
    """``(x, label)``: the stored times in ms, or the driving shaft's speed in rpm."""
    if against == "speed":
        return result.speed[:, 0] * 30 / np.pi, "driving shaft speed, rpm"
    return 1e3 * result.t, "time, ms"


def plot_run_campbell(result: RunCampbell, lines, path: str | Path, against: str = "time",
                      fmax: float | None = None, title: str = "") -> Path:
    """Tracked damped frequencies (Hz) of J11 coloured by whirl, marker size growing with the damping ratio, and
    the excitation lines ``(label, Hz at the stored times)`` (chain orders white dotted, link orders dashed)."""
    plt = pyplot()
    x, xlabel = abscissa(result, against)
    hz = result.wd / (2 * np.pi)
    top = float(fmax or 1.05 * hz.max())
    fig, ax = plt.subplots(figsize=(8.6, 5.6), layout="constrained")
    for j in range(hz.shape[1]):
        for kind, (color, ls) in STYLE.items():
            ax.plot(x, np.where(result.whirl[:, j] == kind, hz[:, j], np.nan), color=color, ls=ls, lw=1.5,
                    marker="o", ms=2.5)
    for kind, (color, ls) in STYLE.items():
        if np.any(result.whirl == kind):
            ax.plot([], [], color=color, ls=ls, label=kind)
    ends = []
    for name, f in lines:
        f = np.asarray(f, float)
        if f.min() > top:
            continue
        ax.plot(x, f, color="k", lw=0.8, ls="--" if "link" in name else ":")
        ends.append((name, float(np.clip(f[-1], 0.0, top))))
    if ends:
        ys = spread(np.array([y for _, y in ends]), 0.03 * top, 0.0, top)
        for (name, y0), y in zip(ends, ys):
            ax.annotate(name, (x[-1], y0), xytext=(x[-1] + 0.01 * (x[-1] - x[0] or 1.0), y), textcoords="data",
                        fontsize=7, va="center", annotation_clip=False,
                        arrowprops={"arrowstyle": "-", "lw": 0.4, "color": "0.5"})
    ax.set_xlim(x[0], x[-1] if x[-1] > x[0] else x[0] + 1.0)
    ax.set_ylim(0.0, top)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("damped natural frequency of J11, Hz")
    ax.set_title(title or "Campbell diagram along the run (structure block J11, chain frozen)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    return save(fig, path)


def write_run_campbell_csv(result: RunCampbell, lines, path: str | Path) -> Path:
    """One row per stored time: ``t_s, driving_rpm, driven_rpm``, per tracked mode ``mode<j>_Hz``,
    ``mode<j>_zeta``, ``mode<j>_whirl``, ``mode<j>_mac``, then the excitation lines in Hz."""
    k = result.wd.shape[1]
    header = ["t_s", "driving_rpm", "driven_rpm"]
    header += [f"mode{j}_{what}" for j in range(k) for what in ("Hz", "zeta", "whirl", "mac")]
    header += [f"{name.replace(' ', '_')}_Hz" for name, _ in lines]
    rpm = result.speed * 30 / np.pi
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for i, t in enumerate(result.t):
            row = [f"{t:.9g}", f"{rpm[i, 0]:.6g}", f"{rpm[i, 1]:.6g}"]
            for j in range(k):
                row += [f"{result.wd[i, j] / (2 * np.pi):.6g}", f"{result.damping_ratio[i, j]:.4g}",
                        result.whirl[i, j], f"{result.mac[i, j]:.4f}"]
            row += [f"{float(np.asarray(f)[i]):.6g}" for _, f in lines]
            w.writerow(row)
    return Path(path)
