"""CPU per operation of strang-friction with all friction implicit (``friction=all``, frozen-mid, RK4, h = 2e-6 s) over
[0, 0.4] ms of variant (e) from the w-short cache's start: RHS, ``f_E``, the two slip maps, the friction solve and its
LUs (docs/accuracy-cost.md, sessions 12 and 13), and the run's CPU split by part (process time summed over the run's
calls).  Medians of many calls, process time.
    .venv/bin/python studies/accuracy-cost/imex_all_costs.py [CACHE] [SCHEME]
"""
import sys
import time
import warnings

import numpy as np

import cvtfem.elements.chain.implicit_friction as IF
from cvtfem.analysis.accuracy_cost import StudyCache
from cvtfem.integrate import solve
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene
from imex_costs import median_cpu           # this directory: python puts a script's own on the path

SCENE = "studies/accuracy-cost/scenes/variant-e-rigid-chapter2-linear-saturated.toml"


def main(cache="out/studies/w-short-cache", scheme="frozen-mid"):
    warnings.simplefilter("ignore")
    loop = closed_loop(load_scene(SCENE))
    x0 = StudyCache.existing(cache).start()[0]
    lus, cpu = [], []
    step = IF.friction_step

    def timed_step(*a, **k):
        t = time.process_time()
        out = step(*a, **k)
        cpu.append(time.process_time() - t)
        lus.append(out[2])
        return out

    IF.friction_step = timed_step
    import cvtfem.machines.chain_halves_cvt as CH
    CH.friction_step = timed_step
    parts = {}

    def timed(name, f):
        def g(*a, **k):
            t0 = time.process_time()
            out = f(*a, **k)
            parts[name] = parts.get(name, 0.0) + time.process_time() - t0
            return out
        return g

    for name in ("friction_sets", "rhs_explicit_all", "rhs", "friction_hold"):
        setattr(loop, name, timed(name, getattr(loop, name)))
    t = time.process_time()
    res = solve(loop, (0.0, 4e-4), x0, method="strang-friction", h=2e-6, adaptive=False, scheme=scheme,
                explicit="rk4", friction="all", t_eval=[4e-4])
    total = time.process_time() - t
    x = res.y[:, -1]
    for name in ("friction_sets", "rhs_explicit_all", "rhs", "friction_hold"):
        delattr(loop, name)
    rhs = median_cpu(lambda: loop.rhs(0, x))
    rhs_e = median_cpu(lambda: loop.rhs_explicit_all(0, x))
    nc = loop.family.size
    halves = median_cpu(lambda: loop.family.chain.friction_slips(x[:nc]), 50)
    sheave = median_cpu(lambda: loop.sheave_slips(x))
    sets = median_cpu(lambda: loop.friction_sets(x), 50)
    G, N = loop.sheave_slips(x)
    B = loop.family.chain.friction_slips(x[:nc])[0]
    print(f"{scheme}: total {total:.2f} s CPU, nfev {res.stats['nfev']}, steps {res.stats['nsteps']}, "
          f"friction solves {len(lus)}, LUs {sum(lus)}")
    print(f"rhs {1e3 * rhs:.3f} ms, rhs_explicit_all {1e3 * rhs_e:.3f} ms ({rhs_e / rhs:.2f} RHS-eq)")
    print(f"slip maps: halves (compiled values) {1e3 * halves:.2f} ms = {halves / rhs:.2f} RHS-eq ({B.shape[0]} "
          f"slips); pin-sheave (compiled, 2 rows a contact) {1e3 * sheave:.3f} ms = {sheave / rhs:.2f} RHS-eq "
          f"({len(N)} contacts); both with the sets {1e3 * sets:.2f} ms = {sets / rhs:.2f} RHS-eq")
    c = np.median(cpu)
    print(f"friction solve: median {1e3 * c:.2f} ms = {c / rhs:.1f} RHS-eq, {np.mean(lus):.2f} LUs each "
          f"(median {np.median(lus):.0f}, max {max(lus)}); per LU {1e3 * sum(cpu) / sum(lus):.2f} ms = "
          f"{sum(cpu) / sum(lus) / rhs:.2f} RHS-eq")
    parts["friction_step"] = sum(cpu)
    parts["other (the scheme's vector work, samples)"] = total - sum(parts.values())
    print("the run's CPU by part: " + ", ".join(f"{k} {v:.2f} s" for k, v in parts.items()))


if __name__ == "__main__":
    main(*sys.argv[1:])
