"""Median cost of one right-hand side and one Jacobian of the 84-pin chains on two rigid sheaves (S2, S3, A1).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_chain_sheaves.py [--calls 1000] [--jac-calls 20]

Each model (reference chain, band-6+2n scene values, clamping 30/35 kN) at its quasi-static state at ratio
2.4 perturbed to a running state (random pin offsets and velocities): ``rhs`` median of ``--calls`` calls,
``jac`` (sparse, analytic blocks plus the contacts' local differences) median of ``--jac-calls``; the
machine and its load are printed.
"""
from __future__ import annotations

import argparse

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

F_APPL = np.array([30000.0, 35000.0])


def running_state(m, x0, seed=0):
    """The quasi-static state with random pin offsets (2 um) and velocities (0.05 m/s)."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = m.family.size, m.n2
    x[:nc] += rng.normal(0.0, 2e-6, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    return x


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    ap.add_argument("--models", default="chain-S2,chain-S3,chain-A1")
    a = ap.parse_args()
    scene = load_scene("band-6+2n")
    print(f"machine: {machine()}")
    for model in a.models.split(","):
        m = from_scene(scene, reference_geometry(), F_APPL, model=model)
        x = running_state(m, m.static_state(2.4, scene.cvt.regime.input_speed)[0])
        t_rhs = median_us(lambda: m.rhs(0.0, x), a.calls, warm_up=True)
        t_jac = median_us(lambda: m.jac(0.0, x), a.jac_calls, warm_up=True)
        print(f"{model}: {m.size} states, {m.jac_sparsity.nnz} Jacobian pattern entries; one RHS {t_rhs:.0f} us "
              f"(median of {a.calls}), one Jacobian {t_jac / 1e3:.1f} ms (median of {a.jac_calls}) = "
              f"{t_jac / t_rhs:.0f} RHS")
    print(f"machine after: {machine()}")


if __name__ == "__main__":
    main()
