"""Which friction sets the stiff eigenvalues of A5 (variants (e), (zh)) at its start state (spec numerics-and-periodic
section 9.2's attribution): the Jacobian spectrum with the scene's friction, with the pin-sheave saturation speed
`cvt.friction.v0` / 10, and with the halves' internal friction speed (half-half rolling slip and half-pack axial
slip, `HALF_PARAMETERS["friction_speed"]`, not a scene key) / 10.  Run from the repository root:

    .venv/bin/python studies/accuracy-cost/a5_friction_spectra.py SCENE OUT.png

Prints the extremes of each spectrum and the eigenvalues that move by about 10; draws the three spectra on the
signed-log plane.  The start state is the chain placed on the sheaves (`placed_state`: the quasi-static solve stalls
at the chapter-2 regime).  `HALF_PARAMETERS` is changed in this process only, before the variant is built.
"""
from __future__ import annotations

import sys

import numpy as np

import cvtfem.machines.chain_halves_cvt as halves
from cvtfem.analysis.accuracy_cost import jacobian_spectrum
from cvtfem.blas import single_thread_blas
from cvtfem.machines.cvt import closed_loop
from cvtfem.post.accuracy_cost import plot_spectra
from cvtfem.scene.loader import load_scene


def spectra(scene) -> dict:
    """``label -> eigenvalues`` (1/s) at the placed start state: as given, pin-sheave v0 / 10, halves' v0 / 10."""
    loop = closed_loop(scene)
    w1, _, ratio = loop.regime.targets(0.0)
    x0 = loop.placed_state(ratio, w1)
    v0 = scene.cvt.friction.v0
    v0_half = halves.HALF_PARAMETERS["friction_speed"]
    out = {f"as given (pin-sheave v0 {v0:g}, halves {v0_half:g} m/s)": jacobian_spectrum(loop, x0)}
    slow = closed_loop(scene.replace({"cvt": {"friction": {"v0": v0 / 10}}}))
    out[f"pin-sheave v0 / 10 = {v0 / 10:g} m/s"] = jacobian_spectrum(slow, x0)
    halves.HALF_PARAMETERS["friction_speed"] = v0_half / 10
    try:
        out[f"halves' friction speed / 10 = {v0_half / 10:g} m/s"] = jacobian_spectrum(closed_loop(scene), x0)
    finally:
        halves.HALF_PARAMETERS["friction_speed"] = v0_half
    return out


def main(scene_name: str, png: str) -> None:
    with single_thread_blas():
        lam = spectra(load_scene(scene_name))
    base = next(iter(lam.values()))
    for label, x in lam.items():
        print(f"{label}: min Re {x.real.min():.4g}, max Re {x.real.max():.4g}, max |Im| {np.abs(x.imag).max():.4g} 1/s;"
              f" five most negative real parts {np.sort(x.real)[:5].round(-3).tolist()}")
        moved = np.sum(x.real < 5 * base.real.min())
        print(f"  eigenvalues below 5 x the first spectrum's min Re: {moved}")
    plot_spectra(lam, png, f"{scene_name}: Jacobian eigenvalues at the placed start state, friction speeds / 10")
    print(f"wrote {png}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
