"""Order-spectrum levels of the support forces of regime-A runs (docs/transmission.md, "f_link / 3 with the resolved
plates and the pin halves" and "Session 16: regime A on variant (e) and the randomised (b)").

For each results file: the four support-force components (driving and driven, x1 and x2) from ``--start`` on,
resampled in chain revolutions (:func:`cvtfem.post.spectrogram.order_spectrum`); the level at order 84 (``f_link``),
28 (``f_link / 3``, the lacing's plates repeating every three links) and 56 (2/3 ``f_link``) over the median level of
orders 10-100, as the range over the four components; and how far the whole orders 1-83 stand above the half orders
between them (median and share above 3 dB over the four components: the randomised chain's bands at ``k f_chain``).

    .venv/bin/python studies/chain/regime-a/order_levels.py RESULTS.h5 [...] [--start 0.01]
"""
from __future__ import annotations

import argparse

import numpy as np

from cvtfem.commands.spectrogram import chain_of
from cvtfem.io.results import read_results
from cvtfem.post import spectrogram as sg

COMPONENTS = (("driving.support_force", "0"), ("driving.support_force", "1"), ("driven.support_force", "0"),
              ("driven.support_force", "1"))
ORDERS = (84, 28, 56)


def levels(path: str, start: float) -> tuple[dict[int, list[float]], np.ndarray, float]:
    """Per order of :data:`ORDERS` its level over the median of orders 10-100 (dB) on each component; the whole
    orders' contrast over the half orders (dB, components x 83); the chain revolutions analysed."""
    res = read_results(path)
    freqs = sg.chain_frequencies(res, *chain_of(res))
    at: dict[int, list[float]] = {k: [] for k in ORDERS}
    contrast = []
    for series, component in COMPONENTS:
        t, y, _ = sg.select_signal(res, series, component, start)
        spectrum = sg.order_spectrum(t, y, freqs)
        db = spectrum.db()
        floor = np.median(db[(spectrum.order > 10) & (spectrum.order < 100)])
        for k in ORDERS:
            at[k].append(float(np.interp(k, spectrum.order, db) - floor))
        contrast.append(spectrum.band_contrast(np.arange(1, freqs.n_pins)))
    return at, np.array(contrast), spectrum.revolutions


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("results", nargs="+")
    parser.add_argument("--start", type=float, default=0.01, help="analyse from this time on, s (default 0.01)")
    args = parser.parse_args()
    print(f"levels over the median of orders 10-100, range over {len(COMPONENTS)} components, from {args.start:g} s")
    for path in args.results:
        at, contrast, revolutions = levels(path, args.start)
        cells = "  ".join(f"order {k}: {min(v):+.1f}..{max(v):+.1f} dB" for k, v in at.items())
        print(f"{path}: {revolutions:.2f} revolutions  {cells}  whole orders 1-83 over the half orders: median "
              f"{np.median(contrast):+.1f} dB, {np.mean(contrast > 3) * 100:.0f} % above 3 dB")


if __name__ == "__main__":
    main()
