"""Median cost of one right-hand side and one Jacobian of the 84-pin A5 chain (independent pin halves) on two rigid
sheaves with H1 contact at all 336 half ends, and of the chain family's own passes.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_chain_halves.py [--calls 1000] [--jac-calls 20]
    # -> out/studies/chain/bench_chain_halves.txt

The reference chain (band-6+2n scene values, clamping 30/35 kN) placed on the sheaves at ratio 2.4
(:meth:`ChainHalvesCVT.placed_state`: halves rolling on each other, sheaves at the wedge estimate) with random
coordinate offsets (0.2 um) and velocities (0.05 m/s): ``rhs`` (forces and dissipated power in one compiled pass,
the contacts, the loops), the family's compiled ``forces``, its element-by-element Jacobian (central and forward
link differences) and the model's ``jac``, each as a wall median and in RHS-equivalents (wall and mean CPU time:
on a loaded machine long calls are preempted more often than short ones).  Machine and load before and after.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

F_APPL = np.array([30000.0, 35000.0])
OUT = Path("out/studies/chain")


def cpu_us(fun, calls: int) -> float:
    """Mean process CPU time of ``fun`` (us)."""
    t0 = time.process_time()
    for _ in range(calls):
        fun()
    return (time.process_time() - t0) / calls * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    a = ap.parse_args()
    scene = load_scene("band-6+2n")
    lines = [f"machine: {machine()}"]
    m = from_scene(scene, reference_geometry(), F_APPL, model="chain-A5")
    rng = np.random.default_rng(0)
    x = m.placed_state(2.4, scene.cvt.regime.input_speed)
    nc, n2 = m.family.size, m.n2
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    q, v = x[:nc], x[n2:n2 + nc]
    ch = m.family.chain
    ends = m._candidates(x[:n2])[0]
    lines.append(f"chain-A5 on the sheaves: {m.size} states ({nc} chain coordinates), {len(ends)} candidate "
                 f"half-end contacts, Jacobian pattern {m.jac_sparsity.nnz} entries")
    m.jac(0.0, x)                                                  # compile and cache
    runs = (("model rhs (chain pass + contacts + loops)", lambda: m.rhs(0.0, x), a.calls),
            ("family forces and dissipated power", lambda: ch.forces_and_dissipation(q, v), a.calls),
            ("family jacobian, central link differences", lambda: ch.jacobian(q, v), a.jac_calls),
            ("family jacobian, forward link differences", lambda: ch.jacobian(q, v, scheme="forward"), a.jac_calls),
            ("model jac (family, contacts, loops, work rows)", lambda: m.jac(0.0, x), max(a.jac_calls // 4, 3)))
    t, c = {}, {}
    for name, fun, calls in runs:
        t[name] = median_us(fun, calls, warm_up=True)
        c[name] = cpu_us(fun, min(calls, 200))
        lines.append(f"{name:<50} median of {calls:4d}: {t[name]:10.1f} us (mean CPU {c[name]:9.1f} us)")
    rhs = runs[0][0]
    lines.append("Jacobians in RHS-equivalents of the model rhs (wall medians; mean CPU times):")
    for name, _, _ in runs[2:]:
        lines.append(f"  {name:<50} {t[name] / t[rhs]:7.1f} (CPU {c[name] / c[rhs]:6.1f})")
    lines.append(f"issue 13 targets: RHS < 300 us, Jacobian < 40 RHS; machine after: {machine()}")
    print("\n".join(lines))
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_chain_halves.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
