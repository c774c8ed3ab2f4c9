"""Variants (e) and (zh) on elastic shafts against rigid shafts: cost of one RHS and one Jacobian.

    OPENBLAS_NUM_THREADS=1 nice .venv/bin/python studies/elastic/bench_variant_e_elastic.py [--calls 200]
        [--jac-calls 5] [--scenes variant-e,regime-stationary:variant-zh,regime-stationary]

For each scene (``--scenes``, separated by colons) the A5 transmission on the scene's elastic shafts
(:mod:`cvtfem.machines.chain_halves_elastic_cvt`) and on rigid shafts (its ``rigid()``), both at the rigid placement
(the randomised chain's start: its rigid quasi-static solve does not converge) made a running state (chain offsets
0.2 um, velocities 0.05 m/s, sheave tilts 0.2 mrad on the elastic shafts): the number of candidate contacts, the
median wall time of ``--calls`` RHS calls and of ``--jac-calls`` Jacobians (CPU time alongside), alternating between
two states so that no cached block is reused.  The machine and its load are printed before and after.  The cost per
simulated millisecond comes from `cvtfem run` (docs/transmission.md, "Variants (e) and (zh) on elastic shafts").
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from cvtfem.analysis.timing import machine, wall_times
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene


def running(model, x0, seed: int, tilt: float):
    """``x0`` with random chain offsets (0.2 um), velocities (0.05 m/s) and, on elastic shafts, sheave tilts."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    s = getattr(model, "structure", None)
    if s is not None:
        tilts = nc + s.sheave_dofs[:, :, 3:5].ravel()
        x[tilts] += rng.normal(0.0, tilt, tilts.size)
    return x


def timed(label: str, model, states, calls: int, jac_calls: int) -> tuple[float, float]:
    """Print and return the RHS and Jacobian medians (us) alternating between ``states``."""
    k = iter(range(10 ** 9))

    def rhs():
        return model.rhs(0.0, states[next(k) % 2])

    def jac():
        return model.jac(0.0, states[next(k) % 2])
    c0 = time.process_time()
    t_rhs = wall_times(rhs, calls, warm_up=True)
    cpu_rhs = (time.process_time() - c0) / (calls + 1)
    c0 = time.process_time()
    t_jac = wall_times(jac, jac_calls, warm_up=True)
    cpu_jac = (time.process_time() - c0) / (jac_calls + 1)
    q, v = states[0][:model.n2], states[0][model.n2:2 * model.n2]
    contacts = len(model._candidates(q)[0])
    rhs_us, jac_us = 1e6 * float(np.median(t_rhs)), 1e6 * float(np.median(t_jac))
    print(f"  {label}: {model.n2} coordinates, {contacts} candidate (end, shaft) pairs; one RHS {rhs_us:.0f} us "
          f"(median of {calls}; CPU {1e6 * cpu_rhs:.0f} us), one Jacobian {jac_us / 1e3:.1f} ms (median of "
          f"{jac_calls}; CPU {1e3 * cpu_jac:.1f} ms) = {jac_us / rhs_us:.0f} RHS")
    return rhs_us, jac_us


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--jac-calls", type=int, default=5)
    ap.add_argument("--scenes", default="variant-e,regime-stationary:variant-zh,regime-stationary")
    a = ap.parse_args()
    print(f"machine: {machine()}")
    for name in a.scenes.split(":"):
        model = chain_loop(load_scene(name))
        rigid = model.rigid()
        w1, _, i = model.regime.targets(0.0)
        elastic, x0 = model.placed(i, w1)
        x0r = rigid.placed_state(i, w1)
        print(f"\n{name} ({type(model).__name__}):")
        timed("elastic shafts", elastic, [running(elastic, x0, s, 2e-4) for s in (1, 2)], a.calls, a.jac_calls)
        timed("rigid shafts  ", rigid, [running(rigid, x0r, s, 0.0) for s in (1, 2)], a.calls, a.jac_calls)
    print(f"\nmachine after: {machine()}")


if __name__ == "__main__":
    main()
