"""Impact at contact onset on the running chain: losses per revolution, events per ms, and the cost against S2 with H1
alone and S1 with rigid contact (no impacts), at the chain presets' operating point (3500 rpm, 200 N m, ratio 2.4).

Each model runs ``T`` seconds from its quasi-static start with the preset's method and tolerance (rock4 rtol 1e-3 for
S2, Radau rtol 1e-3 for S1; and S1 with rock4), ``RUNS`` times; printed: median wall time, RHS calls, steps, events and impacts, the
impact loss per revolution of the driving shaft (over the second half of the run, past the start transient) and its
share of the input work there.  Usage: ``python studies/chain/impact_cost.py [T] [RUNS]``.
"""
from __future__ import annotations

import sys
import time

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.integrate import solve
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene


def run(scene, T: float):
    model = chain_loop(scene)
    x0 = model.start()[0]
    sol = scene.solver
    t0 = time.perf_counter()
    res = solve(model, (0.0, T), x0, method=sol.method, rtol=sol.rtol, atol=sol.atol, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity, t_eval=np.array([T / 2, T]))
    wall = time.perf_counter() - t0
    assert res.status == 0, res.message
    return model, x0, res, wall


def main(T: float = 4e-3, runs: int = 3) -> None:
    print(machine())
    base = load_scene("chain-S2")
    cases = {"S2 + impact (C2 then H1)": base.replace({"cvt": {"effects": {"contact": "impact"}}}),
             "S2 + H1 (no impact)": base, "S1 rigid (no impact)": load_scene("chain-S1"),
             "S1 rigid, rock4": load_scene("chain-S1").replace({"solver": {"method": "rock4"}})}
    for name, scene in cases.items():
        walls = []
        for _ in range(runs):
            model, x0, res, wall = run(scene, T)
            walls.append(wall)
        line = (f"{name:26s} {T * 1e3:.1f} ms: wall {np.median(walls):6.2f} s (median of {runs}), "
                f"{res.stats['nfev']} RHS, {res.stats['nsteps']} steps")
        if hasattr(model, "discrete_state"):
            half, end = res.y[:, 0], res.y[:, 1]
            events = sum(len(t) for t in res.t_events)
            impacts = sum(1 for k, ys in enumerate(res.y_events) for y in ys
                          if (lambda m: m[0] @ m[1])(model.impact_map(y, k // 2, k % 2)[:2]) < 0)
            loss = model.discrete_state(end)[1] - model.discrete_state(half)[1]
            W = model.split(end)[3] - model.split(half)[3]
            revs = float(np.mean([model.split(y)[1][model._idx[1][0]] for y in (half, end)])) * (T / 2) / (2 * np.pi)
            line += (f", {events} events ({events / (T * 1e3):.1f} per ms), {impacts} impacts; second half: impact "
                     f"loss {loss / revs * 1e3:.3f} mJ per revolution = {loss / W[0]:.2e} of the input work "
                     f"(friction + damping {(W[2] - loss) / W[0]:.2e})")
        print(line, flush=True)


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:2]), *(int(a) for a in sys.argv[2:3]))
