"""The chain on two rigid sheaves at the stationary regime (3500 rpm, 200 N m, ratio 2.4) against the 6+2n band.

Run:  .venv/bin/python studies/chain/chain_cvt_stationary.py [--t-end 0.01] [--window 0.006] [--model chain-S2]
      [--png out/studies/chain/chain_cvt_stationary.png]
1. The band-6+2n preset runs 1 s (both loops) to its stationary state: clamping forces F1, F2 and the
   span tensions of :func:`~cvtfem.machines.chain_cvt.band_span_tensions`.
2. The reference chain (84 pins, 9 mm) with the same scene values (friction law of the band preset) and
   F_appl = the band's (F1, F2) starts from its quasi-static state at the ratio and runs ``t_end`` (Radau,
   rtol 1e-3, atol 1e-6); means over the last ``window`` of the span tensions and of the sheave axial
   forces against the clamping forces are printed, with the wall time per simulated ms and the cost
   of one RHS and one Jacobian (median of 1000 / 20 calls), machine named; for the whole-pin chains (``--model
   chain-A1``) also the link twist and shear and the fixed sheaves' axial forces.  ``--png``: the span tensions,
   axial force balance and ratio over the whole run (outputs every 25 us).
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.integrate import solve
from cvtfem.machines import build_model
from cvtfem.machines.chain_cvt import band_span_tensions, from_scene
from cvtfem.scene.loader import load_scene


def band_reference():
    """``(F (2,), T (2,), outputs)`` of the band-6+2n preset after 1 s."""
    band = build_model(load_scene("band-6+2n"))
    res = solve(band, (0.0, 1.0), band.initial_state(), method="Radau", rtol=1e-6, atol=1e-8, n2=band.n2,
                jac=band.jac, jac_sparsity=band.jac_sparsity)
    x = res.y[:, -1]
    o = band.outputs(1.0, x)
    return np.array([o["driving.clamping_force"], o["driven.clamping_force"]]), band_span_tensions(band, x), o


def chain_run(F, t_end, model="chain-S2", dt_out=2.5e-5):
    """Run the chain from its quasi-static state; returns the model, the static report and the sampled outputs."""
    scene = load_scene("band-6+2n")
    m = from_scene(scene, reference_geometry(), F, model=model)
    x0, rep = m.static_state(scene.cvt.regime.ratio, scene.cvt.regime.input_speed)
    t_eval = np.linspace(0.0, t_end, int(round(t_end / dt_out)) + 1)
    t0 = time.perf_counter()
    res = solve(m, (0.0, t_end), x0, method="Radau", rtol=1e-3, atol=1e-6, n2=m.n2, jac=m.jac,
                jac_sparsity=m.jac_sparsity, t_eval=t_eval)
    wall = time.perf_counter() - t0
    outs = [m.outputs(t, y) for t, y in zip(res.t, res.y.T)]
    return m, x0, rep, res, outs, wall


def plot(t, T, balance, ratio, T_band, path):
    """Span tensions with the band's, axial force over clamping force - 1, ratio; PNG at ``path``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    ms = 1e3 * t
    for k, name in enumerate(("tight", "slack")):
        ax[0].plot(ms, T[:, k], c=f"C{k}", lw=0.8, label=f"chain, {name} span")
        ax[0].axhline(T_band[k], c=f"C{k}", ls="--", label=f"band 6+2n, {name}")
    ax[0].set_ylabel("mean span link tension, N")
    for k, name in enumerate(("driving", "driven")):
        ax[1].plot(ms, 100 * balance[:, k], lw=0.8, label=name)
    ax[1].set_ylabel("sum of pin axial forces /\nclamping force - 1, %")
    ax[2].plot(ms, ratio, lw=0.8)
    ax[2].set_ylabel("speed ratio w1 / w2")
    ax[2].set_xlabel("t, ms")
    for a in ax[:2]:
        a.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=90)


def median_s(fn, calls):
    return 1e-6 * median_us(fn, calls)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=0.01)
    ap.add_argument("--window", type=float, default=0.006)
    ap.add_argument("--model", default="chain-S2")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    print(f"machine: {machine()}")
    F, Tb, ob = band_reference()
    print(f"band 6+2n: F1 {F[0]:.0f} N, F2 {F[1]:.0f} N, ratio {ob['ratio']:.4f}, tight {Tb[0]:.0f} N, "
          f"slack {Tb[1]:.0f} N, efficiency {ob['efficiency']:.4f}")
    m, x0, rep, res, outs, wall = chain_run(F, a.t_end, a.model)
    print(f"static state: residual {rep['residual']:.2e} of F2, max penetration {rep['max_penetration'] * 1e6:.2f} um, "
          f"F1 to hold the ratio without torque {rep['F1']:.0f} N, mean link tension {rep['tension']:.0f} N")
    print(f"run 0..{a.t_end * 1e3:g} ms: status {res.status}, {res.stats['nsteps']} steps, wall {wall:.1f} s "
          f"= {wall / (a.t_end * 1e3):.1f} s per simulated ms")
    T = np.array([o["chain.span_tension"] for o in outs])
    A = np.array([o["contact.sheave_axial_force"] for o in outs])
    Fc = np.array([[o["driving.clamping_force"], o["driven.clamping_force"]] for o in outs])
    ratio = np.array([o["ratio"] for o in outs])
    if a.png:
        plot(res.t, T, A / Fc - 1, ratio, Tb, a.png)
    last = res.t >= a.t_end - a.window - 1e-12
    outs, T, A, Fc = [o for o, k in zip(outs, last) if k], T[last], A[last], Fc[last]
    tm, sm = np.nanmean(T, axis=0)
    print(f"chain ({a.model}), mean over the last {a.window * 1e3:g} ms: tight {tm:.0f} N "
          f"({tm / Tb[0] - 1:+.2%} vs band), slack {sm:.0f} N ({sm / Tb[1] - 1:+.2%}), tight - slack {tm - sm:.0f} N "
          f"(M1/r1 {ob['driving.torque'] / rep['placement'].r[0]:.0f} N)")
    bal = A.mean(axis=0) / Fc.mean(axis=0) - 1
    print(f"sheave axial force / clamping force - 1: driving {bal[0]:+.2%}, driven {bal[1]:+.2%}; "
          f"ratio {np.mean([o['ratio'] for o in outs]):.4f}, efficiency {np.mean([o['efficiency'] for o in outs]):.4f}")
    if "chain.twist" in outs[0]:                     # the whole-pin chains: twist, shear, fixed sheaves
        tw = np.array([np.abs(o["chain.twist"]).max() for o in outs])
        sh = np.array([np.abs(o["chain.shear"]).max() for o in outs])
        fx = np.mean([o["contact.fixed_sheave_axial_force"] for o in outs], axis=0)
        print(f"largest link twist {tw.mean():.2e} rad (mean over the window of the per-sample maximum), shear "
              f"{sh.mean():.2e}; fixed sheaves' axial force / clamping force - 1: {fx / Fc.mean(axis=0) - 1}")
    x = res.y[:, -1]
    t_rhs = median_s(lambda: m.rhs(0.0, x), 1000)
    t_jac = median_s(lambda: m.jac(0.0, x), 20)
    print(f"one RHS {t_rhs * 1e3:.2f} ms, one Jacobian {t_jac * 1e3:.0f} ms ({t_jac / t_rhs:.0f} RHS)")


if __name__ == "__main__":
    main()
