"""Why the chain's slack span runs above the 6+2n band model's at the same clamping forces (issue 13).

Run:  .venv/bin/python studies/chain/slack_span.py [--model chain-S1] [--t-end 0.08] [--window 0.005]
      [--link-factor 1] [--method rock4] [--rtol 1e-4] [--states out/studies/chain/slack_span_S1.npz]
      [--band-cache out/studies/chain/band_6+2n_1s.npy] [--v0 V] [--open-loop] [--png FILE]
1. The band-6+2n preset runs 1 s into its stationary regime (3500 rpm, 200 N m, ratio 2.4): clamping forces, span
   tensions by the radial balance at the arc ends (the issue's reference, ``band_span_tensions``) and, as a check of
   that reading, by the momentum balance of the whole driven arc (its contact forces' resultant); the friction
   coefficient along the driven arc.
2. The chain (``--model``, reference geometry, link stiffness times ``--link-factor``) runs from its quasi-static
   state at the band's clamping forces to ``--t-end`` (``--method``, ``--rtol``; states every 25 us saved to
   ``--states``, reused when the file exists): means of the span tensions over successive windows (the trend).
3. Over the second half of the run, per 6 degrees of the driven arc: normal force, tangential friction coefficient
   ``F_t / N``, tangential and radial slip of the pins; the link tension along the arc against the band's.
4. The arc balance of an inextensible band with uniform slip (the 6+2n band's steady state) and of the same band
   whose slip grows along the arc as the chain's does, by the stretch of its links and the radial travel of its pins
   under axial load (:func:`~cvtfem.elements.band.creep.creep_arc`): span tensions at the band's clamping force and
   torque.
Machine and wall times are printed; ``--png`` draws the trend, the tension and the friction along the driven arc.
"""
from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.elements.band.creep import creep_arc, driven_arc
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.integrate import solve
from cvtfem.machines import build_model
from cvtfem.machines.chain_cvt import band_span_tensions, from_scene
from cvtfem.scene.loader import load_scene

BIN = np.radians(6.0)      # angular bins along the driven arc, rad (about one pitch at r2 = 88 mm)


def band_scene(v0=None, open_loop=False):
    """The band-6+2n preset, with the friction law's saturation speed ``v0`` (m/s) and without the loops if asked."""
    scene = load_scene("band-6+2n")
    if v0 is not None:
        scene = scene.replace({"cvt": {"friction": {"v0": v0}}})
    return scene.replace({"cvt": {"effects": {"stabilisation": False}}}) if open_loop else scene


def band_reference(cache="", v0=None):
    """The band-6+2n preset after 1 s (its state read from / written to ``cache``): a dict with the clamping forces
    ``F`` (2,) N, the span tensions ``T_end`` (tight, slack) of ``band_span_tensions`` and the driven arc ``arc``
    (:func:`~cvtfem.elements.band.creep.driven_arc`)."""
    band = build_model(band_scene(v0))
    if cache and os.path.exists(cache):
        x = np.load(cache)
    else:
        res = solve(band, (0.0, 1.0), band.initial_state(), method="Radau", rtol=1e-6, atol=1e-8, n2=band.n2,
                    jac=band.jac, jac_sparsity=band.jac_sparsity)
        x = res.y[:, -1]
        if cache:
            os.makedirs(os.path.dirname(cache) or ".", exist_ok=True)
            np.save(cache, x)
    o = band.outputs(1.0, x)
    q, v, _, _ = band.split(x)
    return {"F": np.array([o["driving.clamping_force"], o["driven.clamping_force"]]),
            "T_end": band_span_tensions(band, x), "arc": driven_arc(band.model, q, v)}


def chain_model(model, F, link_factor=1.0, v0=None, open_loop=False):
    """The chain ``model`` on the sheaves with the band scene's values (:func:`band_scene`) and clamping forces ``F``
    (2,) N; link stiffness times ``link_factor``."""
    geom = reference_geometry()
    geom = replace(geom, c_plate=geom.c_plate * link_factor)
    contact = "rigid" if model == "chain-S1" else "hertz"
    return from_scene(band_scene(v0, open_loop), geom, F, model=model, contact=contact)


def chain_run(m, t_end, method, rtol, path):
    """States every 25 us of a run from the quasi-static state (``rtol``, atol ``1e-3 rtol``), ``(t, Y)``; saved to /
    read from ``path``."""
    if path and os.path.exists(path):
        d = np.load(path)
        return d["t"], d["y"]
    scene = load_scene("band-6+2n")
    x0, _ = m.static_state(scene.cvt.regime.ratio, scene.cvt.regime.input_speed)
    t_eval = np.linspace(0.0, t_end, int(round(t_end / 25e-6)) + 1)
    t0 = time.perf_counter()
    res = solve(m, (0.0, t_end), x0, method=method, rtol=rtol, atol=1e-3 * rtol, n2=m.n2, jac=m.jac,
                jac_sparsity=m.jac_sparsity, t_eval=t_eval)
    wall = time.perf_counter() - t0
    print(f"run 0..{t_end * 1e3:g} ms ({method}): status {res.status}, {res.stats['nsteps']} steps, wall {wall:.0f} s")
    if path:
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        np.savez(path, t=res.t, y=res.y)
    return res.t, res.y


