"""Rotor design figures: static deflection, undamped critical-speed map, 2D mode shapes (matplotlib, lazily)."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _pyplot():  # noqa: ANN202 - matplotlib.pyplot
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _marks(ax, z: np.ndarray, supports, disks) -> None:  # noqa: ANN001 - matplotlib axes
    """Supports (triangles) and disks (bars) along the shaft."""
    for node in supports:
        ax.plot(z[node], 0, "^", color="tab:gray", ms=9, zorder=3)
    for node in disks:
        ax.axvline(z[node], color="tab:orange", lw=1, alpha=0.6)


def plot_static(z: np.ndarray, deflections: dict, supports, disks, path: str | Path, title: str = "") -> Path:
    """Vertical deflection (um) along the shaft (m), one curve per case in ``deflections`` (label -> u2, m)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for label, u in deflections.items():
        ax.plot(z, 1e6 * np.asarray(u), "o-", ms=3, label=label)
    _marks(ax, z, supports, disks)
    ax.set_xlabel("axial position (m)")
    ax.set_ylabel("static deflection u2 (um)")
    ax.set_title(title or "static deflection under gravity")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_critical_map(stiffness: np.ndarray, wn: np.ndarray, path: str | Path, support_curves=(),
                      crossings=(), title: str = "") -> Path:
    """Undamped critical-speed map: ``wn (p, modes)`` (rad/s, drawn in rpm) over the support stiffness (N/m,
    log-log); ``support_curves``: (label, k(speed) N/m, speeds rad/s) drawn as speed over k; ``crossings``:
    (mode, speed rad/s, k N/m) circled."""
    plt = _pyplot()
    rpm = 30 / np.pi
    fig, ax = plt.subplots(figsize=(7, 5))
    for j in range(wn.shape[1]):
        ax.loglog(stiffness, wn[:, j] * rpm, "-", label=f"mode {j + 1}")
    for label, k, speeds in support_curves:
        ax.loglog(k, np.asarray(speeds) * rpm, "k--", lw=1.2, label=label)
    for j, speed, k in crossings:
        ax.loglog(k, speed * rpm, "o", mfc="none", mec="k", ms=10)
        ax.annotate(f"{speed * rpm:.0f} rpm", (k, speed * rpm), textcoords="offset points", xytext=(6, -12),
                    fontsize=8)
    ax.set_xlabel("support stiffness (N/m)")
    ax.set_ylabel("undamped critical speed (rpm)")
    ax.set_title(title or "undamped critical-speed map")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_mode_shapes(z: np.ndarray, modes, n_shaft_nodes: int, path: str | Path, supports=(), disks=(),
                     title: str = "") -> Path:
    """2D mode shapes: per mode the x (u1, solid) and y (u2, dashed) displacements along the shaft, each shape
    turned so that its largest lateral component is real and positive, then the real parts; title lines give
    the frequency, log decrement and whirl."""
    plt = _pyplot()
    k = len(modes.wd)
    fig, axes = plt.subplots(k, 1, figsize=(8, 1.9 * k + 0.6), sharex=True, squeeze=False)
    zs = z[:n_shaft_nodes]
    for i, ax in enumerate(axes[:, 0]):
        X = modes.shapes[: 6 * n_shaft_nodes, i].reshape(-1, 6)
        lateral = X[:, :2]
        peak = lateral.ravel()[np.argmax(np.abs(lateral))]
        if abs(peak) == 0:  # torsional or axial: draw that component
            comp = 5 if modes.whirl[i] == "torsional" else 2
            peak = X[np.argmax(np.abs(X[:, comp])), comp]
            ax.plot(zs, (X[:, comp] / peak).real, "-", color="tab:green", label=modes.whirl[i])
        else:
            shape = lateral / peak
            ax.plot(zs, shape[:, 0].real, "-", color="tab:red", label="x (u1)")
            ax.plot(zs, shape[:, 1].real, "--", color="tab:blue", label="y (u2)")
        ax.axhline(0, color="k", lw=0.5)
        _marks(ax, zs, supports, disks)
        ax.set_title(f"mode {i + 1}: {modes.wd[i] / (2 * np.pi):.4g} Hz, log dec {modes.log_dec[i]:.3g}, "
                     f"{modes.whirl[i]}", fontsize=9)
        ax.set_ylim(-1.15, 1.15)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("axial position (m)")
    fig.suptitle(title or f"mode shapes at {modes.speed * 30 / np.pi:.5g} rpm", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
