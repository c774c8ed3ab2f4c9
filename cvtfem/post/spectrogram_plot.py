"""Plots of :mod:`cvtfem.post.spectrogram`: the spectrogram with excitation lines, the intensity over f / f_chain."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.post.campbell import spread
from cvtfem.post.figures import pyplot, save
from cvtfem.post.spectrogram import OrderIntensity, OrderSpectrum, Spectrogram

#: Dynamic range shown in the spectrogram, dB below its largest value.
DB_RANGE = 80.0
#: Spacing of the line labels at the right edge, as a fraction of the frequency axis.
LABEL_GAP = 0.035


def _labelled(ends: list) -> list:
    """The ``(name, f)`` line ends that get a label: all of them if they fit along the edge at
    :data:`LABEL_GAP`; otherwise the whole multiples (no ``k/3``) first, then every m-th of what is left,
    so the stack never runs off the axes (every line is still drawn)."""
    room = int(1.0 / LABEL_GAP)
    if len(ends) <= room:
        return ends
    whole = [e for e in ends if "/3" not in e[0]]
    ends = whole if whole else ends
    return ends[::-(-len(ends) // room)]


def plot_spectrogram(spec: Spectrogram, path: str | Path, lines=(), line_times=None, title: str = "",
                     label: str = "", modes=None) -> Path:
    """Spectrogram in dB (time on x in ms, frequency on y in Hz up to the last kept frequency) with excitation
    lines ``(label, f(t))`` sampled at ``line_times`` (s) drawn over it and labelled at the right edge, and
    ``modes = (t (s,) s, f (s, k) Hz)``, tracked natural frequencies along the run (a Campbell diagram), as thin
    green lines."""
    plt = pyplot()
    db = spec.db()
    top = float(db.max())
    fig, ax = plt.subplots(figsize=(8.5, 5.0), layout="constrained")
    half = 0.5 * (spec.t[1] - spec.t[0]) if spec.t.size > 1 else 0.5 * spec.window
    edges_t = 1e3 * np.concatenate([spec.t - half, spec.t[-1:] + half])
    edges_f = np.concatenate([spec.f - 0.5 * spec.df, spec.f[-1:] + 0.5 * spec.df]).clip(0.0)
    mesh = ax.pcolormesh(edges_t, edges_f, db, shading="flat", cmap="magma", vmin=top - DB_RANGE, vmax=top)
    unit = f"{spec.unit}$^2$/Hz" if spec.unit else "1/Hz"
    fig.colorbar(mesh, ax=ax, label=f"PSD, dB re 1 {unit}")
    fmax = float(edges_f[-1])
    if line_times is not None:
        tl = 1e3 * np.asarray(line_times)
        inside = (tl >= edges_t[0]) & (tl <= edges_t[-1])
        ends = []
        for name, f in lines:
            f = np.asarray(f)[inside]
            if f.size == 0 or f.min() > fmax:
                continue
            style = dict(color="cyan", ls="--") if "link" in name else dict(color="white", ls=":")
            ax.plot(tl[inside], f, lw=0.9, **style)
            if f[-1] <= fmax:
                ends.append((name, float(f[-1])))
        ends = _labelled(ends)
        if ends:                                   # labels stacked without overlap at the right edge
            ys = spread(np.array([y for _, y in ends]), LABEL_GAP * fmax, 0.0, fmax)
            for (name, y0), y in zip(ends, ys):
                ax.annotate(name, (edges_t[-1], y0), xytext=(edges_t[-1] + 0.01 * (edges_t[-1] - edges_t[0]), y),
                            textcoords="data", fontsize=7, va="center", annotation_clip=False,
                            arrowprops={"arrowstyle": "-", "lw": 0.4, "color": "0.5"})
    if modes is not None:
        tm, fm = modes
        inside = (1e3 * np.asarray(tm) >= edges_t[0]) & (1e3 * np.asarray(tm) <= edges_t[-1])
        for j in range(np.shape(fm)[1]):
            ax.plot(1e3 * np.asarray(tm)[inside], np.asarray(fm)[inside, j], color="lime", lw=0.8,
                    label="modes of J11" if j == 0 else None)
        ax.legend(loc="upper left", fontsize=7, framealpha=0.8)
    ax.set_xlim(edges_t[0], edges_t[-1])
    ax.set_ylim(0.0, fmax)
    ax.set_xlabel("time, ms")
    ax.set_ylabel("frequency, Hz")
    ax.set_title(title or f"{label}: window {1e3 * spec.window:.3g} ms, resolution {spec.df:.3g} Hz", fontsize=10)
    return save(fig, path)


def plot_order_intensity(intensity: OrderIntensity, path: str | Path, title: str = "", unit: str = "") -> Path:
    """Time-averaged intensity in dB over ``f / f_chain``, with the pin-entry orders ``n_pins / 3`` and
    ``n_pins`` (``f_link / 3`` and ``f_link`` of a uniform chain) marked."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.0, 4.0), layout="constrained")
    ax.plot(intensity.order, intensity.db(), color="tab:blue", lw=0.9)
    n = intensity.n_pins
    for k in range(1, int(3 * intensity.order[-1] / n) + 1):
        ax.axvline(k * n / 3, color="0.4" if k % 3 else "tab:red", ls="--" if k % 3 else "-", lw=0.7)
    ax.set_xlim(0.0, intensity.order[-1])
    ax.set_xlabel(r"$f / f_{chain}$ (dashed: $k\,n_{pins}/3$, red: $k\,n_{pins}$, " + f"n_pins = {n})")
    ax.set_ylabel(f"mean PSD, dB re 1 {unit}$^2$/Hz" if unit else "mean PSD, dB")
    ax.set_title(title or "time-averaged intensity over f / f_chain", fontsize=10)
    ax.grid(alpha=0.3)
    return save(fig, path)


def plot_order_spectrum(spec: OrderSpectrum, n_pins: int, path: str | Path, title: str = "", unit: str = "",
                        top: float | None = None) -> Path:
    """Order spectrum in dB over ``f / f_chain`` up to ``top`` (default ``1.2 n_pins``): the whole orders
    (``k f_chain``) as a faint grid, the pin-entry orders ``k n_pins / 3`` dashed and ``k n_pins`` red."""
    plt = pyplot()
    top = float(top or 1.2 * n_pins)
    keep = spec.order <= top
    fig, ax = plt.subplots(figsize=(9.0, 4.2), layout="constrained")
    for k in range(1, int(top) + 1):
        ax.axvline(k, color="0.85", lw=0.4, zorder=0)
    for k in range(1, int(3 * top / n_pins) + 1):
        ax.axvline(k * n_pins / 3, color="0.4" if k % 3 else "tab:red", ls="--" if k % 3 else "-", lw=0.8)
    ax.plot(spec.order[keep], spec.db()[keep], color="tab:blue", lw=0.8)
    ax.set_xlim(0.0, top)
    ax.set_xlabel(r"order $f / f_{chain}$ (grey: whole orders; dashed: $k\,n_{pins}/3$; red: $k\,n_{pins}$, "
                  f"n_pins = {n_pins})")
    ax.set_ylabel(f"PSD, dB re 1 {unit}$^2$ per order" if unit else "PSD, dB per order")
    ax.set_title(title or f"order spectrum over {spec.revolutions:.3g} chain revolutions "
                          f"(resolution {1 / spec.revolutions:.2g} order)", fontsize=10)
    return save(fig, path)
