"""Median cost of the pin–sheave contact evaluations (H1, H2 with friction) and of an A-family RHS with contacts.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_contact.py   # -> out/studies/chain/bench_contact.txt

336 contacts: the 84 pins of the reference chain (pin length 33 mm), both ends, on the sheave pairs of two
shafts (toroidal faces, contact radii 60 and 40 mm; every pin end counted, as if the chain were wrapped on
both pulleys at once), crowned pin faces for H2, smooth friction law.  Prints medians of 1,000 calls of the
compiled kernels and of their numpy twins, then an RHS estimate of an 84-pin A1 chain (and of A4 with
per-plate plates) with its 336 contacts, split into its parts: chain forces, gathering the contact poses
from the state, the contact kernel, scattering the loads into generalized forces, the mass solve.
"""
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.a_loads_kernel import axis_points_kernel, point_loads_kernel
from cvtfem.elements.chain.asymmetric import ChainA1
from cvtfem.elements.chain.per_plate import ChainPerPlate
from cvtfem.elements.contact.kernels import LAW_CODES, h1_contacts, h1_kernel, h2_contacts, h2_kernel
from cvtfem.elements.contact.meridian import Meridian
from cvtfem.machines.chain import FreeChainA

OUT = Path("out/studies/chain")
N_PINS, N_PLATES, PITCH, PIN_L = 84, 12, 0.009, 0.033
MERIDIAN = Meridian("torus", R=0.6, y=0.05, f0=-0.6)
C, F0, V0 = 2.0e10, 0.1, 1e-3


def chain_args() -> dict:
    """84 pins, 12 plates per link on a weave of period 3 (values of bench_rhs_a1)."""
    base = np.linspace(-0.92, 0.92, N_PLATES)
    xi = np.stack([base + 0.04 * (p % 3 - 1) for p in range(N_PINS)]).clip(-1, 1)
    return dict(pitch=np.full(N_PINS, PITCH), plate_xi=xi, n_plates=np.full(N_PINS, N_PLATES),
                plate_stiffness=4e6, plate_bending_stiffness=0.05, plate_torsion_stiffness=1.0,
                pin_length=PIN_L, pin_mass=np.full(N_PINS, 0.012), pin_axial_stiffness=4e8,
                pin_bending_tau=60.0, pin_bending_n=40.0, beta_link_ext=1e-6, beta_link_tors=1e-6,
                beta_link_shear=1e-6, beta_bend=1e-7, pin_axial_damping=5.0, joint_damping=1e-4)


def contact_set(centres: np.ndarray, radius: float, rng) -> dict:
    """Far (side -1) and near (side +1) ends of 84 pins on one sheave pair; centres of the pins (n, 2)."""
    n = centres.shape[0]
    side = np.r_[-np.ones(n), np.ones(n)]
    R = np.column_stack([np.tile(centres, (2, 1)), side * (MERIDIAN(np.full(2 * n, radius))[0] - 2e-6)])
    ang = np.arctan2(R[:, 1], R[:, 0])
    tau = np.column_stack([-np.sin(ang), np.cos(ang)])
    v = 20.0 * np.column_stack([tau, np.zeros(2 * n)]) + rng.normal(size=(2 * n, 3)) * 1e-3
    Bcal = np.zeros((2 * n, 2, 2))
    Bcal[:, 0, 0], Bcal[:, 1, 1] = 1 / 0.5, 1 / 0.02
    m = 2 * n
    return dict(R_pin=R, v_pin=v, omega_pin=rng.normal(size=(m, 3)), slope=rng.normal(size=(m, 2)) * 1e-3,
                tau=tau, beta0=np.zeros(m), beta=np.zeros((m, 2)), Bcal=Bcal, H=np.zeros(m),
                R_c=np.zeros((m, 3)), v_c=np.zeros((m, 3)), theta=np.column_stack([rng.normal(size=(m, 2)) * 1e-3,
                                                                                    np.zeros(m)]),
                omega=np.tile([0.0, 0.0, 20.0 / radius], (m, 1)), side=side)


def join(a: dict, b: dict) -> dict:
    return {k: np.concatenate([a[k], b[k]]) for k in a}


H1_KEYS = ("R_pin", "v_pin", "R_c", "v_c", "theta", "omega", "side")
H2_KEYS = ("R_pin", "v_pin", "omega_pin", "slope", "tau", "beta0", "beta", "Bcal", "H", "R_c", "v_c", "theta", "omega",
           "side")


