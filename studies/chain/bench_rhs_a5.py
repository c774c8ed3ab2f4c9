"""Median time of one force evaluation of the A5 chain family (independent pin halves; 84 pins, 12 plates per link).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_rhs_a5.py   # -> out/studies/chain/bench_rhs_a5.txt

The reference chain of :func:`cvtfem.elements.chain.geometry.reference_geometry` with halves (contact and
stopper parameters assumed, as in docs/chain.md) on a perturbed ring, friction and all damping on.  Prints
the machine and its load with the medians of 1,000 calls of ``forces`` (elastic, damping, friction) and
``accel`` (plus the mass solve) with the plate pass compiled (numba, ``plates_kernel``) and in numpy (the
twin; everything else is numpy in both), and of 3 calls of the coloured-difference ``jacobian`` (both
matrices, numba plate pass).
"""
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.halves import ChainA5, ring_state

OUT = Path("out/studies/chain")
H_PIN = 1.2e-3


def build(use_numba: bool) -> ChainA5:
    """The reference chain (84 pins, l = 33 mm, 12 plates/link, 1.4e9 N/m per link) split into halves."""
    g = reference_geometry()
    n = g.n
    return ChainA5(pitch=g.L + 2 * H_PIN, plate_offset=g.l / 2 * g.xi, n_plates=np.full(n, g.xi.shape[1]),
                   plate_stiffness=g.c_plate, plate_bending_stiffness=0.3, plate_thickness=1.5e-3,
                   plate_torsion_stiffness=1.0, plate_mass=g.m_plate.sum(1), pin_length=g.l, pin_mass=g.m_pin,
                   pin_axial_stiffness=float(g.c_pin[0]), half_bending_tau=g.A_tau / 2, half_bending_n=g.A_n / 2,
                   h_pin=H_PIN, roll_radius=(0.004, 0.004), roll_stiffness=1e11, roll_damping=1e3,
                   hole_radius=0.0031, back_radius=0.0024, back_extent=0.0025, hole_clearance=5e-4,
                   hole_stiffness=1e11, stopper_stiffness=1e6, stopper_play=5e-4, friction_coefficient=0.1,
                   friction_speed=1e-3, friction_law="smooth", half_axial_damping=2.0, beta_plate_ext=1e-6,
                   beta_plate_shear=1e-6, beta_twist=1e-6, beta_bend=1e-7, joint_damping=1e-4,
                   use_numba=use_numba)


def main() -> None:
    ch = build(True)
    rng = np.random.default_rng(0)
    q = ring_state(ch, stretch=2e-6, overlap=1e-6) + 1e-7 * rng.standard_normal(ch.n2)
    v = 0.01 * rng.standard_normal(ch.n2)
    lines = [f"machine: {machine()}",
             f"A5 chain: {ch.n_pins} pins x 21 = {ch.n2} coordinates, {ch.kmax} plates/link, plate model {ch.plate_model}"]
    rhs = None
    for c in (ch, build(False)):
        for name, fun in (("forces (damping, friction)", lambda: c.forces(q, v)), ("accel", lambda: c.accel(q, v))):
            fun()
            t = median_us(fun)
            rhs = t if rhs is None else rhs
            lines.append(f"{c.backend:<6} {name:<28} median of 1000: {t:9.1f} us")
    t = median_us(lambda: ch.jacobian(q, v), 3)
    lines.append(f"numba  {'jacobian (dQ/dq, dQ/dv)':<28} median of 3:    {t:9.1f} us = {t / rhs:.0f} force evaluations")
    lines.append(f"machine after: {machine()}")
    print("\n".join(lines))
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_rhs_a5.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
