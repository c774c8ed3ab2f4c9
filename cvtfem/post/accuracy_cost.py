"""Figures of the accuracy-cost study (issue 16): Jacobian spectra on the signed-log plane, the global error of
the pin force against wall time and RHS calls, and the force traces behind that error."""
from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import NullFormatter  # noqa: E402

from cvtfem.integrate.study import signed_log  # noqa: E402

#: Linear part of the signed-log axes, 1/s: eigenvalues below it in modulus are drawn linearly.
X_STAR = 1.0


def _log_ticks(ax, axis: str, top: float) -> None:
    """Ticks at 0 and +-10^k (1/s) on a signed-log axis reaching ``top``."""
    powers = 10.0 ** np.arange(0, int(np.ceil(np.log10(max(top, 10.0)))) + 1, 2)
    values = np.concatenate([-powers[::-1], [0.0], powers])
    labels = [("-" if v < 0 else "") + (f"1e{int(np.log10(abs(v)))}" if v else "0") for v in values]
    getattr(ax, f"set_{axis}ticks")(signed_log(values, X_STAR), labels, fontsize=7)


def plot_spectra(spectra: dict, path: str | Path, title: str = "") -> Path:
    """Eigenvalues (1/s) of each ``label -> array`` on the signed-log plane (spec section 2.3, x* = 1/s)."""
    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    top = 10.0
    for (label, lam), (marker, colour, size) in zip(spectra.items(), (("o", "C0", 40), ("+", "C3", 18),
                                                                       ("x", "C2", 18), ("^", "C1", 18))):
        lam = np.asarray(lam)
        top = max(top, float(np.max(np.abs(lam.real))), float(np.max(np.abs(lam.imag))))
        style = {"facecolors": "none", "edgecolors": colour} if marker == "o" else {"color": colour}
        ax.scatter(signed_log(lam.real, X_STAR), signed_log(lam.imag, X_STAR), s=size, marker=marker, **style,
                   label=f"{label}: min Re {lam.real.min():.3g}, max |Im| {np.abs(lam.imag).max():.3g} 1/s")
    _log_ticks(ax, "x", top)
    _log_ticks(ax, "y", top)
    ax.axvline(0.0, color="grey", lw=0.6)
    ax.axhline(0.0, color="grey", lw=0.6)
    ax.set_xlabel("Re lambda, 1/s (signed log beyond 1)")
    ax.set_ylabel("Im lambda, 1/s (signed log beyond 1)")
    ax.set_title(textwrap.fill(title or "Jacobian eigenvalues", 100), fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_accuracy_cost(rows, path: str | Path, accept: float, title: str = "") -> Path:
    """Global error E of each run against wall time (left) and RHS calls (middle), one line per method, each
    point labelled with its step or tolerance; the acceptance ``E = accept`` dashed.  Where the rows carry the
    energy balance (``energy_residual``), a third panel: its modulus (relative to the input work) against RHS calls,
    so a run accepted by E that chatters in stick (dissipating too much) stands out."""
    energy = [r for r in rows if r.get("energy_residual") is not None and np.isfinite(r["energy_residual"])]
    fig, axes = plt.subplots(1, 3 if energy else 2, figsize=(18 if energy else 12, 5))
    finite = [r for r in rows if np.isfinite(r["error"]) and r["error"] > 0]
    panels = [(axes[0], finite, "time", "error", "wall time, s (median)"),
              (axes[1], finite, "nfev", "error", "RHS calls")]
    if energy:
        panels.append((axes[2], energy, "nfev", "energy_residual", "RHS calls"))
    for (ax, use, key, value, xlabel) in panels:
        for k, label in enumerate(dict.fromkeys(r["label"] for r in finite + energy)):
            pts = [r for r in use if r["label"] == label]        # in the order of the settings
            if not pts:
                continue
            ys = [max(abs(r[value]), 1e-16) for r in pts]
            line, = ax.loglog([r[key] for r in pts], ys, marker="o", ms=4, label=label, color=f"C{k % 10}",
                              ls=("-", "--", ":")[k // 10 % 3])
            for r, y in zip(pts, ys):
                ax.annotate(r["setting"], (r[key], y), fontsize=6, color=line.get_color(),
                            xytext=(3, 3), textcoords="offset points")
        ax.set_xlabel(xlabel)
        ax.grid(alpha=0.3, which="both")
        ax.xaxis.set_minor_formatter(NullFormatter())        # a decade's minor labels overran each other
    for ax in axes[:2]:
        ax.axhline(accept, color="k", ls="--", lw=0.8)
        ax.set_ylabel("E = max|P - P*| / max|P*| over the window")
    if energy:
        axes[2].set_ylabel("|energy balance residual| / input work, over the run")
    axes[1].legend(fontsize=7, loc="lower left")
    failed = sorted({f"{r['label']} {r['setting']}" for r in rows if not np.isfinite(r["error"])})
    note = f"\nfailed or unstable: {', '.join(failed)}" if failed else ""
    fig.suptitle(textwrap.fill(title or "accuracy against cost", 150) + note, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_local_errors(rows, path: str | Path, title: str = "") -> Path:
    """Test 1: local error e(h) of one step (left) and the effective order p~(h) (right, at the geometric mean
    of neighbouring steps) of each method; its nominal order dotted on the right."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5.5))
    labels = list(dict.fromkeys(r["label"] for r in rows))
    colours = plt.get_cmap("tab20")(np.linspace(0, 1, max(len(labels), 2)))
    for k, (label, colour) in enumerate(zip(labels, colours)):
        mine = [r for r in rows if r["label"] == label]
        hs = np.array([r["h"] for r in mine])
        errs = np.array([r["error"] for r in mine])
        style = ("-", "--", "-.", ":")[k % 4]
        finite = np.isfinite(errs) & (errs > 0)
        a1.loglog(hs[finite], errs[finite], "o" + style, ms=3, color=colour, label=f"{label} ({mine[0]['nominal']})")
        p = np.array([r["p_eff"] for r in mine[1:]], float)
        a2.semilogx(np.sqrt(hs[:-1] * hs[1:]), p, "o" + style, ms=3, color=colour)
    a1.set_xlabel("step h, s")
    a1.set_ylabel("local error e(h), weighted max norm")
    a2.set_xlabel("step h, s")
    a2.set_ylabel("effective order p~ = d ln e / d ln h - 1")
    a2.set_ylim(-1, 9)
    a1.legend(fontsize=6, ncol=2, loc="upper left", title="method (nominal order)", title_fontsize=7)
    for ax in (a1, a2):
        ax.grid(alpha=0.3, which="both")
    fig.suptitle(title or "local error and effective order", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_force_traces(t, reference, runs: dict, path: str | Path, accept: float, title: str = "",
                      unit: str = "N") -> Path:
    """Test 2's output over the window: the reference ``P*(t)`` and each run's ``P(t)`` (``label -> series``, top),
    and their differences scaled as ``E``, ``(P - P*) / max |P*|`` (bottom, the acceptance ``+-accept`` dashed),
    against ``t`` (s, drawn in ms)."""
    t_ms = 1e3 * np.asarray(t)
    scale = float(np.max(np.abs(reference)))
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(11, 7), sharex=True, gridspec_kw={"height_ratios": (3, 2)})
    a1.plot(t_ms, reference, "k-", lw=1.4, label="reference")
    for k, (label, p) in enumerate(runs.items()):
        e = float(np.max(np.abs(p - reference)) / scale)
        a1.plot(t_ms, p, "-", lw=0.8, color=f"C{k}", label=f"{label}: E = {e:.3g}")
        a2.plot(t_ms, (p - reference) / scale, "-", lw=0.8, color=f"C{k}", label=label)
    for s in (-accept, accept):
        a2.axhline(s, color="k", ls="--", lw=0.8)
    a1.set_ylabel(f"output, {unit}")
    a2.set_ylabel("(P - P*) / max |P*|")
    a2.set_xlabel("t, ms")
    a1.legend(fontsize=8, loc="best")
    for ax in (a1, a2):
        ax.grid(alpha=0.3)
    fig.suptitle(textwrap.fill(title or "output over the window", 130), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)
