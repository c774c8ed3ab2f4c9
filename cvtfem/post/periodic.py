"""Plots of periodic responses (matplotlib, imported lazily)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from cvtfem.periodic.response import SAMPLES, ResponseSweep


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_summary(sweep: ResponseSweep, probe: int, path: Path, point: int | None = None) -> Path:
    """Two panels: peak moment of link ``probe`` vs frequency, and its moment over one period.

    Parameters
    ----------
    sweep : ResponseSweep
    probe : int
        Link index.
    path : Path
        PNG file to write.
    point : int, optional
        Sweep point shown over one period (default: largest response with backlash).
    """
    plt = _pyplot()
    name = sweep.nonlinear[0].network.link_names[probe]
    f = sweep.omega / (2 * np.pi)
    pk_nl = sweep.peaks("nonlinear")[:, probe]
    pk_lin = sweep.peaks("linear")[:, probe]
    if point is None:
        point = int(np.argmax(pk_nl))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    if len(f) > 1:
        _draw_branch(ax1, sweep, probe)
        order = np.argsort(f[sweep.requested])
        ax1.plot(f[sweep.requested][order], pk_lin[sweep.requested][order], "s:", ms=3, color="C1",
                 label="without backlash")
        ax1.set_xlabel("cycle frequency, Hz")
        ax1.set_ylabel(f"peak moment {name}, N m")
        ax1.set_title("frequency response (arclength continuation)")
        ax1.legend(fontsize=8)
        ax1.grid(alpha=0.3)
    else:
        ax1.bar(["with backlash", "without"], [pk_nl[0], pk_lin[0]], color=["C0", "C1"])
        ax1.set_ylabel(f"peak moment {name}, N m")
        ax1.set_title(f"ratio {pk_nl[0] / pk_lin[0]:.2f}")
    phase = np.arange(SAMPLES) / SAMPLES * 360
    for sol, label, style in ((sweep.nonlinear[point], "with backlash", "-"),
                              (sweep.linear[point], "without backlash", "--")):
        ax2.plot(phase, sol.link_moments(SAMPLES)[probe], style, label=label)
    ax2.set_xlabel("cycle phase, deg")
    ax2.set_ylabel(f"moment {name}, N m")
    ax2.set_title(f"one period at {f[point]:.3g} Hz")
    ax2.legend()
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def _draw_branch(ax, sweep: ResponseSweep, probe: int) -> None:
    """Peak moment of link ``probe`` along every continuation point: a piece between two reported
    points is solid when both are Floquet-stable, dashed otherwise; folds marked."""
    br = sweep.branch
    f = br.omega / (2 * np.pi)
    pk = np.array([np.abs(s.link_moments(SAMPLES)[probe]).max() for s in br.solutions])
    known = np.isfinite(sweep.floquet_max)
    for k in range(len(sweep.index) - 1):
        lo, hi = sweep.index[k], sweep.index[k + 1] + 1
        solid = not known.all() or (sweep.stable[k] and sweep.stable[k + 1])
        ax.plot(f[lo:hi], pk[lo:hi], "-" if solid else "--", color="C0" if solid else "C3", lw=1.4)
    ax.plot([], [], "-", color="C0", label="with backlash, stable" if known.all() else "with backlash")
    if known.all():
        ax.plot([], [], "--", color="C3", label="with backlash, unstable (Floquet)")
    req = sweep.index[sweep.requested]
    ax.plot(f[req], pk[req], "o", ms=2.5, color="0.2", label="requested frequencies")
    turn = sweep.index[sweep.turning]
    if turn.size:
        ax.plot(f[turn], pk[turn], "kD", ms=6, mfc="none", label="turning points")


def plot_branch(omega: np.ndarray, amplitude: np.ndarray, stability: tuple | None, path: Path,
                ylabel: str = "peak deflection, m", up_down: tuple | None = None) -> Path:
    """Continuation branch (amplitude vs frequency), optional up/down sweeps.

    ``stability = (indices, stable)`` marks the points where Floquet multipliers were computed.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    ax.plot(omega, amplitude, "-", color="0.6", lw=1, label="arclength continuation")
    if stability is not None:
        idx, stable = stability
        ax.plot(omega[idx[stable]], amplitude[idx[stable]], "o", ms=3, color="C0", label="stable (Floquet)")
        ax.plot(omega[idx[~stable]], amplitude[idx[~stable]], "o", ms=3, color="C3", label="unstable (Floquet)")
    if up_down is not None:
        for (w, amp), label, marker in zip(up_down, ("sweep up", "sweep down"), ("^", "v")):
            ax.plot(w, amp, marker, ms=5, mfc="none", label=label)
    ax.set_xlabel("forcing frequency, rad/s")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)
