"""H1 against H2: the chain S3 (or S2) on two rigid sheaves at the stationary regime with either pin-sheave contact.

Run:  .venv/bin/python studies/chain/h1_h2_compare.py [--model chain-S3] [--t-end 0.004] [--window 0.002]
      [--clamping 29700 35500]        # -> out/studies/chain/h1_h2_compare.txt

The band-6+2n scene values (3500 rpm, 200 N m, ratio 2.4, tanh law, v0 0.02 m/s) with the clamping forces per
sheave the band model settles at (docs/chain.md, "The chain on two sheaves": 29.7 and 35.5 kN), the
reference chain (84 pins), both contacts from their own quasi-static start, Radau (rtol 1e-3, atol 1e-6),
outputs every 25 us.  Means over the last ``window``: contact radius (H1: the pin end; H2: the contact point
R_*) and the pin end radius, normal force per loaded pin end, pin axial force of the pins on each arc, pin
bending moment (S3), span tensions, sheave axial force over clamping force, friction power, slip, ratio,
efficiency; the wall time per simulated ms, machine named.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.integrate import solve
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/chain")
RATIO = 2.4


def run(model: str, contact: str, F, t_end: float, window: float) -> dict:
    """Run one contact model; means over the window."""
    scene = load_scene("band-6+2n")
    m = from_scene(scene, reference_geometry(), np.asarray(F, float), model=model, contact=contact)
    x0, rep = m.static_state(RATIO, scene.cvt.regime.input_speed)
    t0 = time.perf_counter()
    res = solve(m, (0.0, t_end), x0, method="Radau", rtol=1e-3, atol=1e-6, n2=m.n2, jac=m.jac,
                jac_sparsity=m.jac_sparsity, t_eval=np.arange(t_end - window, t_end + 1e-12, 25e-6))
    wall = time.perf_counter() - t0
    if res.status != 0:
        raise RuntimeError(f"{contact}: {res.message}")
    n = m.family.n
    acc: dict[str, list] = {}

    def add(key, value):
        acc.setdefault(key, []).append(value)
    for t, x in zip(res.t, res.y.T):
        o = m.outputs(t, x)
        q, v = x[:m.n2], x[m.n2:2 * m.n2]
        pins, shafts, _, (_, d) = m._contacts(q, v, details=True)
        u = m.family.split(q[:m.family.size])[0]
        N = o["contact.normal_force"].reshape(n, 2)
        rad = o["contact.radius"].reshape(n, 2)
        axial = o["chain.pin_axial_force"]
        for k in (0, 1):
            on = N[:, k] > 0
            add(f"radius{k}", rad[on, k].mean())
            add(f"end_radius{k}", np.linalg.norm(u[on] - m.contact.centres[k], axis=1).mean())
            add(f"N{k}", N[on, k].mean())
            add(f"Nmax{k}", N[on, k].max())
            add(f"axial{k}", axial[on].mean())
            if "chain.pin_bending_moment" in o:
                add(f"bend{k}", np.abs(o["chain.pin_bending_moment"].reshape(n, 2)[on]).max(axis=1).mean())
            sel = (shafts == k) & (d["N"] > 0)
            add(f"slip{k}", float((d["N"][sel] * np.linalg.norm(d["slip"][sel], axis=1)).sum() / d["N"][sel].sum()))
        add("span", o["chain.span_tension"])
        add("balance", o["contact.sheave_axial_force"] / [o["driving.clamping_force"], o["driven.clamping_force"]] - 1)
        add("friction", o["contact.friction_power"].sum())
        add("ratio", o["ratio"])
        add("power", o["power"][:2])
    mean = {k: np.nanmean(np.array(v, float), axis=0) for k, v in acc.items()}
    mean["efficiency"] = mean["power"][1] / mean["power"][0]
    mean["wall_per_ms"] = wall / (t_end * 1e3)
    mean["start"] = rep
    return mean


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="chain-S3", choices=("chain-S2", "chain-S3"))
    ap.add_argument("--t-end", type=float, default=4e-3)
    ap.add_argument("--window", type=float, default=2e-3)
    ap.add_argument("--clamping", type=float, nargs=2, default=(29700.0, 35500.0))
    a = ap.parse_args()
    res = {c: run(a.model, c, a.clamping, a.t_end, a.window) for c in ("hertz", "hertz-refined")}
    rows = [("contact radius, driving / driven (mm)", lambda r: (1e3 * r["radius0"], 1e3 * r["radius1"])),
            ("pin end radius, driving / driven (mm)", lambda r: (1e3 * r["end_radius0"], 1e3 * r["end_radius1"])),
            ("mean normal force per pin end (N)", lambda r: (r["N0"], r["N1"])),
            ("largest normal force (N)", lambda r: (r["Nmax0"], r["Nmax1"])),
            ("mean pin axial force on the arc (N)", lambda r: (r["axial0"], r["axial1"])),
            ("force-weighted slip speed (m/s)", lambda r: (r["slip0"], r["slip1"])),
            ("span tension tight / slack (N)", lambda r: tuple(r["span"])),
            ("sheave axial / clamping force - 1 (%)", lambda r: tuple(100 * r["balance"]))]
    if a.model == "chain-S3":
        rows.append(("mean largest pin bending moment on the arc (N m)", lambda r: (r["bend0"], r["bend1"])))
    lines = [f"{a.model} on two rigid sheaves, 3500 rpm, 200 N m, ratio {RATIO}, clamping {a.clamping} N per sheave; "
             f"means over {1e3 * (a.t_end - a.window):.1f}-{1e3 * a.t_end:.1f} ms",
             f"machine: {machine()}", "", f"{'':52s}{'H1 (hertz)':>26s}{'H2 (hertz-refined)':>26s}"]
    for name, f in rows:
        h1, h2 = f(res["hertz"]), f(res["hertz-refined"])
        lines.append(f"{name:52s}" + "".join(f"{v:>13.5g}" for v in h1) + "".join(f"{v:>13.5g}" for v in h2))
    for name, key in (("friction power (W)", "friction"), ("speed ratio", "ratio"), ("efficiency", "efficiency"),
                      ("wall time per simulated ms (s)", "wall_per_ms")):
        lines.append(f"{name:52s}{res['hertz'][key]:>26.6g}{res['hertz-refined'][key]:>26.6g}")
    for c in res:
        s = res[c]["start"]
        lines.append(f"start {c}: residual {s['residual']:.1e}, F1 {s['F1']:.0f} N, tension {s['tension']:.0f} N, "
                     f"{s['nfev']} evaluations")
    text = "\n".join(lines)
    print(text)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "h1_h2_compare.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
