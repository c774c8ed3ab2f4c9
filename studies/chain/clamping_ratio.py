"""The clamping-force ratio F1/F2 that holds the ratio: the 6+2n band against the S1 chain (issue 13/14).

Run:  .venv/bin/python studies/chain/clamping_ratio.py [--ratios 0.8335,1.0,1.25] [--t-end 0.03] [--v0 0.02]
      [--model chain-S1] [--method rock4] [--rtol 1e-4] [--no-table] [--states-dir out/studies/chain/clamping]
      [--png out/studies/chain/clamping_ratio.png]
      (S1: ~1 min for the table, 60-110 s per 30 ms run at load 11-17; S2 with ``--method Radau --rtol 1e-3 --t-end
      0.02``: 2-4.5 min per run.)
1. The band-6+2n preset's steady start (3500 rpm, 200 N m, ratio 2.4; ``--v0`` the friction law's saturation
   speed): both arcs, span tensions and clamping forces.
2. :func:`~cvtfem.elements.band.creep.held_arc` at the band's span tensions: the force each arc needs, without give
   (the Euler arc: the band's own F1/F2), with the chain's link stretch, pin spring (S1), Hertz give (H1), with and
   without the pins' radial slip (spiral running), for v0 = 0.02, 0.05, 0.2 m/s.
3. The chain (``--model``) with the loops off at held clamping forces ``F1 = ratio x F2`` (``--ratios``, F2 the band's), from
   its quasi-static state to ``--t-end`` (rock4, rtol 1e-4; states cached in ``--states-dir``): the speed ratio's
   drift over the second half of the run; the F1/F2 where it does not drift (linear interpolation), against
   held_arc's prediction at the chain's own span tensions.
4. Along the driving arc, last third of the run at the F1/F2 nearest to the no-drift one: the pins' tangential and
   radial slip and friction coefficients against held_arc's profile.
Machine and load are printed; ``--png`` draws the ratio drift and the driving arc.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from slack_span import BIN, arc_profile, band_scene, chain_model, chain_run  # noqa: E402

from cvtfem.analysis.timing import machine  # noqa: E402
from cvtfem.elements.band.creep import band_arc, held_arc  # noqa: E402
from cvtfem.elements.chain.geometry import reference_geometry  # noqa: E402
from cvtfem.machines import build_model  # noqa: E402
from cvtfem.machines.chain_cvt import band_span_tensions  # noqa: E402

V0S = (0.02, 0.05, 0.2)


def band_steady(v0):
    """The band-6+2n preset's steady start at ``v0``: clamping forces (2,) N, spans (tight, slack) N, both arcs."""
    band = build_model(band_scene(v0))
    x = band.initial_state()
    q, v, _, _ = band.split(x)
    o = band.outputs(0.0, x)
    return (np.array([o["driving.clamping_force"], o["driven.clamping_force"]]), band_span_tensions(band, x),
            [band_arc(band.model, q, v, k) for k in (0, 1)])


def gives():
    """The give cases of the table: name -> keyword arguments of :func:`held_arc` (the reference chain's values)."""
    g = reference_geometry()
    EA, c_p, pitch = float(g.c_link[0] * g.L[0]), float(g.c_pin[0]), float(g.L[0])
    return {"none (the 6+2n band)": dict(pitch=pitch),
            "link stretch": dict(EA=EA, pitch=pitch),
            "S1, tangential creep only": dict(EA=EA, c_pin=c_p, pitch=pitch, radial=False),
            "S1: links + pin spring": dict(EA=EA, c_pin=c_p, pitch=pitch),
            "S1, links x10": dict(EA=10 * EA, c_pin=c_p, pitch=pitch),
            "H1 (S2, A1): + Hertz": dict(EA=EA, c_pin=c_p, c_hertz=2.14e10, pitch=pitch)}


def held_forces(arcs, spans, **kw):
    """The forces (2,) N the driving and driven arcs need to hold the ``spans`` (tight, slack) N, and both arcs."""
    Tt, Ts = spans
    out = [held_arc(**arcs[0]["args"], T_in=Tt, T_out=Ts, **kw), held_arc(**arcs[1]["args"], T_in=Ts, T_out=Tt, **kw)]
    return np.array([o["F"] for o in out]), out


