"""What test 2's output itself asks of a step: the error E of the cached reference rebuilt by a cubic spline
through its own samples every H seconds (an oracle method: exact at every step, cubic in between), for the
component the study judges (its E) and for the worst of all components (its error over the largest value of all).  Run from the repository root after the study has
filled its cache (`cvtfem study accuracy-cost ... --cache DIR --json STUDY.json`):

    .venv/bin/python studies/accuracy-cost/step_floor.py STUDY.json CACHE_DIR [H,...]

H (s, default 2e-6,5e-6,1e-5,2e-5,5e-5) must be whole multiples of the study's sample step.  Prints one line per H
and the fastest change of any component between two samples.
"""
from __future__ import annotations

import json
import sys

import numpy as np
from scipy.interpolate import CubicSpline

from cvtfem.analysis import accuracy_cost as ac


def spline_error(p: np.ndarray, dt: float, H: float) -> np.ndarray:
    """The largest error per component of ``p (samples, components)`` (sample step ``dt``) rebuilt from every
    ``H / dt``-th sample, in the units of ``p``."""
    k = round(H / dt)
    if k < 1 or abs(k * dt - H) > 1e-9 * H:
        raise SystemExit(f"step_floor: H = {H:g} s must be a whole multiple of the sample step {dt:g} s")
    t = np.arange(p.shape[0]) * dt
    grid = np.unique(np.r_[np.arange(0, p.shape[0], k), p.shape[0] - 1])
    rebuilt = CubicSpline(t[grid], p[grid], axis=0)(t)
    return np.abs(rebuilt - p).max(axis=0)


def main(study_json: str, cache_dir: str, steps: str = "2e-6,5e-6,1e-5,2e-5,5e-5") -> None:
    report = json.load(open(study_json, encoding="utf-8"))
    ref = report["reference"]
    t1, t2 = ref["window"]
    method, rtol = ref["reference"].split(" rtol ")
    p = np.load(f"{cache_dir}/reference-{method}-{float(rtol):g}.npy")
    dt = (t2 - t1) / (p.shape[0] - 1)
    k = ref["pin"]
    print(f"{report['scene']}: {p.shape[1]} components over [{t1:g}, {t2:g}] s every {dt:g} s; "
          f"judged: {ac.output_component(ref)}")
    scale = np.abs(p).max()
    for H in (float(h) for h in steps.split(",")):
        err = spline_error(p, dt, H)
        worst = int(np.argmax(err))
        print(f"H = {H:g} s: E judged {err[k] / np.abs(p[:, k]).max():.3g}; over the largest value of all: "
              f"worst component {err[worst] / scale:.3g} ({worst}), median {np.median(err) / scale:.3g}")
    jump = np.abs(np.diff(p, axis=0))
    i, c = np.unravel_index(np.argmax(jump), jump.shape)
    print(f"fastest change: {jump[i, c]:.4g} in {dt:g} s, {jump[i, c] / scale:.3g} of the largest value of all "
          f"(component {c}, t = {t1 + i * dt:.6g} s)")


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        raise SystemExit(__doc__)
    main(*sys.argv[1:])
