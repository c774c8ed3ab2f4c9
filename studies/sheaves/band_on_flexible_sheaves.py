"""Band-6+2n at the reference stationary regime on rigid and on flexible sheaves (issue 20).

For each sheave model: the driven clamping force F2 of the clamping schedule, the driving force F1 that holds the
span angle of the target ratio in steady running (root of the span angle's acceleration), then the efficiency
``-M2 w2 / (M1 w1)``, the speed ratio, the faces' opening and the running radius along each arc (nominal radius
plus the band's radial Ritz displacement).  Prints a table; ``--png`` draws the opening and radius change;
``--bench`` times the right-hand side (median of 7 rounds, each the median of 1000 calls, interleaved), rigid and
flexible (face table, and the exact face systems at every call), each compiled and as its numpy twin, and the
compiled Jacobian; ``--convergence`` repeats the flexible case with other harmonic counts and meshes;
``--ratios`` compares rigid and flexible over the ratio range (same torque and speed).

    .venv/bin/python studies/sheaves/band_on_flexible_sheaves.py [--png out.png] [--bench] [--convergence] [--ratios]
"""
from __future__ import annotations

import sys
import time

import numpy as np
from scipy.optimize import newton

from cvtfem.analysis.timing import machine, median_us
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene


def ratio_holding_state(loop):
    """Steady running with the F1 that holds the target span angle: ``(F, q, v, M2)``."""
    band = loop.model
    w1, M1, i = loop.regime.targets(0.0)
    F = loop.clamping.forces(M1, i)
    phi = loop.clamping.span_angle(i)

    def state(F1):
        Fs = np.array([F1, F[1]])
        q, v, M2, _ = band.steady_state(phi, w1, Fs, M1)
        return Fs, q, v, M2

    def span_accel(F1):
        Fs, q, v, M2 = state(F1)
        return band.accel(q, v, Fs, np.array([M1, M2]))[0][0]

    F1 = newton(span_accel, F[0], x1=1.01 * F[0], tol=1e-3)        # secant: F1 within 1 mN
    return state(F1)


def running_radius(band, q):
    """Nominal radius plus the band's radial displacement at each arc's Gauss nodes, m, (2, g)."""
    g = band.arcs(q[0])
    n = band.p.n_ritz
    h = np.stack([q[6:6 + n], q[6 + n:6 + 2 * n]])
    return g["r"][:, None] + np.einsum("kng,kn->kg", g["fr"], h), g["th"]


def bench() -> None:
    """Median right-hand-side times, us: interleaved rounds of 1000 calls at the steady start state; the compiled
    Jacobian (rounds of 30 calls)."""
    import dataclasses

    def variant(loop, **changes):
        return dataclasses.replace(loop, model=dataclasses.replace(loop.model, **changes))

    rigid, flexible = closed_loop(load_scene("band-6+2n")), closed_loop(load_scene("band-6+2n-flexible"))
    loops = {"rigid (numba)": rigid, "rigid (numpy twin)": variant(rigid, use_numba=False),
             "flexible (numba)": flexible, "flexible (numpy twin)": variant(flexible, use_numba=False),
             "flexible exact (numba)": variant(flexible, face_intervals=0),
             "flexible exact (numpy)": variant(flexible, face_intervals=0, use_numba=False)}
    x = rigid.initial_state()
    print(f"machine: {machine()}")
    times = {name: [] for name in loops}
    jac = {name: [] for name in ("rigid (numba)", "flexible (numba)", "flexible exact (numba)")}
    for _ in range(7):
        for name, loop in loops.items():
            times[name].append(median_us(lambda: loop.rhs(0.0, x), 1000 if "numba" in name else 100, warm_up=True))
            if name in jac:
                jac[name].append(median_us(lambda: loop.jac(0.0, x), 30, warm_up=True))
    base = np.median(times["rigid (numba)"])
    for name, t in times.items():
        print(f"rhs {name:24s} {np.median(t):8.1f} us (rounds {min(t):.1f}..{max(t):.1f}) "
              f"{np.median(t) / base - 1:+7.0%} against rigid (numba)")
    for name, t in jac.items():
        print(f"jacobian {name:19s} {np.median(t):8.1f} us (rounds {min(t):.1f}..{max(t):.1f})")


def convergence() -> None:
    """F1/F2, efficiency and largest opening of the flexible case against the face model's resolution."""
    for harmonics, cells in ((12, (24, 2)), (24, (24, 2)), (48, (24, 2)), (24, (48, 4))):
        loop = closed_loop(load_scene("band-6+2n-flexible", {"sheave": {
            "harmonics": harmonics, "cells_radial": cells[0], "cells_axial": cells[1]}}))
        F, q, v, M2 = ratio_holding_state(loop)
        w1, M1, _ = loop.regime.targets(0.0)
        print(f"harmonics {harmonics:3d}, cells {cells[0]} x {cells[1]}: F1/F2 {F[0] / F[1]:.5f}, efficiency "
              f"{-M2 * v[3] / (M1 * v[2]):.6f}, largest opening {loop.model.face_opening(q).max() * 1e6:.1f} um")


