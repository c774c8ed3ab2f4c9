"""Chain quantities along the chain at an instant and over one revolution of an element (issue 14, deliverable 4;
the source's per-revolution figures, low-order digest §7-8, Figs. 1.60-1.65).

*Loop position* ``s`` in [0, 1): the share of the chain loop from the middle of the tight span, measured along
the closed polyline of the pins in the direction of travel.  The reference point is where the polyline crosses
the centre line ``x1 = L/2`` on the tight span (``x2 < 0``; frame of the chain models: driven shaft at the
origin, driving shaft at ``(L, 0)``, chain counter-clockwise).  An element starting there passes the driving
pulley, the slack span and the driven pulley, and returns, as the source draws it.

Two views of one field: the *distribution* (every element at one instant, against its ``s``) and the *revolution*
(one element followed in time, against its unwrapped ``s(t)``).  In a steady run they coincide, which the tests
check.  Both are resampled on a uniform ``s`` grid and smoothed there by a moving average over a number of link
pitches (the source's moving averages; 3 pitches span one lacing period of the plates).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.ndimage import uniform_filter1d

from cvtfem.errors import InputError

#: Chain series with one value (or one row of values) per link ``p`` (pins ``p`` and ``p + 1``); the others
#: of the chain family are per pin.
LINK_SERIES = frozenset({"chain.link_tension", "chain.link_tension_elastic", "chain.plate_tension", "chain.twist",
                         "chain.shear"})
#: Friction components in the frame of the shaft a pin end touches (derived from ``contact.friction_force``).
FRICTION_PARTS = {"contact.friction_circumferential": 0, "contact.friction_radial": 1, "contact.friction_axial": 2}


def loop_position(u, L: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Loop positions of pins and link midpoints, and the loop length.

    Parameters
    ----------
    u : (n, 2) m
        In-plane pin positions in chain order (pin ``p + 1`` ahead of pin ``p`` in the direction of travel).
    L : m
        Centre distance.

    Returns
    -------
    s_pin, s_link : (n,)
        Loop positions in [0, 1) of the pins and of the link midpoints (link ``p`` joins pins ``p`` and ``p + 1``).
    length : m
        Length of the closed pin polyline.
    """
    u = np.asarray(u, float)
    d = np.roll(u, -1, axis=0) - u
    seg = np.hypot(d[:, 0], d[:, 1])
    c = np.concatenate([[0.0], np.cumsum(seg)])
    length = float(c[-1])
    a, b = u[:, 0], u[:, 0] + d[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = (0.5 * L - a) / d[:, 0]
    crossing = np.flatnonzero((a <= 0.5 * L) & (b > 0.5 * L) & (u[:, 1] + frac * d[:, 1] < 0.0))
    if crossing.size != 1:
        raise InputError("chain.coordinates", f"{crossing.size} crossings",
                         "must describe a closed chain that crosses the centre line x1 = L/2 once on its tight span "
                         "(x2 < 0, moving towards the driving shaft)")
    p = crossing[0]
    ref = c[p] + frac[p] * seg[p]
    return (c[:-1] - ref) % length / length, (c[:-1] + 0.5 * seg - ref) % length / length, length


@dataclass(frozen=True)
class ChainSeries:
    """Per-element values of a run: ``values`` (rows, n, m) with ``m`` components per element (labels
    ``components``), ``kind`` "pin" or "link", ``unit``, and the pins' contact state ``shaft_of`` (rows, n):
    0 on the driving pulley, 1 on the driven one, -1 free."""

    name: str
    values: np.ndarray
    kind: str
    unit: str
    components: tuple[str, ...]
    shaft_of: np.ndarray


def contact_state(normal_force, n: int) -> np.ndarray:
    """Shaft each pin touches (rows, n): 0 driving, 1 driven, -1 none, from ``contact.normal_force`` (pin-major,
    per pin end and shaft); a pin counts as touching a shaft where any of its ends carries a force there."""
    N = np.asarray(normal_force).reshape(len(normal_force), n, -1, 2)
    on = (N > 0).any(axis=2)
    return np.where(on[..., 0], 0, np.where(on[..., 1], 1, -1))


def chain_series(series: dict, units: dict, name: str, u, L: float) -> ChainSeries:
    """The stored series ``name`` (or a derived friction part) per element.

    Parameters
    ----------
    series, units : the results file's series and units.
    u : (rows, n, 2) m
        Pin positions at every row (for the friction parts' shaft frames).
    L : m
        Centre distance.
    """
    rows, n = u.shape[:2]
    state = contact_state(series["contact.normal_force"], n)
    if name in FRICTION_PARTS:
        F = series["contact.friction_force"].reshape(rows, n, -1, 2, 3)
        part = np.zeros(F.shape[:3])
        for k, centre in enumerate(((L, 0.0), (0.0, 0.0))):
            r = u - np.asarray(centre)
            e_r = r / np.linalg.norm(r, axis=-1, keepdims=True)
            e_t = np.stack([-e_r[..., 1], e_r[..., 0]], axis=-1)      # counter-clockwise
            axes = (e_t, e_r)
            j = FRICTION_PARTS[name]
            comp = F[..., k, 2] if j == 2 else np.einsum("rnej,rnj->rne", F[..., k, :2], axes[j])
            part += comp
        return ChainSeries(name, part, "pin", "N", _end_labels(part.shape[2]), state)
    if name not in series:
        raise InputError("name", name, "must be a stored per-pin or per-link series of this results file or a "
                         "friction part: " + ", ".join(sorted(quantities(series, n))))
    y = np.asarray(series[name], float)
    if y.ndim != 2 or y.shape[1] % n:
        raise InputError("name", name, f"must have a multiple of {n} values per row (one or more per pin or "
                         f"link); it has {y.shape[1:]}")
    if name.startswith("contact."):
        y = y.reshape(rows, n, -1, 2).sum(axis=3)                 # a pin end touches one shaft at a time
        labels = _end_labels(y.shape[2])
    else:
        y = y.reshape(rows, n, -1)
        labels = ("",) if y.shape[2] == 1 else tuple(str(j) for j in range(y.shape[2]))
    return ChainSeries(name, y, "link" if name in LINK_SERIES else "pin", units.get(name, ""), labels, state)


def quantities(series: dict, n: int) -> list[str]:
    """Names :func:`chain_series` accepts for a results file with ``n`` pins."""
    names = [k for k, y in series.items() if (k.startswith("chain.") or k.startswith("contact."))
             and k != "chain.coordinates" and np.ndim(y) == 2 and np.shape(y)[1] % n == 0 and np.shape(y)[1] >= n]
    return names + (list(FRICTION_PARTS) if "contact.friction_force" in series else [])


def _end_labels(m: int) -> tuple[str, ...]:
    return ("",) if m == 1 else tuple(f"end {j}" for j in range(m))


@dataclass(frozen=True)
class Curve:
    """A field against the loop position on a uniform grid: ``s`` (g,), ``y`` (g, m) smoothed, ``raw`` the samples
    before resampling (``s_raw`` (k,), ``y_raw`` (k, m)), and the shaft each sample's pin touched (``shaft_raw``)."""

    s: np.ndarray
    y: np.ndarray
    s_raw: np.ndarray
    y_raw: np.ndarray
    shaft_raw: np.ndarray


def distribution(cs: ChainSeries, s_pin, s_link, row: int, pitches: float, n_grid: int = 720) -> Curve:
    """Every element of ``cs`` at output row ``row`` against its loop position, moving average over ``pitches``
    link pitches (0: none); the loop is periodic."""
    s = (s_link if cs.kind == "link" else s_pin)[row]
    order = np.argsort(s)
    s_raw, y_raw = s[order], cs.values[row][order]
    grid = (np.arange(n_grid) + 0.5) / n_grid
    y = np.column_stack([np.interp(grid, s_raw, y_raw[:, j], period=1.0) for j in range(y_raw.shape[1])])
    width = pitches * n_grid / cs.values.shape[1]
    if width >= 1:
        y = uniform_filter1d(y, int(round(width)), axis=0, mode="wrap")
    return Curve(grid, y, s_raw, y_raw, cs.shaft_of[row][order])


def revolution(cs: ChainSeries, s_pin, s_link, element: int, rows: slice, pitches: float,
               n_grid: int = 720) -> Curve:
    """Element ``element`` of ``cs`` followed over the output rows ``rows`` against its unwrapped loop position
    (starting in [0, 1)); moving average over ``pitches`` link pitches; the grid covers the positions reached."""
    n = cs.values.shape[1]
    if not 0 <= element < n:
        raise InputError("element", element, f"must be a {cs.kind} index 0..{n - 1}")
    s = np.unwrap((s_link if cs.kind == "link" else s_pin)[rows, element], period=1.0)
    if s.size < 2 or not np.all(np.diff(s) > 0):
        raise InputError("rows", "the followed rows", "must have the element moving forward along the chain at "
                         "every output step (the output step must be shorter than half a revolution)")
    s = s - np.floor(s[0])
    y_raw = cs.values[rows, element]
    k = max(2, int(np.ceil((s[-1] - s[0]) * n_grid)))
    grid = np.linspace(s[0], s[-1], k)
    y = np.column_stack([np.interp(grid, s, y_raw[:, j]) for j in range(y_raw.shape[1])])
    width = pitches * n_grid / n
    if width >= 1:
        y = uniform_filter1d(y, int(round(width)), axis=0, mode="nearest")
    return Curve(grid, y, s, y_raw, cs.shaft_of[rows, element])


def write_curves_csv(curves: dict[str, Curve], labels: dict[str, tuple[str, ...]], path: str | Path) -> Path:
    """The smoothed curves as CSV: per quantity a column ``s[<name>]`` (its own loop-position grid) and its values
    ``<name>[<component>]``; a shorter curve is padded with empty cells."""
    cols, head = [], []
    for name, c in curves.items():
        cols.append(c.s)
        head.append(f"s[{name}]")
        for j, lab in enumerate(labels[name]):
            cols.append(c.y[:, j])
            head.append(name + (f"[{lab}]" if lab else ""))
    table = np.full((max(len(c) for c in cols), len(cols)), np.nan)
    for j, c in enumerate(cols):
        table[:len(c), j] = c
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(out, table, delimiter=",", header=",".join(head), comments="")
    return out


def plot_curves(curves: dict[str, Curve], series: dict[str, ChainSeries], path: str | Path, title: str,
                show_raw: bool = True) -> Path:
    """One panel per quantity against the loop position, the pulley arcs shaded (driving blue, driven orange)
    where the sampled pins touched them."""
    from cvtfem.post.figures import pyplot, save

    plt = pyplot()
    fig, axes = plt.subplots(len(curves), 1, figsize=(8, 2.4 * len(curves) + 0.8), sharex=True, squeeze=False)
    for ax, (name, c) in zip(axes[:, 0], curves.items()):
        cs = series[name]
        for k, colour in ((0, "tab:blue"), (1, "tab:orange")):
            _shade(ax, c.s_raw, c.shaft_raw == k, colour)
        for j, lab in enumerate(cs.components):
            line, = ax.plot(c.s, c.y[:, j], label=lab or None)
            if show_raw:
                ax.plot(c.s_raw, c.y_raw[:, j], ".", ms=2, color=line.get_color(), alpha=0.4)
        ax.set_ylabel(f"{name.split('.', 1)[1]}, {cs.unit}" if cs.unit else name.split('.', 1)[1], fontsize=8)
        ax.grid(alpha=0.3)
        if any(cs.components):
            ax.legend(fontsize=7, loc="best")
    axes[-1, 0].set_xlabel("loop position from mid tight span (driving arc shaded blue, driven arc orange)")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save(fig, path)


def _shade(ax, s, mask, colour: str) -> None:
    """Shade the runs of ``mask`` over the sorted positions ``s``."""
    if not mask.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        ax.axvspan(s[a], s[b - 1], color=colour, alpha=0.12, lw=0)

