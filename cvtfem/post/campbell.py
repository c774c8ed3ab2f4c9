"""Campbell diagram plot (matplotlib, imported lazily)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.modal.campbell import Campbell

_STYLE = {"forward": ("tab:red", "-"), "backward": ("tab:blue", "--"), "torsional": ("tab:green", "-."),
          "axial": ("tab:gray", ":")}


def plot_campbell(result: Campbell, path: str | Path, title: str = "", fmax: float | None = None) -> Path:
    """Tracked damped frequencies (Hz) over speed (rpm), excitation lines and critical speeds.

    Curves are coloured by whirl at each speed (forward red, backward blue dashed,
    torsional green, axial grey); crossings are circled.  A second panel shows
    the damping ratios when any is non-zero.

    Returns
    -------
    Path of the PNG written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rpm = result.speeds * 30 / np.pi
    hz = result.wd / (2 * np.pi)
    damped = np.any(np.abs(result.damping_ratio) > 1e-9)
    fig, axes = plt.subplots(2 if damped else 1, 1, figsize=(8, 7.5 if damped else 5.5), sharex=True,
                             squeeze=False, gridspec_kw={"height_ratios": [3, 1]} if damped else None)
    ax = axes[0, 0]
    top = fmax or 1.05 * hz.max()
    for j in range(hz.shape[1]):
        kinds = result.whirl[:, j]
        for kind, (color, ls) in _STYLE.items():
            y = np.where(kinds == kind, hz[:, j], np.nan)
            ax.plot(rpm, y, color=color, ls=ls, lw=1.6)
    for kind, (color, ls) in _STYLE.items():
        if np.any(result.whirl == kind):
            ax.plot([], [], color=color, ls=ls, label=kind)
    for label, factor in result.orders:
        f = factor * result.speeds / (2 * np.pi)
        ax.plot(rpm, f, color="k", lw=0.8, ls=":")
        i = np.searchsorted(f, 0.95 * top) - 1 if f[-1] > top else len(f) - 1
        ax.annotate(label, (rpm[max(i, 0)], f[max(i, 0)]), fontsize=8, xytext=(2, 2), textcoords="offset points")
    labelled: list[tuple[float, float]] = []
    for c in result.crossings:
        s, f = c["speed_rad_s"] * 30 / np.pi, c["frequency_rad_s"] / (2 * np.pi)
        if f <= top:
            ax.plot(s, f, "o", mfc="none", mec="k", ms=8)
            if all(abs(s - s0) > 0.04 * rpm[-1] or abs(f - f0) > 0.04 * top for s0, f0 in labelled):
                ax.annotate(f"{s:.0f} rpm", (s, f), fontsize=7, xytext=(5, -10), textcoords="offset points")
                labelled.append((s, f))
    ax.set_ylim(0, top)
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_ylabel("damped natural frequency (Hz)")
    ax.set_title(title or "Campbell diagram")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    if damped:
        ax2 = axes[1, 0]
        for j in range(hz.shape[1]):
            color, ls = _STYLE.get(result.whirl[-1, j], ("k", "-"))
            ax2.plot(rpm, result.damping_ratio[:, j], color=color, ls=ls, lw=1)
        ax2.set_ylabel("damping ratio")
        ax2.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("shaft speed (rpm)")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
