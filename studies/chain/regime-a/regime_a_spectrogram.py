"""Support-force spectrograms of chain S2 on rigid shafts in regime A (4000 rpm, 150 N m, ratio 0.45, shortened),
uniform and randomised chain: issue 14's plausibility check (docs/transmission.md, post-processing).

Run:  .venv/bin/python studies/chain/regime-a/regime_a_spectrogram.py [--until 0.15] [--out out/studies/regime-a]
      [--uniform RESULTS.h5] [--random RESULTS.h5] [--start 0.01] [--window 0.0125]

1. Each scene (``chain-S2-A-uniform.toml``, ``chain-S2-A-random.toml`` next to this script) runs ``--until``
   seconds unless its results file is given.
2. ``cvtfem spectrogram`` on the driving shaft's x1 reaction from ``--start`` on: spectrogram with the lines
   k f_chain, k/3 f_link; intensity over f / f_chain; order spectrum (PNG + CSV each).
3. Printed: f_chain and f_link, the strongest line near f_link against ``v / l_link``, the levels at f_link / 3
   and f_link over the median level of 0.5-5 kHz, and how far the whole orders 1..83 stand above the half orders
   in the order spectrum (the randomised chain's bands at k f_chain).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cvtfem.analysis.run import run_scene
from cvtfem.analysis.timing import machine
from cvtfem.cli import main as cli
from cvtfem.commands.spectrogram import chain_of
from cvtfem.io.results import read_results
from cvtfem.post import spectrogram as sg
from cvtfem.scene.loader import load_scene

HERE = Path(__file__).resolve().parent


def figures(path: Path, out: Path, name: str, start: float, window: float) -> None:
    """The spectrogram command's PNGs and CSVs of the driving x1 reaction of ``path``, named ``name-*``."""
    argv = ["spectrogram", str(path), "--series", "driving.support_force", "--component", "0", "--start",
            str(start), "--window", str(window), "--fmax", "5000"]
    for flag, suffix in (("--png", ".png"), ("--csv", ".csv"), ("--intensity-png", "-intensity.png"),
                         ("--intensity-csv", "-intensity.csv"), ("--order-png", "-order.png"),
                         ("--order-csv", "-order.csv")):
        argv += [flag, str(out / f"{name}{suffix}")]
    assert cli(argv) == 0


def levels(path: Path, start: float, window: float) -> dict[str, float]:
    """Line positions and levels of the driving x1 reaction (see the module docstring)."""
    res = read_results(path)
    freqs = sg.chain_frequencies(res, *chain_of(res))
    t, y, _ = sg.select_signal(res, "driving.support_force", "0", start)
    spec = sg.compute_spectrogram(t, y, window, fmax=5000.0)
    mean = spec.psd.mean(axis=1)
    band = (spec.f > 500) & (spec.f < 5000)
    floor = np.median(mean[band])
    f_link = float(np.mean(freqs.f_link[res.time >= start]))
    near = np.abs(spec.f - f_link) < 0.1 * f_link
    peak = float(spec.f[near][np.argmax(mean[near])])
    orders = sg.order_spectrum(t, y, freqs)
    contrast = orders.band_contrast(np.arange(1, freqs.n_pins))
    return {"f_chain": f_link / freqs.n_pins, "f_link": f_link, "peak": peak, "df": spec.df,
            "f_link/3 dB": float(10 * np.log10(np.interp(f_link / 3, spec.f, mean) / floor)),
            "f_link dB": float(10 * np.log10(mean[near].max() / floor)),
            "revolutions": orders.revolutions, "contrast": float(contrast.mean()),
            "contrast median": float(np.median(contrast)),
            "order peak": float(orders.order[np.argmax(orders.psd[1:]) + 1])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--until", type=float, default=0.15)
    ap.add_argument("--out", default="out/studies/regime-a")
    ap.add_argument("--uniform", default=None)
    ap.add_argument("--random", default=None)
    ap.add_argument("--start", type=float, default=0.01)
    ap.add_argument("--window", type=float, default=0.0125)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(machine())
    for name in ("uniform", "random"):
        path = getattr(args, name)
        if path is None:
            path = out / f"{name}.h5"
            summary = run_scene(load_scene(HERE / f"chain-S2-A-{name}.toml"), until=args.until, results=path,
                                overwrite=True, show_progress=False)
            print(f"{name}: {summary}")
        figures(Path(path), out, name, args.start, args.window)
        got = levels(Path(path), args.start, args.window)
        print(f"{name}: f_chain {got['f_chain']:.5g} Hz, f_link {got['f_link']:.5g} Hz; strongest line near f_link "
              f"{got['peak']:.5g} Hz ({got['peak'] / got['f_link'] - 1:+.2%}, bin {got['df']:.3g} Hz); over the median "
              f"level of 0.5-5 kHz: f_link {got['f_link dB']:+.1f} dB, f_link/3 {got['f_link/3 dB']:+.1f} dB; order "
              f"spectrum over {got['revolutions']:.3g} revolutions: whole orders {got['contrast']:+.2f} dB (median "
              f"{got['contrast median']:+.2f} dB) above the half orders, peak at order {got['order peak']:.4g}")


if __name__ == "__main__":
    main()