def main() -> None:
    rng = np.random.default_rng(0)
    ang = 2 * np.pi * np.arange(N_PINS) / N_PINS
    s = join(contact_set(0.060 * np.column_stack([np.cos(ang), np.sin(ang)]), 0.060, rng),
             contact_set(0.040 * np.column_stack([np.cos(ang), np.sin(ang)]), 0.040, rng))
    m = s["R_pin"].shape[0]
    lines = [f"machine: {machine()}", f"{m} contacts (84 pins x 2 ends x 2 shafts), toroidal sheaves, smooth friction"]
    h1 = [s[k] for k in H1_KEYS]
    h2 = [s[k] for k in H2_KEYS]
    t = {}
    for name, fun in (("H1", lambda u: h1_contacts(*h1, C, MERIDIAN, F0, V0, "smooth", 0.2, use_numba=u)),
                      ("H2", lambda u: h2_contacts(*h2, C, MERIDIAN, F0, V0, "smooth", 0.2, use_numba=u))):
        for backend, u in (("numba", True), ("numpy", False)):
            t[name, backend] = median_us(lambda: fun(u))
            lines.append(f"{name} {backend:<6} contact loads            median of 1000: {t[name, backend]:8.1f} us "
                         f"({t[name, backend] / m * 1e3:6.1f} ns per contact)")
    lines.append(f"numba speed-up: H1 {t['H1', 'numpy'] / t['H1', 'numba']:.0f}x, H2 {t['H2', 'numpy'] / t['H2', 'numba']:.0f}x")
    # the kernels alone, on preallocated buffers (what an RHS holding its work arrays pays)
    c, law = np.full(m, C), LAW_CODES["smooth"]
    v3, v1 = (lambda: np.empty((m, 3))), (lambda: np.empty(m))
    out1 = [v3(), v3(), v1(), v1(), v1(), v3(), v3(), v3(), v1()]
    out2 = [v3(), v3(), v1(), v1(), v1(), v3(), v3(), v3(), v1(), v3(), v3(), v1()]
    for name, fun in (("H1", lambda: h1_kernel(*h1, c, MERIDIAN.params, F0, V0, law, 0.2, *out1)),
                      ("H2", lambda: h2_kernel(*h2, c, MERIDIAN.params, F0, V0, law, 0.2, *out2))):
        t[name, "kernel"] = median_us(fun)
        lines.append(f"{name} numba  kernel alone (preallocated)   median of 1000: {t[name, 'kernel']:8.1f} us "
                     f"({t[name, 'kernel'] / m * 1e3:6.1f} ns per contact)")

    # RHS estimate of an 84-pin chain with its 336 contacts: chain forces + gather + contacts + scatter + mass solve
    a1 = ChainA1(**chain_args())
    a4 = ChainPerPlate(model="A4", plate_thickness=1.5e-3, **chain_args())
    R0 = PITCH / (2 * np.sin(np.pi / N_PINS))
    q = a1.rest_state(R0 * np.column_stack([np.cos(ang), np.sin(ang)])) + 1e-6 * rng.standard_normal(a1.n2)
    v = 0.1 * rng.standard_normal(a1.n2)
    pins = np.tile(np.arange(N_PINS), 4)
    xi = np.tile(np.r_[-np.ones(N_PINS), np.ones(N_PINS)], 2)
    force = np.asarray(h2_contacts(*h2, C, MERIDIAN, F0, V0).force)
    moment = rng.normal(size=(m, 2))
    pts, Q = np.empty((m, 3)), np.zeros(a1.n2)
    parts = {
        "A1 chain forces (numba, with damping)": lambda: a1.forces(q, v),
        "A4 chain forces (numba, 1008 plates)": lambda: a4.forces(q, v),
        "gather contact points (numpy axis_points)": lambda: a1.axis_points(q, pins, xi),
        "gather contact points (numba kernel)": lambda: axis_points_kernel(q, N_PINS, PIN_L, pins, xi, pts),
        "H2 contact kernel (336, preallocated)": lambda: h2_kernel(*h2, c, MERIDIAN.params, F0, V0, law, 0.2, *out2),
        "scatter loads (numpy point_loads, np.add.at)": lambda: a1.point_loads(pins, xi, force, moment),
        "scatter loads (numba kernel)": lambda: point_loads_kernel(N_PINS, PIN_L, pins, xi, force, moment, Q),
        "A1 accel (forces + per-pin mass solve)": lambda: a1.accel(q, v),
    }
    lines.append("RHS of an 84-pin chain with 336 H2 contacts, by part:")
    for name, fun in parts.items():
        t[name] = median_us(fun)
        lines.append(f"  {name:<46} {t[name]:8.1f} us")
    for glue_kind in ("numpy", "numba kernel"):
        glue = (t[f"gather contact points ({'numpy axis_points' if glue_kind == 'numpy' else glue_kind})"]
                + t["H2 contact kernel (336, preallocated)"]
                + t[f"scatter loads ({'numpy point_loads, np.add.at' if glue_kind == 'numpy' else glue_kind})"])
        a1_rhs = t["A1 accel (forces + per-pin mass solve)"] + glue
        a4_rhs = a1_rhs + t["A4 chain forces (numba, 1008 plates)"] - t["A1 chain forces (numba, with damping)"]
        lines.append(f"  estimate with {glue_kind} gather/scatter: A1 + contacts {a1_rhs:7.1f} us, "
                     f"A4 + contacts {a4_rhs:7.1f} us")
    lines.append("  target of issue 13 for A5 with refined contact: < 300 us per RHS (source C++: ~760 us)")
    lines.append("Model protocol (FreeChainA, no contacts), median of 20 jac calls at a moving damped state:")
    for name, fam in (("A1", a1), ("A4", a4)):
        model = FreeChainA(fam, q, v)
        x = model.initial_state()
        t_rhs, t_jac = median_us(lambda: model.rhs(0.0, x)), median_us(lambda: model.jac(0.0, x), 20)
        lines.append(f"  {name}: rhs {t_rhs:8.1f} us, jac {t_jac / 1e3:7.2f} ms = {t_jac / t_rhs:5.0f} RHS-equivalents")
    lines.append(f"machine after: {machine()}")
    print("\n".join(lines))
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_contact.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
