"""Forced-response plots: Bode plot of the unbalance response, order map (matplotlib, imported lazily)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.analysis.response import Response


def _pyplot():  # noqa: ANN202 - matplotlib.pyplot
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_bode(res: Response, path: str | Path, title: str = "") -> Path:
    """Amplitude (x, y, orbit major and |minor| semi-axes, m, log scale) and phase (deg) over speed (rpm)."""
    plt = _pyplot()
    rpm = res.speeds * 30 / np.pi
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    ax.semilogy(rpm, np.abs(res.x), color="tab:red", label="|x|")
    ax.semilogy(rpm, np.abs(res.y), color="tab:blue", ls="--", label="|y|")
    ax.semilogy(rpm, res.major, color="k", lw=0.8, label="orbit major")
    ax.semilogy(rpm, np.abs(res.minor), color="tab:gray", lw=0.8, ls=":", label="orbit |minor|")
    ax.set_ylabel(f"amplitude at node {res.node} (m)")
    ax.set_title(title or "unbalance response")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    for z, color, ls, label in ((res.x, "tab:red", "-", "phase x"), (res.y, "tab:blue", "--", "phase y")):
        ax2.plot(rpm, np.where(z != 0, np.degrees(np.angle(z)), np.nan), color=color, ls=ls, label=label)
    ax2.set_ylim(-180, 180)
    ax2.set_yticks([-180, -90, 0, 90, 180])
    ax2.set_ylabel("phase (deg)")
    ax2.set_xlabel("shaft speed (rpm)")
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_order_map(res: Response, path: str | Path, title: str = "") -> Path:
    """``|H|`` (dB re 1 m/N) over speed (rpm) and frequency (Hz), order lines (white), the Campbell
    natural frequencies (black) and the crossings of lateral modes with the order lines (circles)."""
    plt = _pyplot()
    rpm = res.speeds * 30 / np.pi
    hz = res.freqs / (2 * np.pi)
    db = 20 * np.log10(np.maximum(res.map, 1e-300))
    top = db.max()
    fig, ax = plt.subplots(figsize=(8.5, 6))
    mesh = ax.pcolormesh(rpm, hz, db.T, shading="nearest", cmap="viridis", vmin=top - 80, vmax=top)
    fig.colorbar(mesh, ax=ax, label="|(u1, u2)| per unit force (dB re 1 m/N)")
    if res.campbell is not None:
        for j in range(res.campbell.wd.shape[1]):
            ax.plot(rpm, res.campbell.wd[:, j] / (2 * np.pi), color="k", lw=0.7, ls="--")
        for c in res.campbell.crossings:
            if c["whirl"] in ("forward", "backward"):
                ax.plot(c["speed_rad_s"] * 30 / np.pi, c["frequency_rad_s"] / (2 * np.pi), "o", mfc="none",
                        mec="w", ms=7)
    for k in res.orders:
        ax.plot(rpm, k * res.speeds / (2 * np.pi), color="w", lw=1.0)
        ax.annotate(f"{k:.4g}x", (rpm[-1], k * res.speeds[-1] / (2 * np.pi)), color="w", fontsize=8,
                    xytext=(-24, -12), textcoords="offset points")
    ax.set_ylim(hz[0], hz[-1])
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_xlabel("shaft speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{title or 'order map'}: force x at node {res.force_node}, response at node {res.node}")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
