"""Worked example of docs/response.md: pin-entry noise of the CVT sheave shaft, uniform against randomised chain.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/response/cvt_spectrum.py     # -> out/studies/response/

An 84-link chain at pitch radius 60 mm, 1 mN s per pin entry on each sheave at the entry angle 0: a uniform chain
(9 mm links) and a randomised one (42 links of 8 mm and 42 of 10 mm, seed 1; the same length, 756 mm), lines up to
2 f_link.  Prints the ERP of the sheave faces (dB and dB(A) re 1 pW) over speed for both, and the share of the
pin-entry force power at f_link and 2 f_link; writes the order map and the ERP plots.
"""
from pathlib import Path

import numpy as np

from cvtfem.analysis.spectrum import PinEntry, scene_spectrum
from cvtfem.modal.excitation import chain_pattern, pattern_spectrum
from cvtfem.post.response import plot_erp, plot_spectrum_map
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/response")
N, RADIUS, IMPULSE = 84, 0.06, 1e-3


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    scene = load_scene("cvt_sheave_shaft")
    speeds = np.linspace(0.0, 6000.0, 121) * np.pi / 30
    chains = {"uniform": np.full(N, 0.009), "randomised": chain_pattern(N, 0.008, 0.010, 0.5, 1)}
    res = {}
    for name, lengths in chains.items():
        k = np.arange(1, 2 * N + 1)
        power = np.abs(pattern_spectrum(lengths, k)) ** 2
        share = power[k % N == 0].sum() / power.sum()
        print(f"{name}: share of the pin-entry line power (k = 1 .. 2N) at f_link and 2 f_link: {share:.3f}")
        res[name] = scene_spectrum(scene, speeds, 4, orders=(RADIUS * 2 * np.pi / 0.009 / 3,),
                                   pin=PinEntry(lengths, RADIUS, IMPULSE, 0.0, 2), n_freqs=300, n_modes=12)
        plot_spectrum_map(res[name], OUT / f"spectrum_{name}_map.png", f"CVT sheave shaft, {name} chain")
        plot_erp(res[name], OUT / f"spectrum_{name}_erp.png", f"CVT sheave shaft, {name} chain: sheave-face ERP")
    rpm = speeds * 30 / np.pi
    print("| rpm | uniform ERP dB | uniform dB(A) | randomised ERP dB | randomised dB(A) |")
    print("|---|---|---|---|---|")
    for i in range(10, len(speeds), 20):
        u, r = res["uniform"], res["randomised"]
        print(f"| {rpm[i]:.0f} | {u.erp_db[i]:.1f} | {u.erp_a_db[i]:.1f} | {r.erp_db[i]:.1f} | {r.erp_a_db[i]:.1f} |")
    for name, r in res.items():
        lin = 10 ** (r.erp_a_db[1:] / 10)
        print(f"{name}: speed-averaged A-weighted ERP {10 * np.log10(lin.mean()):.1f} dB(A), "
              f"max {r.erp_a_db[1:].max():.1f} dB(A) at {rpm[1:][np.argmax(r.erp_a_db[1:])]:.0f} rpm")
    print(f"wrote {OUT}/spectrum_*_map.png, spectrum_*_erp.png")


if __name__ == "__main__":
    main()
