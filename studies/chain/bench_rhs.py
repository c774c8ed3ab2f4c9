"""Benchmark: one force evaluation (and one Jacobian) of the free 84-pin chain, models S1, S2, S3.

Run:  .venv/bin/python studies/chain/bench_rhs.py [--calls 1000]
Prints, per model, the median wall time of ``calls`` single calls of ``forces(q, qd)`` (elastic plus
dissipative, reference chain with randomised pitch, damping on), of ``solve_mass`` on the result,
and of ``jacobian(q, qd)`` (median of 20), with the machine and its load.  No sheave contact yet.
"""
from __future__ import annotations

import argparse

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry, ring_positions
from cvtfem.elements.chain.symmetric import ChainS1, ChainS2, ChainS3, damping_from_ratio


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    args = ap.parse_args()
    geom = reference_geometry(randomised=True)
    damping = damping_from_ratio(geom, 0.05, b_joint=0.01)
    x, _ = ring_positions(geom.L)
    rng = np.random.default_rng(0)
    print(f"machine: {machine()}")
    print(f"{'model':<9} {'coords':>6} {'forces us':>10} {'+M^-1 us':>9} {'jacobian ms':>12} {'= forces':>9}")
    for Family in (ChainS1, ChainS2, ChainS3):
        fam = Family(geom, damping)
        n = fam.n
        q = fam.join(x + 1e-5 * rng.standard_normal((n, 2)), np.full(n, geom.l / 2), 1e-3 * rng.standard_normal((n, 2)))
        qd = rng.standard_normal(fam.size)
        t_f = median_us(lambda: fam.forces(q, qd), args.calls)
        t_a = median_us(lambda: fam.solve_mass(fam.forces(q, qd)), args.calls)
        t_j = median_us(lambda: fam.jacobian(q, qd), 20)
        print(f"{fam.kind:<9} {fam.size:>6} {t_f:>10.1f} {t_a:>9.1f} {t_j / 1e3:>12.2f} {t_j / t_f:>9.0f}")


if __name__ == "__main__":
    main()
