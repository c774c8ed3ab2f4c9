"""Sweep results as tables, maps and reports: contour maps over two varied numbers (one panel per value of the
other varied keys, e.g. per sheave profile), lines over one, and a Markdown or HTML report from a template."""
from __future__ import annotations

import html
import math
from pathlib import Path
from string import Template
from typing import Any

import numpy as np

from cvtfem.post.figures import pyplot, save

#: Summary numbers plotted by default, per analysis (a report tabulates every summary number).
PLOTTED = {"run": ("efficiency", "F1_F2"), "modes": ("f0_Hz", "f2_Hz"), "campbell": ("first_critical_rpm",),
           "periodic": ("peak_moment_Nm",)}
#: Summary numbers' labels on plots.
LABELS = {"efficiency": "efficiency", "F1_F2": "clamping-force ratio F1/F2", "ratio": "speed ratio",
          "cvt.regime.torque": "input torque M1, N m", "cvt.regime.ratio": "ratio i = w1/w2"}

MARKDOWN = Template("""# Sweep report: $analysis of $scene

$counts. Index: `$index`.

$figures

## Variants

$table
""")

HTML = Template("""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>Sweep report: $analysis of $scene</title>
<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;font-size:90%}
td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}img{max-width:100%}</style></head>
<body><h1>Sweep report: $analysis of $scene</h1>
<p>$counts. Index: <code>$index</code>.</p>
$figures
<h2>Variants</h2>
$table
</body></html>
""")


def layout(index: dict[str, Any]) -> tuple[list[str], list[str]]:
    """``(axes, groups)``: the varied keys with numeric values (the first two are plot axes) and the varied keys
    with other values (one panel per combination)."""
    entries = index["variants"]
    keys = list(dict.fromkeys(k for e in entries for k in e["params"]))
    varied = [k for k in keys if len({repr(e["params"].get(k)) for e in entries}) > 1]
    numeric = [k for k in varied if all(isinstance(e["params"].get(k), (int, float)) and
                                        not isinstance(e["params"].get(k), bool) for e in entries)]
    return numeric, [k for k in varied if k not in numeric]


def _value(entry: dict[str, Any], name: str) -> float:
    v = entry["summary"].get(name)
    return float(v) if isinstance(v, (int, float)) else math.nan   # None: undefined (e.g. efficiency at zero torque)


def plot_quantity(index: dict[str, Any], name: str, path: str | Path) -> Path | None:
    """A contour map of summary number ``name`` over the first two numeric varied keys (a line plot over one),
    one panel per combination of the other varied keys, the maximum of each panel marked; None if nothing to plot."""
    axes, groups = layout(index)
    done = [e for e in index["variants"] if e["status"] == "finished" and math.isfinite(_value(e, name))]
    if not axes or not done:
        return None
    panels: dict[tuple, list] = {}
    for e in done:
        panels.setdefault(tuple(e["params"].get(k) for k in groups), []).append(e)
    plt = pyplot()
    fig, axs = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.2), squeeze=False, layout="constrained")
    z_all = np.array([_value(e, name) for e in done])
    levels = np.linspace(z_all.min(), z_all.max(), 15) if np.ptp(z_all) > 0 else None
    for ax, (group, es) in zip(axs[0], sorted(panels.items(), key=lambda kv: repr(kv[0]))):
        x = np.array([e["params"][axes[0]] for e in es], float)
        z = np.array([_value(e, name) for e in es])
        k = int(np.argmax(z))
        if len(axes) >= 2:
            y = np.array([e["params"][axes[1]] for e in es], float)
            if len(es) >= 3 and levels is not None and np.ptp(x) > 0 and np.ptp(y) > 0:
                cs = ax.tricontourf(x, y, z, levels=levels, cmap="viridis")
                ax.tricontour(x, y, z, levels=levels, colors="k", linewidths=0.4)
            else:
                cs = ax.scatter(x, y, c=z, cmap="viridis")
            ax.plot(x, y, ".", color="w", ms=2)
            ax.plot(x[k], y[k], "r*", ms=14, label=f"max {z[k]:.5g} at ({x[k]:.4g}, {y[k]:.4g})")
            ax.set_ylabel(LABELS.get(axes[1], axes[1]))
        else:
            order = np.argsort(x)
            ax.plot(x[order], z[order], "o-")
            ax.plot(x[k], z[k], "r*", ms=14, label=f"max {z[k]:.5g} at {x[k]:.4g}")
            ax.set_ylabel(LABELS.get(name, name))
        ax.set_xlabel(LABELS.get(axes[0], axes[0]))
        ax.legend(loc="best", fontsize=8)
        ax.set_title(", ".join(f"{g.rsplit('.', 1)[-1]} = {v}" for g, v in zip(groups, group)) or name)
    if len(axes) >= 2:
        fig.colorbar(cs, ax=axs[0].tolist(), label=LABELS.get(name, name), format="%.5g")
    fig.suptitle(f"{LABELS.get(name, name)}: {index['analysis']} of {index['scene']}")
    return save(fig, path)


