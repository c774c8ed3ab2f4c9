"""Median cost of one right-hand side and one Jacobian of the 84-pin chain on two rigid sheaves: A5 (independent pin
halves, 336 half ends) with H1 (``chain-A5``, variant (zh)) and with H2 (``chain-A5+H2``, variant (e) on rigid
shafts), and A1 and S2 with H1 to check that they are not slowed (issue 13 benchmark).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_chain_halves.py [--calls 1000] [--jac-calls 20]
        [--models chain-A5 chain-A5+H2 chain-A1 chain-S2] [--out out/studies/chain/bench_chain_halves.txt]

The reference chain (band-6+2n scene values, clamping 30/35 kN) placed on the sheaves at ratio 2.4 (A5:
:meth:`ChainHalvesCVT.placed_state`, halves rolling on each other; A1, S2: the wedge estimate's placement) with
random coordinate offsets (0.2 um) and velocities (0.05 m/s).  Per model: ``rhs`` (chain pass, contacts, loops) and
``jac`` (all blocks: the Jacobian is asked alternately at two states 1e-12 m apart, so no cached block is reused);
for A5 also the family's compiled pass, the contact pass (``_contact_forces``: broad phase, gather, kernel, scatter)
and the family's element-by-element Jacobian (its default, exact link blocks, and central link differences).  Wall
medians (:mod:`cvtfem.analysis.timing`) and medians of process CPU time over batches (on a loaded machine CPU time
is the steadier figure), the Jacobians in RHS-equivalents of both; the machine and its load (1, 5, 15 min) before
and after.  The script runs on older trees too (``PYTHONPATH``), for before/after tables.
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


def cpu_us(fun, calls: int, batches: int = 7) -> float:
    """Median over ``batches`` batches of the mean process CPU time per call of ``fun`` (us), ``calls`` calls in all."""
    per = max(calls // batches, 1)
    times = []
    for _ in range(batches):
        t0 = time.process_time()
        for _ in range(per):
            fun()
        times.append((time.process_time() - t0) / per * 1e6)
    return float(np.median(times))


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
    model, _, contact = name.partition("+")
    m = from_scene(scene, reference_geometry(), F_APPL, model=model,
                   contact="hertz-refined" if contact == "H2" else "hertz")
    x = running_state(m, scene.cvt.regime.input_speed)
    nc, n2 = m.family.size, m.n2
    ends = m._candidates(x[:n2])[0]
    lines = [f"{name} on the sheaves ({type(m).__name__}): {m.size} states ({nc} chain coordinates), {len(ends)} "
             f"candidate end contacts, Jacobian pattern {m.jac_sparsity.nnz} entries"]
    m.jac(0.0, x)                                                  # compile and cache
    runs = [("model rhs (chain pass + contacts + loops)", lambda: m.rhs(0.0, x), a.calls),
            ("model jac (family, contacts, loops, work rows)", alternating(lambda y: m.jac(0.0, y), x), a.jac_calls)]
    if model == "chain-A5":
        ch = m.family.chain
        q, v = x[:nc], x[n2:n2 + nc]
        Q = np.zeros(n2)
        runs[1:1] = [("family forces and dissipated power", lambda: ch.forces_and_dissipation(q, v), a.calls),
                     ("contact pass (forces and friction power)",
                      lambda: m._contact_forces(x[:n2], x[n2:2 * n2], Q), a.calls),
                     ("family jacobian, default (exact link blocks*)",
                      alternating(lambda y: ch.jacobian(y[:nc], v), x), a.jac_calls),
                     ("family jacobian, central link differences",
                      alternating(lambda y: ch.jacobian(y[:nc], v, scheme="central"), x), a.jac_calls)]
    t, c = {}, {}
    for label, fun, calls in runs:
        t[label] = median_us(fun, calls, warm_up=True)
        c[label] = cpu_us(fun, min(calls, 280) if calls > 100 else calls)
        lines.append(f"  {label:<50} median of {calls:4d}: {t[label]:10.1f} us (CPU median {c[label]:9.1f} us)")
    rhs = runs[0][0]
    lines.append("  Jacobians in RHS-equivalents of the model rhs (wall medians; CPU medians):")
    for label, _, _ in runs:
        if "jac" in label:
            lines.append(f"    {label:<50} {t[label] / t[rhs]:7.1f} (CPU {c[label] / c[rhs]:6.1f})")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    ap.add_argument("--models", nargs="+", default=["chain-A5", "chain-A5+H2", "chain-A1", "chain-S2"])
    ap.add_argument("--out", type=Path, default=Path("out/studies/chain/bench_chain_halves.txt"))
    a = ap.parse_args()
    scene = load_scene("band-6+2n")
    lines = [f"machine: {machine()}; {load()}"]
    print(lines[0], flush=True)
    for name in a.models:
        block = bench_model(name, scene, a)
        print("\n".join(block), flush=True)
        lines += block
    lines.append("* trees before session 8: central link differences")
    lines.append(f"issue 13 targets (A5 with H1 and with H2): RHS < 300 us, Jacobian < 40 RHS; after: {load()}")
    print(lines[-1])
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
