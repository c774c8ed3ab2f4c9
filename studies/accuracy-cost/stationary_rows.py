"""Methods on variant (e) at the stationary regime (3500 rpm, 200 N m, ratio 2.4; the settled state of a stored run):
from the newest checkpoint of a results file, ``SPAN`` s of each method against DUMKA3 adaptive at rtol 1e-3, judged on
all 168 pin halves' axial forces (E = largest error over the largest force, 100 samples), the energy balance of the
span (residual over the input work) and the CPU time (process time of the solve alone, one core).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/accuracy-cost/stationary_rows.py RESULTS.h5 [--span 1e-3]
    # RESULTS.h5: a run of studies/chain/variant-e-stationary-inclined.toml (a copy: the file is only read)

The reference is kept beside the file (``RESULTS.h5.reference-<t>-<span>.npy``).  docs/accuracy-cost.md, sessions 18-19.
"""
from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from cvtfem.analysis.accuracy_cost import chain_output, energy_balance
from cvtfem.analysis.timing import machine
from cvtfem.integrate import solve
from cvtfem.io.results import read_checkpoint, read_first_row, read_scene_toml
from cvtfem.machines.chain_cvt_elastic import FACE_REFERENCE, with_face_reference
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import _parse, scene_from_dict

HALVES = "chain.pin_half_axial_force"
MULTIRATE = dict(method="strang-friction", adaptive=False, scheme="multirate-rk4", friction="all")
ROWS = [("DUMKA3 adaptive rtol 3e-2 (the preset to session 18)", dict(method="dumka3", rtol=3e-2, atol=3e-5)),
        ("multirate-rk4, 2e-6 s", dict(MULTIRATE, h=2e-6)),
        ("multirate-rk4, 1.5e-6 s", dict(MULTIRATE, h=1.5e-6)),
        ("multirate-rk4, 1e-6 s", dict(MULTIRATE, h=1e-6)),
        ("multirate-rk4 adaptive rtol 3e-3, steps <= 1.5e-6 s (the preset since session 19)",
         dict(MULTIRATE, adaptive=True, max_step=1.5e-6, rtol=3e-3, atol=3e-6)),
        ("multirate-rk4 adaptive rtol 1e-2, steps <= 1.5e-6 s",
         dict(MULTIRATE, adaptive=True, max_step=1.5e-6, rtol=1e-2, atol=1e-5))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--span", type=float, default=1e-3)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    path = args.results
    scene = scene_from_dict(_parse(read_scene_toml(path), path), source=path)
    loop = with_face_reference(chain_loop(scene), read_first_row(path, FACE_REFERENCE))
    ck = read_checkpoint(path)
    x, t = ck["x"], float(ck["t"][0])
    ts = t + np.linspace(0.0, args.span, 101)[1:]
    print(f"{machine()}\nvariant (e), stationary regime, from the checkpoint at t = {t:.4f} s over {args.span:g} s")
    loop.rhs(t, x)
    solve(loop, (t, t + 1e-8), x, split=loop.stiff_split, **dict(MULTIRATE, h=1e-8))   # compile, load the kernels
    ref_file = Path(f"{path}.reference-{t:.6f}-{args.span:g}.npy")
    if ref_file.exists():
        P = np.load(ref_file)
    else:
        P = chain_output(loop, solve(loop, (t, t + args.span), x, method="dumka3", rtol=1e-3, atol=1e-6,
                                     t_eval=ts).y, HALVES)
        np.save(ref_file, P)
    print("| method | E (all halves) | energy residual | CPU s per simulated ms | steps | RHS calls | inner stages |")
    print("|---|---|---|---|---|---|---|")
    for label, kw in ROWS:
        c0 = time.process_time()
        r = solve(loop, (t, t + args.span), x, t_eval=ts, split=loop.stiff_split, **kw)
        cpu = time.process_time() - c0
        E = np.abs(chain_output(loop, r.y, HALVES) - P).max() / np.abs(P).max()
        residual = energy_balance(loop, x, r.y[:, -1])["energy_residual"]
        print(f"| {label} | {E:.2e} | {residual:.1e} | {cpu / (args.span * 1e3):.2f} | {r.stats['nsteps']} | "
              f"{r.stats['nfev']} | {r.stats['nnewton']} |", flush=True)


if __name__ == "__main__":
    main()
