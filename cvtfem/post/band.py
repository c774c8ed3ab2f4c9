"""Plots of band-model runs (PNG): normal force along the contact arcs (the regime history of any CVT run is
:mod:`cvtfem.post.history`).

matplotlib is imported inside the functions (``import cvtfem`` must not load it).
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from cvtfem.post.figures import pyplot, save


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
