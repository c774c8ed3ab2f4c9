"""Span tensions, sheave axial force balance and ratio of a chain-on-sheaves results file (``cvtfem run``).

    .venv/bin/python studies/chain/plot_chain_run.py RESULTS.h5 [--png out/studies/chain/variant_a_run.png]
        [--band 7418,2016]

Three panels over the run: the mean tight and slack span link tension (``chain.span_tension``, with the band
model's settled values as dashed lines if ``--band`` gives them), the sum of the pins' axial forces on each
movable sheave over its clamping force minus 1 (and the fixed sheaves' for the whole-pin chains), and the
speed ratio.
"""
from __future__ import annotations

import argparse
import os

import h5py
import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--png", default="out/studies/chain/variant_a_run.png")
    ap.add_argument("--band", default="7418,2016", help="band span tensions tight,slack (N); '' for none")
    a = ap.parse_args()
    with h5py.File(a.results) as f:
        s = f["series"]
        t = 1e3 * s["time"][:]
        T = s["chain.span_tension"][:]
        F = np.column_stack([s["driving.clamping_force"][:], s["driven.clamping_force"][:]])
        mov = s["contact.sheave_axial_force"][:] / F - 1
        fix = s["contact.fixed_sheave_axial_force"][:] / F - 1 if "contact.fixed_sheave_axial_force" in s else None
        ratio = s["ratio"][:]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    band = [float(v) for v in a.band.split(",")] if a.band else []
    for k, name in enumerate(("tight", "slack")):
        ax[0].plot(t, T[:, k], c=f"C{k}", lw=0.8, label=f"chain, {name} span")
        if band:
            ax[0].axhline(band[k], c=f"C{k}", ls="--", label=f"band 6+2n settled, {name}")
    ax[0].set_ylabel("mean span link tension, N")
    for k, name in enumerate(("driving", "driven")):
        ax[1].plot(t, 100 * mov[:, k], c=f"C{k}", lw=0.8, label=f"{name}, movable sheave")
        if fix is not None:
            ax[1].plot(t, 100 * fix[:, k], c=f"C{k}", ls=":", lw=0.8, label=f"{name}, fixed sheave")
    ax[1].set_ylabel("sum of pin axial forces /\nclamping force - 1, %")
    ax[2].plot(t, ratio, lw=0.8)
    ax[2].set_ylabel("speed ratio w1 / w2")
    ax[2].set_xlabel("t, ms")
    for x in ax[:2]:
        x.legend(fontsize=7)
    fig.suptitle(os.path.basename(a.results), fontsize=9)
    fig.tight_layout()
    os.makedirs(os.path.dirname(a.png) or ".", exist_ok=True)
    fig.savefig(a.png, dpi=90)
    print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