def window_means(m, t, Y, width):
    """Rows ``[t_start, T_tight, T_slack, F1, ratio]`` of the means over successive windows of ``width`` s."""
    rows = []
    for a in np.arange(0.0, t[-1] - 1e-12, width):
        sel = np.nonzero((t >= a - 1e-12) & (t < a + width - 1e-12))[0]
        outs = [m.outputs(t[i], Y[:, i]) for i in sel]
        T = np.nanmean([o["chain.span_tension"] for o in outs], axis=0)
        rows.append([a, *T, np.mean([o["driving.clamping_force"] for o in outs]), np.mean([o["ratio"] for o in outs])])
    return np.array(rows)


def arc_profile(m, t, Y, t_from, shaft=1):
    """Along arc ``shaft`` (1 driven, 0 driving; angle from its axis, rad, negative at the entry, bins of
    :data:`BIN`) from ``t_from`` s on: bin centres and, per bin, mean link tension N, summed normal force per sample N,
    the tangential and radial friction coefficients ``F_t / N``, ``F_r / N`` (on the sheave, outwards > 0), the mean
    tangential and radial slip m/s of the pin ends in contact (radial: outwards > 0)."""
    edges = np.arange(-2.2, 2.2 + 1e-9, BIN)
    nb = len(edges) - 1
    acc, cnt, ten, tcnt = np.zeros((5, nb)), np.zeros(nb), np.zeros(nb), np.zeros(nb)
    nc, centre = m.family.size, m.contact.centres[shaft]
    side = -1.0 if shaft == 1 else 1.0                       # the driven arc lies at x < 0 of its centre
    samples = np.nonzero(t >= t_from)[0]
    for i in samples:
        q, v = Y[:m.n2, i], Y[m.n2:2 * m.n2, i]
        pins, shafts, X, _ = m._contacts(q, v)
        _, det = m.contact.local(X, shafts, details=True)
        s = (shafts == shaft) & (det["N"] > 0)
        arm = X[s, :2] - centre
        e_r = arm / np.linalg.norm(arm, axis=1)[:, None]
        e_t = np.column_stack([-e_r[:, 1], e_r[:, 0]])
        b = np.digitize(np.arctan2(side * arm[:, 1], side * arm[:, 0]), edges) - 1
        F_fr, w = det["F_fr"][s], det["slip"][s]
        for j, val in enumerate([det["N"][s], (F_fr[:, :2] * e_t).sum(1), (F_fr[:, :2] * e_r).sum(1),
                                 (w[:, :2] * e_t).sum(1), (w[:, :2] * e_r).sum(1)]):
            np.add.at(acc[j], b, val)
        np.add.at(cnt, b, 1)
        u = m.pin_positions(q[:nc])
        mid = 0.5 * (u + np.roll(u, -1, axis=0)) - centre
        T = m.family.outputs(q[:nc], v[:nc])[f"{m.family.name}.link_tension"]
        bl = np.digitize(np.arctan2(side * mid[:, 1], side * mid[:, 0]), edges) - 1
        ok = (bl >= 0) & (bl < nb)
        np.add.at(ten, bl[ok], T[ok])
        np.add.at(tcnt, bl[ok], 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (0.5 * (edges[1:] + edges[:-1]), ten / tcnt, acc[0] / len(samples), -acc[1] / acc[0],
                -acc[2] / acc[0], acc[3] / cnt, acc[4] / cnt)


def plot(trend, prof, band, creep, label, path):
    """Span tensions over the run, the link tension and the friction coefficient along the driven arc."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 10))
    ms = 1e3 * (trend[:, 0] + 0.5 * (trend[1, 0] - trend[0, 0]))
    for k, name in enumerate(("tight", "slack")):
        ax[0].plot(ms, trend[:, 1 + k] / band["T_end"][k] - 1, "o-", c=f"C{k}", label=f"{label}, {name} span")
        ax[0].axhline(creep["T"][k] / band["T_end"][k] - 1, c=f"C{k}", ls=":", label=f"creeping band, {name}")
    ax[0].axhline(0.0, c="k", lw=0.8)
    ax[0].set_ylabel("span tension / band 6+2n - 1")
    ax[0].set_xlabel("t, ms (window means)")
    deg, T, _, f, _, _, _ = prof
    arc = band["arc"]
    half = arc["args"]["wrap"] / 2
    on = np.abs(deg) <= half
    ax[1].plot(np.degrees(deg), T, "o", ms=3, label=f"{label}: mean link tension")
    ax[1].plot(np.degrees(arc["theta"] - half), arc["T_theta"], "-", label="band 6+2n: rho v^2 + 2 r N sin(gamma)")
    ax[1].plot(np.degrees(creep["theta"] - half), creep["T_theta"], ":",
               label="creeping band (the chain's link stretch and pin give)")
    ax[1].set_ylabel("tension, N")
    ax[2].plot(np.degrees(deg[on]), f[on], "o", ms=3, label=f"{label}: F_t / N of the pins")
    ax[2].plot(np.degrees(arc["theta"] - half), arc["f_theta"], "-", label="band 6+2n (uniform slip)")
    ax[2].plot(np.degrees(creep["theta"] - half), creep["f_theta"], ":", label="creeping band")
    ax[2].set_ylabel("tangential friction coefficient")
    for a in ax[1:]:
        a.set_xlabel("angle on the driven arc from its axis, deg (entry from the slack span < 0)")
    for a in ax:
        a.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=90)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="chain-S1")
    ap.add_argument("--t-end", type=float, default=0.08)
    ap.add_argument("--window", type=float, default=0.005)
    ap.add_argument("--link-factor", type=float, default=1.0)
    ap.add_argument("--method", default="rock4")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--states", default="")
    ap.add_argument("--band-cache", default="", help="the band's state after 1 s (.npy), written or read")
    ap.add_argument("--v0", type=float, default=None, help="saturation speed of the friction law, m/s (both models)")
    ap.add_argument("--open-loop", action="store_true", help="the chain without loops: the band's forces held")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    print(f"machine: {machine()}")
    band = band_reference(a.band_cache, a.v0)
    Te, Ta, args = band["T_end"], band["arc"]["T"], band["arc"]["args"]
    print(f"band 6+2n: F1 {band['F'][0]:.0f} N, F2 {band['F'][1]:.0f} N; spans tight/slack {Te[0]:.0f} / {Te[1]:.0f} N "
          f"(arc ends), {Ta[0]:.0f} / {Ta[1]:.0f} N (driven arc's momentum balance); tangential friction "
          f"coefficient on the driven arc {band['arc']['f_theta'].min():.4f}..{band['arc']['f_theta'].max():.4f}")
    m = chain_model(a.model, band["F"], a.link_factor, a.v0, a.open_loop)
    geom = m.family.geom
    EA, c_p = float(geom.c_link[0] * geom.L[0]), float(geom.c_pin[0])
    c_h = np.inf if a.model == "chain-S1" else float(m.contact.c[1])
    uniform = creep_arc(**args)["T"]
    cr = creep_arc(**args, EA=EA, c_pin=c_p, c_hertz=c_h, pitch=float(geom.L[0]))
    creep, slip = cr["T"], cr["slip"]
    print(f"arc balance, uniform slip: {uniform[0]:.0f} / {uniform[1]:.0f} N; slip growing with the chain's link "
          f"stretch (EA {EA:.3g} N) and pin give (c_p {c_p:.3g} N/m, Hertz {c_h:.3g}): {creep[0]:.0f} / "
          f"{creep[1]:.0f} N ({creep[0] / Te[0] - 1:+.2%} / {creep[1] / Te[1] - 1:+.2%}), slip {1e3 * slip[0]:.1f} -> "
          f"{1e3 * slip[1]:.1f} mm/s")
    t, Y = chain_run(m, a.t_end, a.method, a.rtol, a.states)
    trend = window_means(m, t, Y, a.window)
    label = a.model + (f" (links x{a.link_factor:g})" if a.link_factor != 1 else "")
    label += " (loops off)" if a.open_loop else ""
    print(f"{label}: span tensions over successive windows (deviation from the band's arc-end values)")
    for s, tt, ts, F1, ratio in trend:
        print(f"  {s * 1e3:5.1f}-{(s + a.window) * 1e3:5.1f} ms: tight {tt:6.0f} N ({tt / Te[0] - 1:+.2%}), slack "
              f"{ts:5.0f} N ({ts / Te[1] - 1:+.2%}), mean ({(tt + ts) / Te.sum() - 1:+.2%}), F1 {F1:.0f} N, "
              f"ratio {ratio:.4f}")
    prof = arc_profile(m, t[::2], Y[:, ::2], t[-1] / 2)
    deg, T, N, f, _, wt, wr = prof
    print("driven arc, second half of the run: angle deg, link tension N, normal force N, F_t/N, slip t/r mm/s")
    for j in np.nonzero(np.isfinite(f) & (np.abs(deg) <= args["wrap"] / 2 + BIN))[0]:
        print(f"  {np.degrees(deg[j]):6.0f} {T[j]:7.0f} {N[j]:7.0f} {f[j]:+.4f} {1e3 * wt[j]:+8.1f} "
              f"{1e3 * wr[j]:+8.1f}")
    if a.png:
        plot(trend, prof, band, cr, label, a.png)


if __name__ == "__main__":
    main()