def drift(m, t, Y):
    """Speed ratio at the run's samples, its drift (1/s, fit over the second half), and the means over the last third
    of the span tensions (tight, slack) N and the clamping forces (2,) N."""
    outs = [m.outputs(ti, Y[:, i]) for i, ti in enumerate(t)]
    ratio = np.array([o["ratio"] for o in outs])
    half = t >= t[-1] / 2
    rate = np.polyfit(t[half], ratio[half], 1)[0]
    last = t >= 2 * t[-1] / 3
    spans = np.nanmean([outs[i]["chain.span_tension"] for i in np.nonzero(last)[0]], axis=0)
    return ratio, rate, spans


def plot(runs, prof, model_arc, F_pred_ratio, band_ratio, path, model="chain-S1"):
    """The speed ratio of the open-loop runs over time; slip and friction along the driving arc, chain against
    :func:`held_arc`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 10.5))
    for k, (rq, (t, ratio, rate, _)) in enumerate(runs.items()):
        ax[0].plot(1e3 * t, ratio, c=f"C{k}", label=f"{model}, loops off, F1/F2 = {rq:.4g}: drift {rate:+.3f} 1/s")
    ax[0].set_xlabel("t, ms")
    ax[0].set_ylabel("speed ratio w1 / w2")
    ax[0].set_title(f"band 6+2n holds the ratio at F1/F2 = {band_ratio:.3f}; held_arc ({model}'s give) predicts "
                    f"{F_pred_ratio:.3f}", fontsize=9)
    deg, _, _, f_t, f_r, w_t, w_r = prof
    th = np.degrees(model_arc["theta"] - model_arc["theta"][-1] / 2)
    ax[1].plot(np.degrees(deg), 1e3 * np.abs(w_t), "o", c="C0", ms=3, label=f"{model} pins: |tangential slip|")
    ax[1].plot(np.degrees(deg), 1e3 * w_r, "s", c="C1", ms=3, label=f"{model} pins: radial slip (outwards > 0)")
    ax[1].plot(th, 1e3 * np.abs(model_arc["w_t"]), "-", c="C0", label="held_arc: |tangential slip|")
    ax[1].plot(th, 1e3 * model_arc["w_r"], "-", c="C1", label="held_arc: radial slip")
    ax[1].set_ylabel("slip, mm/s")
    ax[1].set_ylim(-80, 80)                             # the arriving pin (~ -1 m/s radially) is off the scale
    ax[2].plot(np.degrees(deg), np.abs(f_t), "o", c="C0", ms=3, label=f"{model} pins: |F_t| / N")
    ax[2].plot(np.degrees(deg), f_r, "s", c="C1", ms=3, label=f"{model} pins: F_r / N on the sheave (outwards > 0)")
    ax[2].plot(th, np.abs(model_arc["f_t"]), "-", c="C0", label="held_arc: |f_t|")
    ax[2].plot(th, model_arc["f_r"], "-", c="C1", label="held_arc: f_r")
    ax[2].set_ylabel("friction coefficient parts")
    for a in ax[1:]:
        a.set_xlabel("angle on the driving arc from its axis, deg (entry from the tight span < 0)")
        a.set_xlim(th[0] - 10, th[-1] + 10)
    for a in ax:
        a.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=90)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ratios", default="0.8335,1.0,1.25", help="F1/F2 of the open-loop S1 runs")
    ap.add_argument("--t-end", type=float, default=0.03)
    ap.add_argument("--v0", type=float, default=0.02)
    ap.add_argument("--states-dir", default="out/studies/chain/clamping")
    ap.add_argument("--model", default="chain-S1", help="chain-S1 (give: pin spring) or chain-S2 (and Hertz)")
    ap.add_argument("--method", default="rock4")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--no-table", action="store_true", help="skip the held_arc table")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    own = "S1: links + pin spring" if a.model == "chain-S1" else "H1 (S2, A1): + Hertz"
    print(f"machine: {machine()}")
    F, spans, arcs = band_steady(a.v0)
    print(f"band 6+2n (v0 {a.v0}): F1 {F[0]:.0f} N, F2 {F[1]:.0f} N, F1/F2 {F[0] / F[1]:.4f}; spans {spans[0]:.0f} / "
          f"{spans[1]:.0f} N; wraps {arcs[0]['args']['wrap']:.4f} / {arcs[1]['args']['wrap']:.4f} rad, tan(gamma) "
          f"{arcs[0]['args']['tan_gamma']:.4f} / {arcs[1]['args']['tan_gamma']:.4f}")
    print("held_arc at the band's spans: F1, F2 N, F1/F2, mean radial slip on the driving arc mm/s")
    for v0 in () if a.no_table else V0S:
        Fv, sv, av = (F, spans, arcs) if v0 == a.v0 else band_steady(v0)
        for name, kw in gives().items():
            Fh, out = held_forces(av, sv, **kw)
            print(f"  v0 {v0:4.2f} {name:28s} {Fh[0]:7.0f} {Fh[1]:7.0f}  {Fh[0] / Fh[1]:.4f} "
                  f"({Fh[0] / Fh[1] / (Fv[0] / Fv[1]) - 1:+6.1%} on the band's)  {1e3 * out[0]['w_r'].mean():+5.1f}")
    runs, states = {}, {}
    for rq in [float(s) for s in a.ratios.split(",")]:
        m = chain_model(a.model, np.array([rq * F[1], F[1]]), v0=a.v0, open_loop=True)
        name = a.model.replace("chain-", "")
        path = os.path.join(a.states_dir, f"{name}_open_v0{a.v0:g}_F1F2_{rq:g}_{a.t_end * 1e3:g}ms.npz")
        t, Y = chain_run(m, a.t_end, a.method, a.rtol, path)
        ratio, rate, sp = drift(m, t, Y)
        runs[rq], states[rq] = (t, ratio, rate, sp), (m, t, Y)
        Fh, _ = held_forces(arcs, sp, **gives()[own])
        print(f"{a.model} loops off, F1/F2 {rq:.4f}: ratio {ratio[0]:.4f} -> {ratio[-1]:.4f}, drift over the 2nd half "
              f"{rate:+.4f} 1/s; spans (last third) {sp[0]:.0f} / {sp[1]:.0f} N; held_arc at these spans: F1/F2 "
              f"{Fh[0] / Fh[1]:.4f}")
    rq = np.array(sorted(runs))
    rates = np.array([runs[r][2] for r in rq])
    if len(rq) > 1 and rates.min() < 0 < rates.max():
        j = int(np.nonzero(np.diff(np.sign(rates)))[0][0])
        zero = rq[j] - rates[j] * (rq[j + 1] - rq[j]) / (rates[j + 1] - rates[j])
        print(f"{a.model} holds its ratio (no drift) at F1/F2 = {zero:.4f} (linear between {rq[j]:g} and {rq[j + 1]:g}); "
              f"band {F[0] / F[1]:.4f}")
    else:
        zero = rq[np.argmin(np.abs(rates))]
        print(f"no sign change of the drift over F1/F2 = {list(rq)}: nearest to no drift {zero:g}")
    near = rq[np.argmin(np.abs(rq - zero))]
    m, t, Y = states[near]
    sel = slice(None, None, 2)
    prof = arc_profile(m, t[sel], Y[:, sel], 2 * t[-1] / 3, shaft=0)
    Fh, out = held_forces(arcs, runs[near][3], **gives()[own])
    deg, T, N, f_t, f_r, w_t, w_r = prof
    print(f"driving arc, F1/F2 {near:g}, last third: angle deg, link tension N, N per sample, F_t/N, F_r/N, slip t/r "
          f"mm/s; sum F_r / sum N sin(gamma): ", end="")
    on = np.isfinite(f_t) & (np.abs(deg) <= arcs[0]["args"]["wrap"] / 2 + BIN)
    sg = arcs[0]["args"]["tan_gamma"] / np.hypot(1, arcs[0]["args"]["tan_gamma"])
    print(f"{np.nansum(f_r[on] * N[on]) / (sg * np.nansum(N[on])):+.3f} (held_arc: "
          f"{np.mean(out[0]['f_r']) / sg:+.3f})")
    for j in np.nonzero(on)[0]:
        print(f"  {np.degrees(deg[j]):6.0f} {T[j]:7.0f} {N[j]:7.0f} {f_t[j]:+.4f} {f_r[j]:+.4f} {1e3 * w_t[j]:+7.1f} "
              f"{1e3 * w_r[j]:+7.1f}")
    if a.png:
        plot(runs, prof, out[0], Fh[0] / Fh[1], F[0] / F[1], a.png, a.model)


if __name__ == "__main__":
    main()
