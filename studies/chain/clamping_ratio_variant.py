"""The clamping-force ratio F1/F2 at which a transmission variant holds its ratio, by open-loop runs (issue 14).

Run:  .venv/bin/python studies/chain/clamping_ratio_variant.py [--scene variant-a,regime-stationary]
      [--ratios 1.0,1.2] [--t-end 0.02] [--method rock4] [--rtol 1e-3] [--states-dir out/studies/chain/clamping]
      [--png out/studies/chain/clamping_ratio_variant_a.png]
      (variant (a): ~9 s wall per simulated ms idle, 20 ms per ratio; variant (b): ~45 s per ms, keep ``--t-end``
      at a few ms.)
1. The scene (``--scene``, a preset list; solver method and tolerance from it unless given) with the loops off, its
   prescribed clamping forces F_appl (the estimate (1.13) x safety, the band's split) and its quasi-static start.
2. For each F1/F2 in ``--ratios``: F2 = the scene's, F1 = ratio x F2 held, ``M2 = -b20 w2`` (the target point's
   resistance), a run from the quasi-static start to ``--t-end`` (states every 25 us cached in ``--states-dir``):
   the speed ratio's drift (1/s) and the movable sheaves' axial velocities (linear fits over the second half), the
   mean ratio, input speed and span tensions over the second half.
3. The no-drift F1/F2 by linear interpolation between the two bracketing ratios (or the secant through the two
   nearest to zero drift when none brackets), of the speed ratio and of each sheave's axial position; and the F1/F2
   at which the speed ratio's mean over the second half is the regime's ratio, the same interpolation: the ratio
   loop's equilibrium, the value for ``cvt.control.start_force_ratio``.  Where the chain's speed ratio at its
   geometric start ratio is off the target (A1 with H2: 2.485 at 2.4 within 2 ms), the two differ: the loop holds the
   speed ratio, not the start geometry (docs/transmission.md, "Stationary start of the loops").  Against
   :func:`~cvtfem.elements.band.creep.held_arc`'s prediction with the H1 give (pin spring and Hertz) at the chain's
   span tensions and the band's arcs.
Machine, load, wall and CPU times are printed; ``--png`` draws the speed ratio over time per F1/F2.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from clamping_ratio import band_steady, gives, held_forces  # noqa: E402

from cvtfem.analysis.timing import machine  # noqa: E402
from cvtfem.integrate import solve  # noqa: E402
from cvtfem.machines import build_model  # noqa: E402
from cvtfem.scene.loader import load_scene  # noqa: E402

SAMPLE = 25e-6      # s between stored states


def open_loop_model(names):
    """The scene of the preset list ``names`` with the loops off, built (its quasi-static start solved once)."""
    scene = load_scene(names).replace({"cvt": {"effects": {"stabilisation": False}}})
    return scene, build_model(scene)


def run_held(m, x0, rq, t_end, method, rtol, atol, path):
    """States every :data:`SAMPLE` of ``m`` at held ``F1 = rq F2`` from ``x0`` to ``t_end``: ``(t, Y, wall, cpu)``
    (read from ``path`` when it exists, then wall and cpu are the stored run's)."""
    if path and os.path.exists(path):
        d = np.load(path)
        return d["t"], d["y"], float(d["wall"]), float(d["cpu"])
    mq = m.with_clamping(np.array([rq * m.F_appl[1], m.F_appl[1]]))
    t_eval = np.linspace(0.0, t_end, int(round(t_end / SAMPLE)) + 1)
    w0, c0 = time.perf_counter(), time.process_time()
    res = solve(mq, (0.0, t_end), x0, method=method, rtol=rtol, atol=atol, n2=mq.n2, jac=mq.jac,
                jac_sparsity=mq.jac_sparsity, t_eval=t_eval)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    print(f"  F1/F2 {rq:g}: 0..{1e3 * t_end:g} ms ({method}, rtol {rtol:g}): status {res.status}, "
          f"{res.stats['nsteps']} steps, {res.stats['nfev']} RHS, wall {wall:.0f} s, cpu {cpu:.0f} s", flush=True)
    if res.status != 0:
        raise SystemExit(f"the run at F1/F2 = {rq:g} failed: {res.message}")
    if path:
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        np.savez(path, t=res.t, y=res.y, wall=wall, cpu=cpu)
    return res.t, res.y, wall, cpu


def drift(m, rq, t, Y):
    """Speed ratio at the samples; over the second half: its drift 1/s (linear fit), the axial velocities (2,) m/s of
    the movable sheaves (linear fits of their positions, outwards > 0), the means of ratio, input speed rpm and span
    tensions (tight, slack) N."""
    mq = m.with_clamping(np.array([rq * m.F_appl[1], m.F_appl[1]]))
    outs = [mq.outputs(ti, Y[:, i]) for i, ti in enumerate(t)]
    ratio = np.array([o["ratio"] for o in outs])
    z = np.array([[o["driving.sheave_position"], o["driven.sheave_position"]] for o in outs])
    half = t >= t[-1] / 2
    rate = np.polyfit(t[half], ratio[half], 1)[0]
    dz = np.polyfit(t[half], z[half], 1)[0]
    rpm = float(np.mean([o["driving.speed"] for o in outs]) * 30 / np.pi)
    spans = np.nanmean([outs[i]["chain.span_tension"] for i in np.nonzero(half)[0]], axis=0)
    return ratio, rate, dz, float(np.mean(ratio[half])), rpm, spans


def no_drift(rq, rates):
    """The F1/F2 of zero drift: linear between the bracketing pair, else the secant through the two nearest zero."""
    order = np.argsort(rq)
    rq, rates = np.asarray(rq)[order], np.asarray(rates)[order]
    change = np.nonzero(np.diff(np.sign(rates)))[0]
    if len(change):
        j = int(change[0])
        pair, how = (j, j + 1), "linear between"
    else:
        near = np.argsort(np.abs(rates))[:2]
        pair, how = tuple(sorted(near)), "secant (extrapolated) through"
    a, b = pair
    zero = rq[a] - rates[a] * (rq[b] - rq[a]) / (rates[b] - rates[a])
    return float(zero), f"{how} {rq[a]:g} and {rq[b]:g}"


def plot(runs, zero, label, path):
    """The speed ratio of the open-loop runs over time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, (rq, (t, ratio, rate, *_)) in enumerate(sorted(runs.items())):
        ax.plot(1e3 * t, ratio, c=f"C{k}", lw=0.8, label=f"F1/F2 = {rq:.4g}: drift {rate:+.3f} 1/s (2nd half)")
    ax.axhline(2.4, c="k", lw=0.5, ls=":")
    ax.set_xlabel("t, ms")
    ax.set_ylabel("speed ratio w1 / w2")
    ax.set_title(f"{label}, loops off at held clamping forces: no drift at F1/F2 = {zero:.3f}", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=90)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="variant-a,regime-stationary")
    ap.add_argument("--ratios", default="1.0,1.2", help="held F1/F2 of the open-loop runs")
    ap.add_argument("--t-end", type=float, default=0.02)
    ap.add_argument("--method", default="", help="default: the scene's")
    ap.add_argument("--rtol", type=float, default=0.0, help="default: the scene's (atol scales with it)")
    ap.add_argument("--states-dir", default="out/studies/chain/clamping")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    print(f"machine: {machine()}; load {os.getloadavg()[0]:.1f}", flush=True)
    scene, m = open_loop_model(a.scene)
    method = a.method or scene.solver.method
    rtol = a.rtol or scene.solver.rtol
    atol = scene.solver.atol * rtol / scene.solver.rtol
    w0, c0 = time.perf_counter(), time.process_time()
    x0, rep = m.start()
    print(f"{a.scene} ({scene.cvt.model}, {scene.cvt.effects.contact}, shaft elasticity "
          f"{scene.cvt.effects.shaft_elasticity}), loops off: F_appl {m.F_appl[0]:.0f} / {m.F_appl[1]:.0f} N "
          f"(F1/F2 {m.F_appl[0] / m.F_appl[1]:.4f}); start {rep['kind']} in {time.perf_counter() - w0:.0f} s wall, "
          f"{time.process_time() - c0:.0f} s cpu", flush=True)
    tag = a.scene.replace(",", "+")
    runs = {}
    for rq in [float(s) for s in a.ratios.split(",")]:
        path = os.path.join(a.states_dir, f"{tag}_open_F1F2_{rq:g}_{1e3 * a.t_end:g}ms_{method}_{rtol:g}.npz")
        t, Y, wall, cpu = run_held(m, x0, rq, a.t_end, method, rtol, atol, path)
        ratio, rate, dz, mean, rpm, spans = drift(m, rq, t, Y)
        runs[rq] = (t, ratio, rate, dz, mean, rpm, spans)
        print(f"F1/F2 {rq:.4f}: ratio {ratio[0]:.4f} -> {ratio[-1]:.4f}, over the 2nd half: drift {rate:+.4f} 1/s, "
              f"sheaves {1e3 * dz[0]:+.2f} / {1e3 * dz[1]:+.2f} mm/s (driving / driven, outwards > 0), mean "
              f"{mean:.4f}, input {rpm:.0f} rpm; spans {spans[0]:.0f} / {spans[1]:.0f} N "
              f"({wall / (1e3 * t[-1]):.1f} s wall, {cpu / (1e3 * t[-1]):.1f} s cpu per simulated ms)", flush=True)
    if len(runs) < 2:
        return
    rq = sorted(runs)
    zero, how = no_drift(rq, [runs[r][2] for r in rq])
    print(f"{a.scene}: the speed ratio does not drift at F1/F2 = {zero:.4f} ({how}); the band's (F_appl) "
          f"{m.F_appl[0] / m.F_appl[1]:.4f}")
    for k, name in enumerate(("driving", "driven")):
        zk, how = no_drift(rq, [runs[r][3][k] for r in rq])
        print(f"  the {name} sheave stays at F1/F2 = {zk:.4f} ({how})")
    i_d = scene.cvt.regime.ratio
    level, how = no_drift(rq, [runs[r][4] - i_d for r in rq])
    print(f"  the speed ratio's mean over the 2nd half is the target {i_d:g} at F1/F2 = {level:.4f} ({how}): the "
          f"ratio loop's equilibrium (its integral's F11 = F1 - F1a at e = 0), the value for start_force_ratio")
    _, _, arcs = band_steady(scene.cvt.friction.v0)
    near = rq[int(np.argmin(np.abs(np.array(rq) - zero)))]
    Fh, _ = held_forces(arcs, runs[near][6], **gives()["H1 (S2, A1): + Hertz"])
    print(f"held_arc (H1 give: pin spring + Hertz, with radial slip) at the spans of F1/F2 {near:g} "
          f"({runs[near][6][0]:.0f} / {runs[near][6][1]:.0f} N): F1/F2 {Fh[0] / Fh[1]:.4f}")
    if a.png:
        plot(runs, zero, a.scene, a.png)


if __name__ == "__main__":
    main()
