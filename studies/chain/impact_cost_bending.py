"""The cost of impact at contact onset on the bending-pin chains S3 and A1: each chain with ``effects.contact =
"impact"`` against the same chain with H1 alone, both from their quasi-static start at the presets' operating point
(3500 rpm, 200 N m, ratio 2.4), with the preset's method (S3 on the chain-S2 preset: rock4; A1: Radau) at rtol
``RTOL``.

Per chain, ``T`` seconds simulated, ``RUNS`` runs of each model, the H1 and impact runs alternating (a change of the
machine's load hits both): the median wall time per simulated ms, RHS calls, steps, Jacobians and LU factorisations,
events, and one indicator evaluation against one RHS (median of 200 calls at the start state); also the impact loss
and its share of the input work.  Usage: ``python studies/chain/impact_cost_bending.py [T] [RUNS] [RTOL] [S3,A1]``.
"""
from __future__ import annotations

import sys

import numpy as np

from cvtfem.analysis.timing import machine, median_us, wall_times
from cvtfem.integrate import solve
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene

CHAINS = {"S3": ("chain-S2", {"cvt": {"model": "chain-S3", "effects": {"pin_bending": True}}}),
          "A1": ("chain-A1", {})}


def pair(name: str, rtol: float):
    """``(H1 scene, impact scene)`` of chain ``name`` (``S3`` or ``A1``)."""
    preset, over = CHAINS[name]
    base = load_scene(preset).replace(over).replace({"solver": {"rtol": rtol, "atol": rtol * 1e-3}})
    return base, base.replace({"cvt": {"effects": {"contact": "impact"}}})


def main(T: float = 5e-4, runs: int = 3, rtol: float = 1e-3, chains: str = "S3,A1") -> None:
    print(machine())
    print(f"{T * 1e3:g} ms from the quasi-static start, rtol {rtol:g}, median of {runs} runs, H1 and impact runs "
          "alternating (so that a change of the machine's load hits both)")
    for name in chains.split(","):
        cases = []
        for label, scene in zip((f"{name} + H1", f"{name} + impact"), pair(name, rtol)):
            model = chain_loop(scene)
            cases.append((label, scene.solver, model, model.start()[0], [], {}))
        for _ in range(runs):
            for label, sol, model, x0, walls, result in cases:
                def run():
                    result["res"] = solve(model, (0.0, T), x0, method=sol.method, rtol=sol.rtol, atol=sol.atol,
                                          n2=model.n2, jac=model.jac, jac_sparsity=model.jac_sparsity)
                walls.append(wall_times(run, 1)[0])
                assert result["res"].status == 0, result["res"].message
        for label, sol, model, x0, walls, result in cases:
            res = result["res"]
            st = res.stats
            rhs_us = median_us(lambda: model.rhs(0.0, x0), 200, warm_up=True)
            line = (f"{label:12s} {sol.method:6s} wall {np.median(walls) / (T * 1e3):7.2f} s per ms "
                    f"(runs {', '.join(f'{w:.1f}' for w in walls)} s), {st['nfev']} RHS, {st['nsteps']} steps, "
                    f"{st['njev']} Jacobians, {st['nlu']} LU; RHS {rhs_us:.0f} us")
            if hasattr(model, "discrete_state"):
                end = res.y[:, -1]
                events = sum(len(t) for t in res.t_events)
                loss = model.discrete_state(end)[1]
                W = model.split(end)[3]
                ev_us = median_us(lambda: model.events(0.0, x0), 200, warm_up=True)
                line += (f", indicators {ev_us:.0f} us; {events} events, impact loss {loss * 1e3:.3f} mJ = "
                         f"{loss / W[0]:.1e} of the input work")
            print(line, flush=True)


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:2]), *(int(a) for a in sys.argv[2:3]), *(float(a) for a in sys.argv[3:4]),
         *sys.argv[4:5])
