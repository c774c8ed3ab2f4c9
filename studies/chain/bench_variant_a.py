"""Cost of variant (a), the 84-pin A1 with the refined contact H2 at both pin ends, against A1 with H1.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_variant_a.py [--calls 1000] [--jac-calls 20]

Each contact (reference chain, band-6+2n scene values, clamping 30/35 kN) at its quasi-static state at ratio
2.4 perturbed to a running state (random pin offsets and velocities, as ``bench_chain_sheaves.py``): one
``rhs`` (median of ``--calls``), its contact pass alone, one ``jac`` (median of ``--jac-calls``).  The machine
and its load are printed.  (Simulated time per wall time: ``cvtfem run variant-a --until 1e-3``'s summary.)
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


def bench_calls(calls: int, jac_calls: int) -> None:
    scene = load_scene("band-6+2n")
    for contact in ("hertz", "hertz-refined"):
        m = from_scene(scene, reference_geometry(), F_APPL, model="chain-A1", contact=contact)
        x = running_state(m, m.static_state(2.4, scene.cvt.regime.input_speed)[0])
        q, v = x[:m.n2], x[m.n2:2 * m.n2]
        n_contacts = len(m._candidates(q)[0])
        t_rhs = median_us(lambda: m.rhs(0.0, x), calls, warm_up=True)
        t_pass = median_us(lambda: m._contact_set(q, v), calls, warm_up=True)
        t_jac = median_us(lambda: m.jac(0.0, x), jac_calls, warm_up=True)
        print(f"A1 + {contact}: {n_contacts} candidate contacts; one RHS {t_rhs:.0f} us (median of {calls}; the "
              f"contact pass with its map {t_pass:.0f} us), one Jacobian {t_jac / 1e3:.1f} ms (median of "
              f"{jac_calls}) = {t_jac / t_rhs:.0f} RHS")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    a = ap.parse_args()
    print(f"machine: {machine()}")
    bench_calls(a.calls, a.jac_calls)
    print(f"machine after: {machine()}")


if __name__ == "__main__":
    main()