def ratios() -> None:
    """F1/F2, efficiency and largest opening, rigid and flexible, at ratios across the range."""
    print(f"{'ratio':>6s} {'F1/F2 rigid':>12s} {'flexible':>9s} {'change':>8s} {'eff. rigid':>11s} {'flexible':>9s} "
          f"{'F1, F2 kN':>14s} {'opening um':>14s}")
    loops = {name: closed_loop(load_scene(name)) for name in ("band-6+2n", "band-6+2n-flexible")}
    for ratio in (0.5, 1.0, 1.6, 2.4):
        out = {}
        for name, loop in loops.items():
            loop = loop.with_regime(ratio=ratio)
            F, q, v, M2 = ratio_holding_state(loop)
            w1, M1, _ = loop.regime.targets(0.0)
            out[name] = (F, -M2 * v[3] / (M1 * v[2]), loop.model.face_opening(q).max(axis=1))
        (Fr, er, _), (Ff, ef, wf) = out.values()
        print(f"{ratio:6.2f} {Fr[0] / Fr[1]:12.4f} {Ff[0] / Ff[1]:9.4f} {(Ff[0] / Ff[1]) / (Fr[0] / Fr[1]) - 1:+8.2%} "
              f"{er:11.5f} {ef:9.5f} {Ff[0] / 1e3:6.1f} {Ff[1] / 1e3:6.1f}   {wf[0] * 1e6:5.1f} {wf[1] * 1e6:6.1f}")


def main(argv: list[str]) -> None:
    rows = {}
    for name in ("band-6+2n", "band-6+2n-flexible"):
        loop = closed_loop(load_scene(name))
        t = time.perf_counter()
        F, q, v, M2 = ratio_holding_state(loop)
        w1, M1, _ = loop.regime.targets(0.0)
        r, th = running_radius(loop.model, q)
        rows[name] = dict(F=F, eff=-M2 * v[3] / (M1 * v[2]), ratio=v[2] / v[3], r=r, th=th,
                          w=loop.model.face_opening(q), secs=time.perf_counter() - t)
    print(f"machine: {machine()}")
    print(f"{'sheaves':22s} {'F1 kN':>8s} {'F2 kN':>8s} {'F1/F2':>8s} {'efficiency':>11s} {'w1/w2':>8s} "
          f"{'max opening um (arc 1, 2)':>27s} {'solve s':>8s}")
    for name, row in rows.items():
        F, w = row["F"], row["w"]
        print(f"{name:22s} {F[0] / 1e3:8.3f} {F[1] / 1e3:8.3f} {F[0] / F[1]:8.4f} {row['eff']:11.5f} "
              f"{row['ratio']:8.4f} {w[0].max() * 1e6:13.1f} {w[1].max() * 1e6:13.1f} {row['secs']:8.1f}")
    dr = rows["band-6+2n-flexible"]["r"] - rows["band-6+2n"]["r"]
    for k in range(2):
        print(f"arc {k + 1}: running radius change {dr[k].min() * 1e6:.1f} .. {dr[k].max() * 1e6:.1f} um "
              f"(mean {dr[k].mean() * 1e6:.1f} um; nominal r = {rows['band-6+2n']['r'][k].mean() * 1e3:.2f} mm)")
    if "--bench" in argv:
        bench()
    if "--convergence" in argv:
        convergence()
    if "--ratios" in argv:
        ratios()
    if "--png" in argv:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
        flex = rows["band-6+2n-flexible"]
        for k, label in enumerate(("driving", "driven")):
            deg = np.degrees(flex["th"][k])
            axes[0].plot(deg, flex["w"][k] * 1e6, "o-", label=f"arc {k + 1} ({label})")
            axes[1].plot(deg, dr[k] * 1e6, "o-", label=f"arc {k + 1} ({label})")
        axes[0].set(xlabel="angle along the arc from its middle, deg", ylabel="face opening per sheave, um",
                    title="wedge opening under the band (flexible)")
        axes[1].set(xlabel="angle along the arc from its middle, deg", ylabel="running radius, flexible - rigid, um",
                    title="running radius change")
        for ax in axes:
            ax.grid(True)
            ax.legend()
        fig.tight_layout()
        fig.savefig(argv[argv.index("--png") + 1], dpi=110)


if __name__ == "__main__":
    main(sys.argv[1:])
