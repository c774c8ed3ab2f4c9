"""Median time of one force evaluation of the A1 chain family (84 pins, 12 plates per link).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_rhs_a1.py   # -> out/studies/chain/bench_rhs_a1.txt

Prints the machine and its load with the medians of 1,000 calls of ``elastic_forces``, ``forces``
(elastic + all damping) and ``accel`` (forces + per-pin mass solve) at a perturbed ring state, for
the compiled kernel (numba) and its numpy twin, and of 100 calls of the analytic ``stiffness_matrix``
and ``damping_matrix`` (sparse, numpy).
"""
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.asymmetric import ChainA1

OUT = Path("out/studies/chain")
N_PINS, N_PLATES, PITCH, PIN_L = 84, 12, 0.009, 0.03


def build(use_numba: bool) -> ChainA1:
    """84 pins, 12 plates per link on a weave of period 3 (assumed values of the right orders of magnitude)."""
    base = np.linspace(-0.92, 0.92, N_PLATES)
    xi = np.stack([base + 0.04 * (p % 3 - 1) for p in range(N_PINS)]).clip(-1, 1)
    return ChainA1(pitch=np.full(N_PINS, PITCH), plate_xi=xi, n_plates=np.full(N_PINS, N_PLATES),
                   plate_stiffness=4e6, plate_bending_stiffness=0.05, plate_torsion_stiffness=1.0,
                   pin_length=PIN_L, pin_mass=np.full(N_PINS, 0.012), pin_axial_stiffness=4e8,
                   pin_bending_tau=60.0, pin_bending_n=40.0, beta_link_ext=1e-6, beta_link_tors=1e-6,
                   beta_link_shear=1e-6, beta_bend=1e-7, pin_axial_damping=5.0, joint_damping=1e-4,
                   use_numba=use_numba)


def main() -> None:
    ch = build(True)
    rng = np.random.default_rng(0)
    ang = 2 * np.pi * np.arange(N_PINS) / N_PINS
    R = PITCH / (2 * np.sin(np.pi / N_PINS))
    q = ch.rest_state(R * np.column_stack([np.cos(ang), np.sin(ang)])) + 1e-6 * rng.standard_normal(ch.n2)
    v = 0.1 * rng.standard_normal(ch.n2)
    lines = [f"machine: {machine()}", f"A1 chain: {N_PINS} pins x 10 = {ch.n2} coordinates, {N_PLATES} plates/link"]
    for c in (ch, build(False)):
        for name, fun in (("elastic_forces", lambda: c.elastic_forces(q)), ("forces (with damping)", lambda: c.forces(q, v)),
                          ("accel", lambda: c.accel(q, v))):
            fun()
            lines.append(f"{c.backend:<6} {name:<24} median of 1000: {median_us(fun):8.1f} us")
    for name, fun in (("stiffness_matrix", lambda: ch.stiffness_matrix(q)), ("damping_matrix", lambda: ch.damping_matrix(q))):
        lines.append(f"numpy  {name:<24} median of 100:  {median_us(fun, 100):8.1f} us")
    lines.append(f"machine after: {machine()}")
    print("\n".join(lines))
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_rhs_a1.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
