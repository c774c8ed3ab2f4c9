"""Median cost of one right-hand side and one Jacobian of variant (e) on rigid shafts (the 84-pin A5 chain with the
refined contact H2 at every half end), its contact pass's share, and the same for A5 with H1 (variant (zh)).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_variant_e.py [--calls 1000] [--jac-calls 20]
    # -> out/studies/chain/bench_variant_e.txt

The reference chain (band-6+2n scene values, clamping 30/35 kN) placed on the sheaves at ratio 2.4
(:meth:`ChainHalvesCVT.placed_state`) with random coordinate offsets (0.2 um) and velocities (0.05 m/s), for each
contact: the model's ``rhs``; its contact pass (broad phase, contact map, local kernel, scatter of the forces); the
local kernel alone (H2: :class:`HalfEndContact`, and inside it the refined kernel); the model's ``jac``, the
contacts' Jacobian entries as the model takes them (``_contact_jacobian``) and the numpy local Jacobian.  See
``bench_chain_halves.py`` for the before/after tables of issue 13.  Wall medians (``cvtfem.analysis.timing``) and
mean CPU times; Jacobians also in RHS-equivalents.  Machine and load before and after.
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


def contact_pass(m, q, v):
    """The contact part of one RHS as the model runs it (``_contact_forces``: broad phase, gather, local kernel,
    scatter; compiled for H1 and H2 since session 8, the numpy path before)."""
    Q = np.zeros(m.n2)
    m._contact_forces(q, v, Q)
    return Q


def bench(name: str, m, x, calls: int, jac_calls: int) -> list[str]:
    """Timing lines of one model at state ``x``."""
    n2 = m.n2
    q, v = x[:n2], x[n2:2 * n2]
    _, shafts, _, _, X, _ = m._contact_set(q, v)
    m.jac(0.0, x)                                                  # compile and cache
    runs = [("model rhs", lambda: m.rhs(0.0, x), calls),
            ("contact pass (broad phase, map, kernel, scatter)", lambda: contact_pass(m, q, v), calls),
            ("contact kernel (local)", lambda: m.contact.local(X, shafts), calls)]
    inner = getattr(m.contact.pair, "kernel_inputs", None)
    if inner is not None:
        Xk = inner(X)
        runs.append(("  of which the refined kernel", lambda: m.contact.pair.pair.local(Xk, shafts), calls))
    runs += [("contact local Jacobian (numpy)", lambda: m.contact.local_jacobian(X, shafts), jac_calls),
             ("contact Jacobian entries (model)", lambda: m._contact_jacobian(q, v), jac_calls),
             ("model jac", lambda: m.jac(0.0, x), max(jac_calls // 4, 3))]
    lines = [f"{name}: {m.size} states, {len(X)} candidate half-end contacts, Jacobian pattern "
             f"{m.jac_sparsity.nnz} entries"]
    t, c = {}, {}
    for label, fun, k in runs:
        t[label] = median_us(fun, k, warm_up=True)
        c[label] = cpu_us(fun, min(k, 200))
        lines.append(f"  {label:<50} median of {k:4d}: {t[label]:10.1f} us (mean CPU {c[label]:9.1f} us)")
    rhs, cp = "model rhs", runs[1][0]
    lines.append(f"  contact pass share of the rhs: {t[cp] / t[rhs]:.0%} (CPU {c[cp] / c[rhs]:.0%})")
    for label in ("contact local Jacobian (numpy)", "contact Jacobian entries (model)", "model jac"):
        lines.append(f"  {label:<50} {t[label] / t[rhs]:7.1f} RHS (CPU {c[label] / c[rhs]:6.1f})")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    a = ap.parse_args()
    scene = load_scene("band-6+2n")
    lines = [f"machine: {machine()}"]
    for contact, name in (("hertz-refined", "A5 + H2 (variant (e), rigid shafts)"),
                          ("hertz", "A5 + H1 (variant (zh))")):
        m = from_scene(scene, reference_geometry(), F_APPL, model="chain-A5", contact=contact)
        rng = np.random.default_rng(0)
        x = m.placed_state(2.4, scene.cvt.regime.input_speed)
        nc, n2 = m.family.size, m.n2
        x[:nc] += rng.normal(0.0, 2e-7, nc)
        x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
        block = bench(name, m, x, a.calls, a.jac_calls)
        print("\n".join(block), flush=True)
        lines += block
    lines.append(f"issue 13 targets (A5 + H2): RHS < 300 us, Jacobian < 40 RHS; machine after: {machine()}")
    print(lines[-1])
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_variant_e.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
