"""Median cost of one right-hand side and one Jacobian of the 84-pin chain on two rigid sheaves with H1 contact: A5
(independent pin halves, 336 half ends), and A1 and S2 to check that they are not slowed (issue 13 benchmark).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_chain_halves.py [--calls 1000] [--jac-calls 20]
        [--models chain-A5 chain-A1 chain-S2] [--out out/studies/chain/bench_chain_halves.txt]

The reference chain (band-6+2n scene values, clamping 30/35 kN) placed on the sheaves at ratio 2.4 (A5:
:meth:`ChainHalvesCVT.placed_state`, halves rolling on each other; A1, S2: the wedge estimate's placement) with
random coordinate offsets (0.2 um) and velocities (0.05 m/s).  Per model: ``rhs`` (chain pass, contacts, loops) and
``jac`` (all blocks: the Jacobian is asked alternately at two states 1e-12 m apart, so no cached block is reused);
for A5 also the family's compiled pass and its element-by-element Jacobian (central and forward link
differences).  Wall medians (:mod:`cvtfem.analysis.timing`) and mean process CPU times, the Jacobians in
RHS-equivalents of both; the machine and its load (1, 5, 15 min) before and after.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

F_APPL = np.array([30000.0, 35000.0])
RATIO = 2.4


def cpu_us(fun, calls: int) -> float:
    """Mean process CPU time of ``fun`` (us)."""
    t0 = time.process_time()
    for _ in range(calls):
        fun()
    return (time.process_time() - t0) / calls * 1e6


def load() -> str:
    return "load average " + ", ".join(f"{a:.2f}" for a in os.getloadavg())


def running_state(m, w1: float) -> np.ndarray:
    """The chain placed on the sheaves at :data:`RATIO`, shafts turning, with random offsets and velocities."""
    if hasattr(m, "placed_state"):
        x = m.placed_state(RATIO, w1)
    else:
        pl, u3, z = m.wedge_guess(RATIO, float(m.F_appl[1]))
        nc, iphi, iz, _ = m._idx
        x = np.zeros(m.size)
        x[:nc], x[iz] = m._placed(pl, u3), z
        x[m.n2 + iphi] = w1 * pl.r[0] / pl.r
    rng = np.random.default_rng(0)
    nc, n2 = m.family.size, m.n2
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    return x


def alternating(fun, x):
    """``fun(x_k)`` on two states 1e-12 m apart in turn (defeats the caches of the last state's blocks)."""
    xs = [x, x.copy()]
    xs[1][0] += 1e-12
    k = [0]

    def call():
        k[0] ^= 1
        return fun(xs[k[0]])
    return call


def bench_model(name: str, scene, a) -> list[str]:
    m = from_scene(scene, reference_geometry(), F_APPL, model=name)
    x = running_state(m, scene.cvt.regime.input_speed)
    nc, n2 = m.family.size, m.n2
    ends = m._candidates(x[:n2])[0]
    lines = [f"{name} on the sheaves: {m.size} states ({nc} chain coordinates), {len(ends)} candidate end contacts, "
             f"Jacobian pattern {m.jac_sparsity.nnz} entries"]
    m.jac(0.0, x)                                                  # compile and cache
    runs = [("model rhs (chain pass + contacts + loops)", lambda: m.rhs(0.0, x), a.calls),
            ("model jac (family, contacts, loops, work rows)", alternating(lambda y: m.jac(0.0, y), x), a.jac_calls)]
    if name == "chain-A5":
        ch = m.family.chain
        q, v = x[:nc], x[n2:n2 + nc]
        runs[1:1] = [("family forces and dissipated power", lambda: ch.forces_and_dissipation(q, v), a.calls),
                     ("family jacobian, central link differences",
                      alternating(lambda y: ch.jacobian(y[:nc], v), x), a.jac_calls),
                     ("family jacobian, forward link differences",
                      alternating(lambda y: ch.jacobian(y[:nc], v, scheme="forward"), x), a.jac_calls)]
    t, c = {}, {}
    for label, fun, calls in runs:
        t[label] = median_us(fun, calls, warm_up=True)
        c[label] = cpu_us(fun, min(calls, 200))
        lines.append(f"  {label:<50} median of {calls:4d}: {t[label]:10.1f} us (mean CPU {c[label]:9.1f} us)")
    rhs = runs[0][0]
    lines.append("  Jacobians in RHS-equivalents of the model rhs (wall medians; mean CPU times):")
    for label, _, _ in runs:
        if "jac" in label:
            lines.append(f"    {label:<50} {t[label] / t[rhs]:7.1f} (CPU {c[label] / c[rhs]:6.1f})")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    ap.add_argument("--models", nargs="+", default=["chain-A5", "chain-A1", "chain-S2"])
    ap.add_argument("--out", type=Path, default=Path("out/studies/chain/bench_chain_halves.txt"))
    a = ap.parse_args()
    scene = load_scene("band-6+2n")
    lines = [f"machine: {machine()}; {load()}"]
    print(lines[0], flush=True)
    for name in a.models:
        block = bench_model(name, scene, a)
        print("\n".join(block), flush=True)
        lines += block
    lines.append(f"issue 13 targets (A5): RHS < 300 us, Jacobian < 40 RHS; after: {load()}")
    print(lines[-1])
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
