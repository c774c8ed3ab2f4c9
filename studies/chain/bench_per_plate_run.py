"""Cost of the per-plate chains A3 and A4 running on two rigid shafts, against A1 (issue 13; variants (g), (d)).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_per_plate_run.py [--calls 1000] [--jac-calls 20]
        [--contacts hertz,hertz-refined]

Reference chain (84 pins, 12 plates per link: 1,008 plates), band-6+2n scene values, clamping 30/35 kN, ratio 2.4.
A1's quasi-static state, then A3's from it and A4's from A3's (the stages of A4's start; their times and evaluations
are printed), perturbed to a running state (random pin offsets 2 um and velocities 0.05 m/s, as
``bench_variant_a.py``; A4's plates then sit in several states, printed).  For each model and contact: one ``rhs``
(median of ``--calls``) and one ``jac`` (median of ``--jac-calls``); the machine and its load are printed before
and after.  (Simulated time per wall time: the ``cvtfem run`` summaries, docs/chain.md.)
"""
from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

F_APPL = np.array([30000.0, 35000.0])
MODELS = ("chain-A1", "chain-A3", "chain-A4")


def running_state(m, x0, seed=0):
    """The quasi-static state with random pin offsets (2 um) and velocities (0.05 m/s)."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = m.family.size, m.n2
    x[:nc] += rng.normal(0.0, 2e-6, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    return x


def balances(scene, contact: str) -> dict:
    """``{model: (transmission, x0)}``: A1 balanced from the placement, A3 from A1's balance, A4 from A3's."""
    out, x = {}, None
    for name in MODELS:
        m = from_scene(scene, reference_geometry(), F_APPL, model=name, contact=contact)
        if x is not None:
            m = replace(m, start_chain=x[:m.family.size], start_z=x[m._idx[2]])
        t0 = time.perf_counter()
        x, rep = m.static_state(2.4, scene.cvt.regime.input_speed)
        print(f"  {name} start: residual {rep['residual']:.1e} of F2 in {rep['nfev']} evaluations, "
              f"{time.perf_counter() - t0:.1f} s wall; mean tension {rep['tension']:.2f} N, F1 {rep['F1']:.1f} N")
        out[name] = (m, x)
    return out


def bench_calls(contacts, calls: int, jac_calls: int) -> None:
    scene = load_scene("band-6+2n")
    for contact in contacts:
        print(f"contact {contact}:")
        for name, (m, x0) in balances(scene, contact).items():
            x = running_state(m, x0)
            t_rhs = median_us(lambda: m.rhs(0.0, x), calls, warm_up=True)
            t_jac = median_us(lambda: m.jac(0.0, x), jac_calls, warm_up=True)
            states = ""
            if name == "chain-A4":
                k, n = np.unique(m.outputs(0.0, x)["chain.plate_state"], return_counts=True)
                states = "; plate states " + ", ".join(f"{int(a)}: {b}" for a, b in zip(k, n))
            print(f"  {name}: one RHS {t_rhs:.0f} us (median of {calls}), one Jacobian {t_jac / 1e3:.1f} ms "
                  f"(median of {jac_calls}) = {t_jac / t_rhs:.0f} RHS{states}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=1000)
    ap.add_argument("--jac-calls", type=int, default=20)
    ap.add_argument("--contacts", default="hertz,hertz-refined")
    a = ap.parse_args()
    print(f"machine: {machine()}")
    bench_calls(a.contacts.split(","), a.calls, a.jac_calls)
    print(f"machine after: {machine()}")


if __name__ == "__main__":
    main()
