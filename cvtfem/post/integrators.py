"""Plots of the integrator studies (matplotlib, imported lazily): stability regions on the
linear or signed-log plane (spec §2.3, §3.3), effective order (§9.4), work-precision (§9.6)."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from cvtfem.integrate.study import amplification, effective_order, signed_log, signed_log_inverse
from cvtfem.post.figures import pyplot, save

__all__ = ["plot_stability", "plot_effective_order", "plot_work_precision", "write_csv"]


def plot_stability(methods, path: Path, extent: float = 6.0, log: bool = False, n: int = 401,
                   x_star: float = 1e-3, log_extent: float = 1e4) -> Path:
    """Stable regions ``|R(z)| <= 1`` of ``methods`` = [(label, method, options), ...].

    Linear plane ``[-extent, extent/3] x [-extent, extent]`` or, with ``log``, the signed-log
    plane (``x* = 1e-3``, up to ``+-log_extent``), grid lines at powers of ten.
    """
    plt = pyplot()
    if log:
        lim = float(signed_log(log_extent, x_star))
        u = np.linspace(-lim, lim, n)
        re_t, im_t = np.meshgrid(u, u)
        z = signed_log_inverse(re_t, x_star) + 1j * signed_log_inverse(im_t, x_star)
        X, Y = re_t, im_t
    else:
        re = np.linspace(-extent, extent / 3, n)
        im = np.linspace(-extent, extent, n)
        X, Y = np.meshgrid(re, im)
        z = X + 1j * Y
    k = len(methods)
    cols = min(k, 4)
    rows = (k + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.2 * rows), squeeze=False)
    for ax, (label, method, options) in zip(axes.flat, methods):
        r = amplification(method, z, **options)
        ax.contourf(X, Y, (r <= 1).astype(float), levels=[0.5, 1.5], colors=["#6a9fd4"])
        ax.contour(X, Y, r, levels=[1.0], colors="k", linewidths=0.6)
        ax.axhline(0, color="0.4", lw=0.5)
        ax.axvline(0, color="0.4", lw=0.5)
        ax.set_title(label, fontsize=9)
        ax.set_aspect("equal")
        if log:
            decades = np.arange(int(np.log10(x_star)), int(np.log10(log_extent)) + 1)
            ticks = np.concatenate([-signed_log(10.0 ** decades[::-1], x_star), [0],
                                    signed_log(10.0 ** decades, x_star)])
            labels = [f"-1e{d}" for d in decades[::-1]] + ["0"] + [f"1e{d}" for d in decades]
            for tk in ticks:
                style = "-" if abs(abs(tk) - signed_log(1.0, x_star)) < 1e-9 else ":"
                ax.axvline(tk, color="0.6", lw=0.4, ls=style)
                ax.axhline(tk, color="0.6", lw=0.4, ls=style)
            ax.set_xticks(ticks[::2], labels[::2], fontsize=6, rotation=90)
            ax.set_yticks(ticks[::2], labels[::2], fontsize=6)
        ax.set_xlabel("Re hλ" + (" (signed log)" if log else ""), fontsize=8)
        ax.set_ylabel("Im hλ", fontsize=8)
    for ax in list(axes.flat)[k:]:
        ax.set_visible(False)
    fig.suptitle("stability regions |R(hλ)| ≤ 1 (brute force, one step per pixel)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.35 / fig.get_figheight()))  # keep the first row's titles clear
    return save(fig, path)


def plot_effective_order(curves, path: Path, title: str = "") -> Path:
    """``curves`` = [(label, hs, errs, nominal order)]: local error e(h) and p~(h) (spec (2.8))."""
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    for label, hs, errs, p in curves:
        line, = a1.loglog(hs, errs, "o-", ms=3, label=label)
        hm = np.sqrt(np.asarray(hs[:-1]) * np.asarray(hs[1:]))
        a2.semilogx(hm, effective_order(hs, errs), "o-", ms=3, color=line.get_color())
        a2.axhline(p, color=line.get_color(), ls=":", lw=0.8)
    a1.set_xlabel("h")
    a1.set_ylabel("local error e(h)")
    a2.set_xlabel("h")
    a2.set_ylabel("effective order p~ = dln e/dln h - 1")
    a1.legend(fontsize=7)
    for ax in (a1, a2):
        ax.grid(True, which="both", lw=0.3)
        ax.xaxis.set_minor_formatter(plt.NullFormatter())  # minor labels of a short log range overlap
    fig.suptitle(title or "effective order test", fontsize=10)
    fig.tight_layout()
    return save(fig, path)


def _setting_label(row) -> str:
    """A point's setting: its rtol (adaptive) or its step (fixed)."""
    if "rtol" in row:
        return f"{row['rtol']:.0e}"
    return f"h={row['h']:.0e}" if "h" in row else ""


def plot_work_precision(rows, path: Path, title: str = "", note: str = "") -> Path:
    """Error vs wall time and vs RHS calls, one line per ``label`` (rows from ``work_precision``); each
    point labelled with its rtol (or step), ``note`` (error measure, simulated span) under the panels."""
    from matplotlib.ticker import LogLocator, NullFormatter

    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.8))
    labels = list(dict.fromkeys(r["label"] for r in rows))
    for i, label in enumerate(labels):
        sel = [r for r in rows if r["label"] == label and np.isfinite(r["error"]) and r["error"] > 0]
        if not sel:
            continue
        err = [r["error"] for r in sel]
        # 10 colours, then the next ten dashed with other markers: no two methods look alike
        style = dict(color=f"C{i % 10}", ls=("-", "--", ":")[i // 10 % 3], marker="osv^D"[i // 10 % 5], ms=3)
        a1.loglog([r["time"] for r in sel], err, label=label, **style)
        a2.loglog([r["nfev"] for r in sel], err, label=label, **style)
        for j, r in enumerate(sel):   # labels right of the point, methods staggered vertically
            dy = (-9, 3, 9, -3)[(i + j) % 4]
            for ax, x in ((a1, r["time"]), (a2, r["nfev"])):
                ax.annotate(_setting_label(r), (x, r["error"]), xytext=(4, dy), textcoords="offset points",
                            fontsize=5.5, color=f"C{i % 10}")
    a1.set_xlabel("wall time, s (median)")
    a2.set_xlabel("RHS calls (incl. Jacobians)")
    plotted = any(np.isfinite(r["error"]) and r["error"] > 0 for r in rows)
    for ax in (a1, a2):
        ax.set_ylabel("relative error")
        ax.grid(True, which="both", lw=0.3)
        if plotted:
            ax.xaxis.set_major_locator(LogLocator(base=10, numticks=6))   # decades only: no overlapping labels
            ax.xaxis.set_minor_formatter(NullFormatter())
        else:
            ax.text(0.5, 0.5, "no run reached a finite error\n(all failed or unstable: see the table)",
                    ha="center", va="center", transform=ax.transAxes)
    if plotted:
        a1.legend(fontsize=7)
    fig.suptitle(title or "work-precision", fontsize=10)
    if note:
        fig.text(0.5, 0.01, note, ha="center", va="bottom", fontsize=7.5, wrap=True)
    fig.tight_layout(rect=(0, 0.06 if note else 0, 1, 1))
    return save(fig, path)


def write_csv(rows, path: Path) -> Path:
    """Rows (dicts) to CSV with the union of their keys as header."""
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    return Path(path)
