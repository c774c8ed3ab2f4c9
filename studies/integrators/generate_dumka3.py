"""Regenerate ``cvtfem/integrate/dumka3_data.npz`` (the 14 DUMKA3 polynomials, ~10 min).

    .venv/bin/python studies/integrators/generate_dumka3.py [OUT.npz]

Method: :mod:`cvtfem.integrate.dumka3_gen`. Prints per polynomial the real stability length
against the published DUMKA3 bound, the damping eta, the finishing coefficients and the
internal (rounding-error) amplification of the chosen sub-step order.
"""
import sys
from pathlib import Path

import numpy as np

from cvtfem.integrate import dumka3_gen as G


def report(k, d):
    print(f"P{k:<2d} s = {d['s']:3d}  length {d['length']:.8g} (published {G.PUBLISHED_BETA[k]:.8g},"
          f" {d['length'] / G.PUBLISHED_BETA[k] - 1:+.1e})  eta {d['eta']:.4f}"
          f"  finishing {np.array2string(d['finish'], precision=6)}"
          f"  internal amplification {d['amplification']:.3g}", flush=True)


if __name__ == "__main__":
    G.generate(Path(sys.argv[1]) if len(sys.argv) > 1 else G.DATA_FILE, report)
