"""Forced-response plots: Bode plot, order maps, ERP over speed (matplotlib, imported lazily)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.analysis.response import Response
from cvtfem.analysis.spectrum import Spectrum


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


def _map(ax, fig, speeds, freqs, values, campbell, orders, label: str,  # noqa: ANN001 - matplotlib
         whirls: tuple[str, ...]) -> None:
    """Colour map of ``values`` (s, w) in dB over rpm and Hz, order lines (white, labelled), Campbell natural
    frequencies (black dashed) and the crossings of the modes of kinds ``whirls`` with the order lines (circles)."""
    rpm = speeds * 30 / np.pi
    hz = freqs / (2 * np.pi)
    db = 20 * np.log10(np.maximum(values, 1e-300))
    top = db.max()
    mesh = ax.pcolormesh(rpm, hz, db.T, shading="nearest", cmap="viridis", vmin=top - 80, vmax=top)
    fig.colorbar(mesh, ax=ax, label=label)
    if campbell is not None:
        for j in range(campbell.wd.shape[1]):
            ax.plot(rpm, campbell.wd[:, j] / (2 * np.pi), color="k", lw=0.7, ls="--")
        for c in campbell.crossings:
            if c["whirl"] in whirls:
                ax.plot(c["speed_rad_s"] * 30 / np.pi, c["frequency_rad_s"] / (2 * np.pi), "o", mfc="none",
                        mec="w", ms=7)
    for k in orders:
        ax.plot(rpm, k * speeds / (2 * np.pi), color="w", lw=1.0)
        end = min(k * speeds[-1], freqs[-1]) / (2 * np.pi)
        ax.annotate(f"{k:.4g}x", (end / k * 2 * np.pi * 30 / np.pi, end), color="w", fontsize=8,
                    xytext=(-30, -12), textcoords="offset points")
    ax.set_ylim(hz[0], hz[-1])
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_xlabel("shaft speed (rpm)")
    ax.set_ylabel("frequency (Hz)")


def plot_order_map(res: Response, path: str | Path, title: str = "") -> Path:
    """``|H|`` (dB re 1 m/N) over speed (rpm) and frequency (Hz), order lines (white), the Campbell
    natural frequencies (black) and the crossings of lateral modes with the order lines (circles)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 6))
    _map(ax, fig, res.speeds, res.freqs, res.map, res.campbell, res.orders,
         "|(u1, u2)| per unit force (dB re 1 m/N)", ("forward", "backward"))
    ax.set_title(f"{title or 'order map'}: force x at node {res.force_node}, response at node {res.node}")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_spectrum_map(res: Spectrum, path: str | Path, title: str = "") -> Path:
    """The order map of :func:`cvtfem.analysis.spectrum.scene_spectrum` (dB re 1 m per unit input)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 6))
    _map(ax, fig, res.speeds, res.freqs, res.map, res.campbell, res.orders,
         "|(u1, u2, u3)| per unit input (dB re 1 m)", ("forward", "backward", "axial"))
    ax.set_title(f"{title or 'order map'}\nresponse at node {res.node} to {res.map_input}", fontsize=10)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_erp(res: Spectrum, path: str | Path, title: str = "") -> Path:
    """ERP of the sheave faces over speed: total and A-weighted (dB re 1 pW), and the response at the node of the
    (up to five) lines with the largest ERP (m, log)."""
    plt = _pyplot()
    rpm = res.speeds * 30 / np.pi
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    ax.plot(rpm, res.erp_db, color="k", label="ERP")
    ax.plot(rpm, res.erp_a_db, color="tab:red", ls="--", label="ERP, A-weighted")
    ax.set_ylabel("sheave-face ERP (dB re 1 pW)")
    ax.set_title(title or "equivalent radiated power")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    peak = res.line_erp.max(axis=0)
    strongest = [j for j in np.argsort(peak)[::-1] if peak[j] > 1e-12 * peak.max()][:5]  # lines that radiate
    for j in strongest:
        ax2.semilogy(rpm, np.maximum(res.line_amplitude[:, j], 1e-30), label=res.line_labels[j])
    if strongest:
        ax2.set_ylim(bottom=max(res.line_amplitude[:, strongest].max() * 1e-6, 1e-30))
        ax2.legend(fontsize=7)
    ax2.set_ylabel(f"|(u1, u2, u3)| at node {res.node} (m)")
    ax2.set_xlabel("shaft speed (rpm)")
    ax2.set_title(f"the {len(strongest)} lines with the largest ERP", fontsize=9)
    ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