def maxima(index: dict[str, Any], name: str) -> list[tuple[dict[str, Any], float]]:
    """Per combination of the non-numeric varied keys, the parameters and value of the largest ``name``."""
    _, groups = layout(index)
    best: dict[tuple, tuple[dict[str, Any], float]] = {}
    for e in index["variants"]:
        v = _value(e, name)
        g = tuple(e["params"].get(k) for k in groups)
        if e["status"] == "finished" and math.isfinite(v) and (g not in best or v > best[g][1]):
            best[g] = (e["params"], v)
    return list(best.values())


def write_report(index: dict[str, Any], out: str | Path, fmt: str = "md", index_path: str = "") -> Path:
    """Fill the Markdown or HTML template with the sweep's table and its plots (PNGs beside ``out``)."""
    out = Path(out)
    entries = index["variants"]
    keys = list(dict.fromkeys(k for e in entries for k in e["params"]))
    numbers = list(dict.fromkeys(k for e in entries for k in e["summary"]))
    head = ["id", *keys, "status", *numbers, "wall s"]
    rows = [[e["id"], *(_cell(e["params"].get(k)) for k in keys), e["status"],
             *(_cell(e["summary"].get(k)) for k in numbers), _cell(e["wall_s"])] for e in entries]
    figures = []
    for name in PLOTTED.get(index["analysis"], ()):
        png = plot_quantity(index, name, out.with_name(f"{out.stem}_{name}.png"))
        if png is not None:
            varied = sum(layout(index), [])
            best = "; ".join(f"{v:.6g} at " + ", ".join(f"{k} = {_cell(p.get(k))}" for k in varied)
                             for p, v in maxima(index, name))
            figures.append((LABELS.get(name, name), png.name, f"maximum: {best}"))
    status: dict[str, int] = {}
    for e in entries:
        status[e["status"]] = status.get(e["status"], 0) + 1
    counts = f"{len(entries)} variants: " + ", ".join(f"{n} {s}" for s, n in sorted(status.items()))
    fields = {"analysis": index["analysis"], "scene": index["scene"], "counts": counts, "index": index_path}
    if fmt == "html":
        esc = html.escape
        fig_text = "\n".join(f"<h2>{esc(t)}</h2>\n<p>{esc(note)}</p>\n<img src=\"{esc(p)}\" alt=\"{esc(t)}\">"
                             for t, p, note in figures)
        table = ("<table>\n<tr>" + "".join(f"<th>{esc(h)}</th>" for h in head) + "</tr>\n"
                 + "\n".join("<tr>" + "".join(f"<td>{esc(c)}</td>" for c in r) + "</tr>" for r in rows) + "\n</table>")
        text = HTML.substitute({k: esc(v) for k, v in fields.items()}, figures=fig_text, table=table)
    else:
        fig_text = "\n\n".join(f"## {t}\n\n{note}\n\n![{t}]({p})" for t, p, note in figures)
        table = "\n".join(["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
                          + ["| " + " | ".join(r) + " |" for r in rows])
        text = MARKDOWN.substitute(fields, figures=fig_text, table=table)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text, encoding="utf-8")
    return out


def _cell(v: Any) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)
