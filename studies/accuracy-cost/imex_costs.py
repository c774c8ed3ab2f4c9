"""CPU per operation of strang-friction (frozen-mid, DUMKA3, h = 2e-6 s) over [0, 0.4] ms of variant (e) from the
w-short cache's start: RHS, f_E, slip map, friction solve (docs/accuracy-cost.md, session 11).
    .venv/bin/python studies/accuracy-cost/imex_costs.py [CACHE]
"""
import sys
import time
import warnings

import numpy as np

from cvtfem.analysis.accuracy_cost import StudyCache
from cvtfem.integrate import solve
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

SCENE = "studies/accuracy-cost/scenes/variant-e-rigid-chapter2-linear-saturated.toml"


def timed(fn, acc):
    """``fn`` with its CPU time and calls added to ``acc = [seconds, calls, extra]`` (extra: LUs of a solve)."""
    def wrapped(*a, **k):
        t = time.process_time()
        out = fn(*a, **k)
        acc[0] += time.process_time() - t
        acc[1] += 1
        acc[2] += out[2] if isinstance(out, tuple) and len(out) == 3 and np.isscalar(out[2]) else 0
        return out
    return wrapped


def median_cpu(fn, k=300):
    ts = []
    for _ in range(k):
        t = time.process_time()
        fn()
        ts.append(time.process_time() - t)
    return float(np.median(ts))


def main(cache="out/studies/w-short-cache"):
    warnings.simplefilter("ignore")
    loop = closed_loop(load_scene(SCENE))
    x0 = StudyCache.existing(cache).start()[0]
    ch = loop.family.chain
    slips, steps = [0.0, 0, 0], [0.0, 0, 0]
    ch.friction_slips, ch.friction_step = timed(ch.friction_slips, slips), timed(ch.friction_step, steps)
    t = time.process_time()
    res = solve(loop, (0.0, 4e-4), x0, method="strang-friction", h=2e-6, adaptive=False, scheme="frozen-mid",
                t_eval=[4e-4])
    total = time.process_time() - t
    rhs, rhs_e = median_cpu(lambda: loop.rhs(0, x0)), median_cpu(lambda: loop.rhs_explicit(0, x0))
    print(f"total {total:.2f} s CPU, nfev {res.stats['nfev']}; rhs {1e3 * rhs:.3f} ms, rhs_explicit {1e3 * rhs_e:.3f} ms")
    s = slips[0] / slips[1]
    print(f"slip maps: {slips[1]}, {1e3 * s:.2f} ms each = {s / rhs:.1f} RHS-eq")
    f = steps[0] / steps[1]
    print(f"friction solves: {steps[1]}, {steps[2] / steps[1]:.1f} LUs each, {1e3 * f:.2f} ms each = {f / rhs:.1f} "
          f"RHS-eq; per LU {1e3 * steps[0] / steps[2]:.2f} ms")


if __name__ == "__main__":
    main(*sys.argv[1:])
