"""Chains on elastic shafts against rigid shafts: cost of one RHS and one Jacobian, and a short run.

    OPENBLAS_NUM_THREADS=1 nice .venv/bin/python studies/elastic/chain_elastic.py [--until 2e-3] [--calls 200]
        [--scenes chain-S2,regime-chapter2:chain-A1,regime-chapter2,shafts-elastic]

Scenes (``--scenes``, separated by colons; default ``chain-S2,regime-chapter2`` with and without the part
``shafts-elastic``: ElasticChainCVT, beam FE shafts, rigid sheaves, linear bearings).  For each: the states, the RHS median of ``--calls`` calls and the Jacobian
median of ``--jac-calls`` calls at the quasi-static start perturbed to a running state; then a Radau run (the
scene's tolerances) over ``--until`` s: wall time per simulated ms, simulated ms per wall minute, RHS calls and
Jacobians, and at the end the sheave tilts, the bearing forces and the support force.  The machine and its load
are printed before and after.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.integrate import solve
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene


def running_state(m, x0, seed=0):
    """The start with random position offsets (1 um) and velocities (0.05 m/s) of all second-order coordinates."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    n2 = m.n2
    x[:n2] += rng.normal(0.0, 1e-6, n2)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    return x


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--until", type=float, default=2e-3)
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--jac-calls", type=int, default=10)
    ap.add_argument("--scenes", default="chain-S2,regime-chapter2:chain-S2,regime-chapter2,shafts-elastic")
    a = ap.parse_args()
    print(f"machine: {machine()}")
    for name in a.scenes.split(":"):
        scene = load_scene(name)
        m = chain_loop(scene)
        x0, info = m.start()
        x = running_state(m, x0)
        t_rhs = median_us(lambda: m.rhs(0.0, x), a.calls, warm_up=True)
        t_jac = median_us(lambda: m.jac(0.0, x), a.jac_calls, warm_up=True)
        print(f"\n{name}: {m.n2} coordinates, {m.size} states; one RHS {t_rhs:.0f} us (median of {a.calls}), "
              f"one Jacobian {t_jac / 1e3:.1f} ms (median of {a.jac_calls}); start: {info['kind']}")
        sv = scene.solver
        t0 = time.perf_counter()
        res = solve(m, (0.0, a.until), x0, method="Radau", rtol=sv.rtol, atol=sv.atol, n2=m.n2, jac=m.jac,
                    jac_sparsity=m.jac_sparsity)
        wall = time.perf_counter() - t0
        ms = 1e3 * a.until
        print(f"  run {ms:g} ms: status {res.status}, wall {wall:.1f} s = {wall / ms:.1f} s per simulated ms = "
              f"{60 * ms / wall:.2f} ms per wall minute; {res.stats['nfev']} RHS, {res.stats['njev']} Jacobians, "
              f"{res.stats['nsteps']} steps")
        o = m.outputs(res.t[-1], res.y[:, -1])
        print(f"  end: ratio {o['ratio']:.4f}, efficiency {o['efficiency']:.4f}, "
              f"support force driving {np.round(o['driving.support_force'], 1)} N, "
              f"driven {np.round(o['driven.support_force'], 1)} N")
        for shaft in ("driving", "driven"):
            if f"{shaft}.sheave_tilt" in o:
                tilt = 1e3 * o[f"{shaft}.sheave_tilt"].reshape(2, 2)
                b = o[f"{shaft}.bearing_force"].reshape(2, 3)
                print(f"  {shaft}: sheave tilt (mrad) fixed {np.round(tilt[0], 4)}, movable {np.round(tilt[1], 4)}; "
                      f"bearing forces (N) {np.round(b[0], 1)}, {np.round(b[1], 1)}")
    print(f"\nmachine after: {machine()}")


if __name__ == "__main__":
    main()
