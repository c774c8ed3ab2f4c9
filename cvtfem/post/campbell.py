"""Campbell diagram plot (matplotlib, imported lazily)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.modal.campbell import Campbell

#: Colour and line style of a tracked curve, and the marker of its crossings, by whirl label.
_STYLE = {"forward": ("tab:red", "-", "^"), "backward": ("tab:blue", "--", "v"),
          "torsional": ("tab:green", "-.", "s"), "axial": ("tab:gray", ":", "D")}
#: Offsets (points) tried in turn for a crossing label: below right, above right, below left, above left.
_LABEL_OFFSETS = ((5, -11), (5, 4), (-42, -11), (-42, 4))


def spread(y: np.ndarray, gap: float, low: float, high: float) -> np.ndarray:
    """Positions nearest to ``y`` (same order) that are at least ``gap`` apart and inside ``[low, high]``.

    Used to stack labels along an edge of the axes without overlap: a forward pass pushes each
    label above the one below it, a backward pass pulls the stack down under ``high``.
    """
    order = np.argsort(y, kind="stable")
    out = np.clip(np.asarray(y, float)[order], low, high)
    for i in range(1, len(out)):
        out[i] = max(out[i], out[i - 1] + gap)
    if len(out) and out[-1] > high:
        out[-1] = high
        for i in range(len(out) - 2, -1, -1):
            out[i] = min(out[i], out[i + 1] - gap)
    placed = np.empty_like(out)
    placed[order] = out
    return placed


def _order_labels(ax, result: Campbell, rpm: np.ndarray, top: float) -> None:
    """Excitation lines, labelled where they leave the axes: on the right edge, stacked without overlap,
    or above the top edge for lines that leave through it."""
    right, above = [], []
    for label, factor in result.orders:
        f = factor * result.speeds / (2 * np.pi)
        ax.plot(rpm, f, color="k", lw=0.8, ls=":")
        if f[-1] > top:
            above.append((label, float(np.interp(top, f, rpm))))
        else:
            right.append((label, float(f[-1])))
    if right:
        ys = spread(np.array([y for _, y in right]), 0.035 * top, 0.0, 0.98 * top)
        for (label, y0), y in zip(right, ys):
            ax.annotate(label, (rpm[-1], y0), xytext=(rpm[-1], y), textcoords="data", fontsize=7,
                        va="center", xycoords="data", annotation_clip=False,
                        arrowprops={"arrowstyle": "-", "lw": 0.4, "color": "0.5"} if abs(y - y0) > 0.01 * top
                        else None, horizontalalignment="left")
    if above:
        span = rpm[-1] - rpm[0]
        xs = spread(np.array([x for _, x in above]), 0.09 * span, rpm[0], rpm[-1])
        for (label, _), x in zip(above, xs):
            ax.annotate(label, (x, top), fontsize=7, ha="center", va="bottom", xytext=(0, 2),
                        textcoords="offset points", annotation_clip=False, rotation=30)


def _crossings(ax, result: Campbell, top: float) -> None:
    """Critical speeds: a marker per whirl kind; rpm labels where they do not collide (display coordinates)."""
    from matplotlib.transforms import Bbox

    renderer = ax.figure.canvas.get_renderer()
    shown = [(c["speed_rad_s"] * 30 / np.pi, c["frequency_rad_s"] / (2 * np.pi), c["whirl"])
             for c in result.crossings if c["frequency_rad_s"] / (2 * np.pi) <= top]
    half = 5.0 * ax.figure.dpi / 72.0  # half a 7-point marker plus its edge, pixels
    taken = [Bbox.from_extents(x - half, y - half, x + half, y + half)
             for x, y in ax.transData.transform([(s, f) for s, f, _ in shown]).reshape(-1, 2)]
    for s, f, whirl in shown:
        color, _, marker = _STYLE.get(whirl, ("k", "-", "o"))
        ax.plot(s, f, marker, mfc="none", mec=color, ms=7, mew=1.4)
        for dx, dy in _LABEL_OFFSETS:
            text = ax.annotate(f"{s:.0f} rpm", (s, f), fontsize=7, xytext=(dx, dy), textcoords="offset points")
            box = text.get_window_extent(renderer).expanded(1.12, 1.3)
            if not any(box.overlaps(b) for b in taken) and ax.bbox.contains(box.x0, box.y0) \
                    and ax.bbox.contains(box.x1, box.y1):
                taken.append(box)
                break
            text.remove()


def plot_campbell(result: Campbell, path: str | Path, title: str = "", fmax: float | None = None,
                  lines: tuple = ()) -> Path:
    """Tracked damped frequencies (Hz) over speed (rpm), excitation lines and critical speeds.

    Curves are coloured by whirl at each speed (forward red, backward blue dashed, torsional green,
    axial grey); crossings carry the marker of their mode's whirl (forward triangle up, backward down,
    torsional square, axial diamond) and an rpm label where it does not collide with another.  ``fmax``
    (Hz) limits the frequency axis.  A second panel shows the damping ratios when any is non-zero.
    ``lines``: further ``(label, Hz per speed)`` curves (the sheaves' own waves), thin, labelled at their end.

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
    fig, axes = plt.subplots(2 if damped else 1, 1, figsize=(8.6, 7.5 if damped else 5.5), sharex=True,
                             squeeze=False, gridspec_kw={"height_ratios": [3, 1]} if damped else None)
    ax = axes[0, 0]
    top = fmax or 1.05 * hz.max()
    for j in range(hz.shape[1]):
        kinds = result.whirl[:, j]
        for kind, (color, ls, _) in _STYLE.items():
            ax.plot(rpm, np.where(kinds == kind, hz[:, j], np.nan), color=color, ls=ls, lw=1.6)
    for kind, (color, ls, marker) in _STYLE.items():
        if np.any(result.whirl == kind):
            ax.plot([], [], color=color, ls=ls, marker=marker, mfc="none", label=kind)
    shown = [(label, line) for label, line in lines if 0 < line[-1] < top]
    at = spread(np.array([line[-1] for _, line in shown]), 0.025 * top, 0.0, top)
    for label, line in lines:
        ax.plot(rpm, line, color="tab:purple", ls="-." if label.endswith("bw") else ":", lw=1.1)
    for (label, _), y in zip(shown, at):
        ax.annotate(label, (rpm[-1], y), fontsize=7, color="tab:purple", ha="left", va="center",
                    annotation_clip=False)
    ax.set_ylim(0, top)
    ax.set_xlim(rpm[0], rpm[-1])
    _order_labels(ax, result, rpm, top)
    ax.set_ylabel("damped natural frequency (Hz)")
    ax.set_title(title or "Campbell diagram", pad=22)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    if damped:
        ax2 = axes[1, 0]
        for j in range(hz.shape[1]):
            color, ls, _ = _STYLE.get(result.whirl[-1, j], ("k", "-", "o"))
            ax2.plot(rpm, result.damping_ratio[:, j], color=color, ls=ls, lw=1)
        ax2.set_ylabel("damping ratio")
        ax2.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("shaft speed (rpm)")
    fig.tight_layout(rect=(0, 0, 0.93, 1))
    _crossings(ax, result, top)
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
