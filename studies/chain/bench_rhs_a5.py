"""Median cost of one force evaluation and one Jacobian of the A5 chain family (independent pin halves; 84 pins,
12 plates per link), and an estimate of the RHS with 2 x 84 x 2 refined (H2) sheave contacts.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_rhs_a5.py   # -> out/studies/chain/bench_rhs_a5.txt

The reference chain of :func:`cvtfem.elements.chain.geometry.reference_geometry` with halves (contact and
stopper parameters assumed, as in docs/chain.md) on a perturbed ring, friction and all damping on.  Prints
the machine and its load, the medians of ``forces`` (elastic, damping, friction) compiled
(``halves_kernel``) and numpy (the twin), of ``accel`` (plus the mass solve), of the element-by-element
``jacobian`` (forward and central link differences) and of the coloured central differences of the
compiled forces (504 evaluations, the previous method), each Jacobian also in force evaluations.  Then the
RHS estimate with contacts: compiled ``accel`` + the compiled H2 kernel on 336 contacts (the contact set of
``bench_contact``) + gathering the contact points and scattering the loads (A1's compiled kernels on 336
points, as a proxy: A5 has no compiled half-end gather/scatter yet).
"""
import time
from pathlib import Path

import numpy as np
from bench_contact import C, F0, H2_KEYS, MERIDIAN, N_PINS, PIN_L, V0, contact_set, join

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.a_loads_kernel import axis_points_kernel, point_loads_kernel
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.halves import ChainA5, ring_state
from cvtfem.elements.contact.kernels import LAW_CODES, h2_kernel

OUT = Path("out/studies/chain")
H_PIN = 1.2e-3
CALLS = 1000


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


def h2_contact_work(rng) -> tuple:
    """Closures timing the H2 kernel on 336 contacts and the A1 gather/scatter kernels on 336 points."""
    ang = 2 * np.pi * np.arange(N_PINS) / N_PINS
    s = join(contact_set(0.060 * np.column_stack([np.cos(ang), np.sin(ang)]), 0.060, rng),
             contact_set(0.040 * np.column_stack([np.cos(ang), np.sin(ang)]), 0.040, rng))
    m = s["R_pin"].shape[0]
    h2 = [s[k] for k in H2_KEYS]
    c, law = np.full(m, C), LAW_CODES["smooth"]
    out = [np.empty((m, 3)) if k == 3 else np.empty(m) for k in (3, 3, 1, 1, 1, 3, 3, 3, 1, 3, 3, 1)]  # h2_kernel's
    pins = np.tile(np.arange(N_PINS), 4)
    xi = np.tile(np.r_[-np.ones(N_PINS), np.ones(N_PINS)], 2)
    q1 = rng.standard_normal(10 * N_PINS) * 1e-3
    pts, Q = np.empty((m, 3)), np.zeros(10 * N_PINS)
    force, moment = rng.normal(size=(m, 3)), rng.normal(size=(m, 2))
    return m, (lambda: h2_kernel(*h2, c, MERIDIAN.params, F0, V0, law, 0.2, *out),
               lambda: axis_points_kernel(q1, N_PINS, PIN_L, pins, xi, pts),
               lambda: point_loads_kernel(N_PINS, PIN_L, pins, xi, force, moment, Q))


def cpu_us(fun, calls: int) -> float:
    """Mean process CPU time of ``fun`` (us): on a loaded machine wall medians of short calls miss the preemption
    that long calls (a Jacobian) cannot; CPU time compares the two fairly."""
    t0 = time.process_time()
    for _ in range(calls):
        fun()
    return (time.process_time() - t0) / calls * 1e6


def main() -> None:
    ch, ref = build(True), build(False)
    rng = np.random.default_rng(0)
    q = ring_state(ch, stretch=2e-6, overlap=1e-6) + 1e-7 * rng.standard_normal(ch.n2)
    v = 0.01 * rng.standard_normal(ch.n2)
    lines = [f"machine: {machine()}",
             f"A5 chain: {ch.n_pins} pins x 21 = {ch.n2} coordinates, {ch.kmax} plates/link, plate model "
             f"{ch.plate_model}, friction and all damping on"]
    ch.jacobian(q, v)                                          # compile and cache before timing
    runs = (("numba  forces", lambda: ch.forces(q, v), CALLS),
            ("numba  accel (forces + mass solve)", lambda: ch.accel(q, v), CALLS),
            ("numpy  forces (reference twin)", lambda: ref.forces(q, v), 200),
            ("numba  jacobian, central link differences", lambda: ch.jacobian(q, v), 200),
            ("numba  jacobian, forward link differences", lambda: ch.jacobian(q, v, scheme="forward"), 200),
            ("numba  coloured_jacobian (504 force calls)", lambda: ch.coloured_jacobian(q, v), 5))
    t = {}
    for name, fun, calls in runs:
        t[name] = median_us(fun, calls)
        lines.append(f"{name:<44} median of {calls:4d}: {t[name]:10.1f} us")
    rhs, rhs_cpu = t["numba  forces"], cpu_us(runs[0][1], CALLS)
    lines.append("Jacobians (dQ/dq and dQ/dv) in compiled force evaluations (wall medians; mean CPU times):")
    for name, fun, calls in runs[3:]:
        lines.append(f"  {name:<44} {t[name] / rhs:7.1f} (CPU: {cpu_us(fun, min(calls, 20)) / rhs_cpu:6.1f})")
    m, (h2, gather, scatter) = h2_contact_work(rng)
    for name, fun in ((f"H2 contact kernel ({m}, preallocated)", h2), (f"gather {m} points (A1 kernel)", gather),
                      (f"scatter {m} loads (A1 kernel)", scatter)):
        t[name] = median_us(fun, CALLS)
        lines.append(f"{name:<44} median of {CALLS:4d}: {t[name]:10.1f} us")
    est = t["numba  accel (forces + mass solve)"] + sum(t[k] for k in t if k.startswith(("H2", "gather", "scatter")))
    lines.append(f"RHS estimate, A5 accel + {m} H2 contacts + gather/scatter: {est:.1f} us "
                 f"(issue 13 target < 300 us; source C++ ~760 us)")
    lines.append(f"machine after: {machine()}")
    print("\n".join(lines))
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_rhs_a5.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
