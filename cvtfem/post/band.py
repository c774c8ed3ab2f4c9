"""Plots of band-model runs (PNG): regime history and normal force along the contact arcs.

matplotlib is imported inside the functions (``import cvtfem`` must not load it).
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from cvtfem.post.figures import pyplot, save

RPM = 30 / math.pi


def windowed_efficiency(t, work, window: float = 0.05, energy=None):
    """Moving-window efficiency over ``window`` seconds from cumulative works ``(n, 4)`` (J).

    Without ``energy``: ``dW_out / dW_in``.  With the model energy ``(n,)`` (J): the kinetic-energy
    corrected form ``1 - (dW_in - dW_out - dE) / dW_in`` of spec section 6.2.
    """
    t = np.asarray(t)
    work = np.asarray(work)
    j = np.searchsorted(t, t - window)
    d_in = work[:, 0] - work[j, 0]
    d_out = work[:, 1] - work[j, 1]
    if energy is not None:
        E = np.asarray(energy).reshape(-1)
        d_out = d_out + (E - E[j])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(d_in > 0, d_out / np.where(d_in > 0, d_in, 1.0), np.nan)


def plot_regime(results, path: str | Path, title: str = "") -> Path:
    """Speeds (rpm), ratio, efficiency and clamping forces against time from a run's results.

    Parameters
    ----------
    results : cvtfem.io.results.Results
        A ``cvtfem run`` results file read back.
    path : path of the PNG to write.
    """
    plt = pyplot()

    s, t = results.series, results.time
    fig, ax = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    ax[0].plot(t, s["driving.speed"][:, 0] * RPM, label="driving n1")
    ax[0].plot(t, s["driven.speed"][:, 0] * RPM, label="driven n2")
    ax[0].set_ylabel("speed, rpm")
    ax[0].legend(loc="best")
    ax[1].plot(t, s["ratio"][:, 0], label="omega1/omega2")
    ax[1].plot(t, s["control.ratio_estimate"][:, 0], "--", label="smoothed estimate")
    ax[1].set_ylabel("ratio")
    ax[1].legend(loc="best")
    ax[2].plot(t, windowed_efficiency(t, s["work"]), label="output / input, 0.05 s window")
    ax[2].plot(t, windowed_efficiency(t, s["work"], energy=s["energy"]), "--", label="kinetic-energy corrected")
    ax[2].set_ylabel("efficiency")
    ax[2].legend(loc="best")
    ax[3].plot(t, s["driving.clamping_force"][:, 0] / 1e3, label="F1")
    ax[3].plot(t, s["driven.clamping_force"][:, 0] / 1e3, label="F2")
    ax[3].set_ylabel("clamping force, kN")
    ax[3].set_xlabel("time, s")
    ax[3].legend(loc="best")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title or "regime history")
    fig.tight_layout()
    return save(fig, path)


def plot_normal_force(xi, curves: Mapping[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """Normal force per sheave along both arcs against ``xi = theta / theta*`` (band enters at xi = -1).

    Parameters
    ----------
    xi : (g,) quadrature nodes in [-1, 1].
    curves : mapping label -> (2, g) array, N/m (arc 1 = driving, arc 2 = driven).
    """
    plt = pyplot()

    fig, ax = plt.subplots(1, 2, figsize=(10, 4), sharey=False)
    for label, N in curves.items():
        N = np.asarray(N).reshape(2, -1)
        for k in range(2):
            ax[k].plot(xi, N[k] / 1e3, marker=".", label=label)
    for k, name in enumerate(("driving pulley (arc 1)", "driven pulley (arc 2)")):
        ax[k].set_title(name)
        ax[k].set_xlabel("theta / theta*  (band enters at -1)")
        ax[k].grid(alpha=0.3)
    ax[0].set_ylabel("normal force per sheave, kN/m")
    ax[1].legend(loc="best", fontsize=8)
    fig.suptitle(title or "normal force along the contact arcs")
    fig.tight_layout()
    return save(fig, path)


def convergence_table(xi, curves: Mapping[int, np.ndarray]) -> Sequence[tuple[int, float]]:
    """Relative L2 difference of each normal-force distribution to the highest-order one."""
    ref = curves[max(curves)]
    return [(n, float(np.linalg.norm(N - ref) / np.linalg.norm(ref))) for n, N in sorted(curves.items())]
