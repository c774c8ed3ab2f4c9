"""``cvtfem periodic SCENE``: periodic response of a torsional network by harmonic balance."""
from __future__ import annotations

import argparse


def _sweep(text: str) -> tuple[float, float, int]:
    from cvtfem.errors import InputError

    try:
        a, b, n = text.split(":")
        out = (float(a), float(b), int(n))
    except ValueError:
        raise InputError("--sweep", text, "must be START:STOP:POINTS in Hz, e.g. 8:16:33") from None
    if not (0 < out[0] < out[1] and out[2] >= 2):
        raise InputError("--sweep", text, "needs 0 < START < STOP (Hz) and POINTS >= 2")
    return out


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("periodic", help="periodic response of a torsional network (harmonic balance)")
    p.add_argument("scene", metavar="SCENE", help="scene file (.toml) or preset name")
    p.add_argument("--harmonics", type=int, metavar="N", help="number of harmonics (default: scene)")
    p.add_argument("--sweep", metavar="A:B:N", help="cycle-frequency sweep in Hz (default: scene)")
    p.add_argument("--no-backlash", action="store_true", help="contact stiffness everywhere")
    p.add_argument("--stability", action="store_true", help="Floquet multipliers of each solution")
    p.add_argument("--json", metavar="OUT", help="write per-frequency harmonics and link peaks/RMS")
    p.add_argument("--png", metavar="OUT", help="plot frequency response and moments over one period")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import json
    import sys

    import numpy as np

    from cvtfem.errors import InputError
    from cvtfem.machines.torsional import build, periodic_settings
    from cvtfem.periodic.response import response_sweep
    from cvtfem.scene.loader import load_scene
    from cvtfem.scene.schema.torsional import MAX_HARMONICS

    scene = load_scene(args.scene)
    if scene.kind != "torsional":
        raise InputError("SCENE", args.scene, f"must describe a torsional network, not a {scene.kind}")
    cfg = periodic_settings(scene)
    N = cfg.harmonics if args.harmonics is None else args.harmonics
    if not 1 <= N <= MAX_HARMONICS:
        raise InputError("--harmonics", N, f"must be a whole number in 1..{MAX_HARMONICS} (the Newton blocks grow "
                         f"as (2N+1)^2 per node: {N} harmonics would need {8 * (2 * N + 1) ** 2 / 1e9:.3g} GB each)")
    if args.sweep:
        a, b, n = _sweep(args.sweep)
        freqs = np.linspace(a, b, n)
    elif cfg.sweep:
        freqs = np.linspace(cfg.sweep[0], cfg.sweep[1], int(cfg.sweep[2]))
    else:
        freqs = np.array([cfg.frequency])
    net = build(scene)
    backlash = cfg.backlash and not args.no_backlash
    result = response_sweep(net, 2 * np.pi * freqs, N, cfg.samples, cfg.tol, cfg.max_iter, backlash)
    nl_links = np.flatnonzero(net.law != 0)
    probe = (net.link_names.index(cfg.probe) if cfg.probe else int(nl_links[0]) if nl_links.size else 0)
    pk_nl, pk_lin = result.peaks("nonlinear")[:, probe], result.peaks("linear")[:, probe]
    print(f"{scene.title or scene.source}: {net.n_nodes} disks, {net.n_links} links "
          f"({nl_links.size} nonlinear), N = {N} harmonics, probe link `{net.link_names[probe]}`")
    print(f"{'f, Hz':>8} {'conv':>5} {'iter':>5} {'peak M (backlash)':>18} {'peak M (none)':>14} {'ratio':>6}"
          + ("  max|Floquet|" if args.stability else ""))
    data = result.to_dict()
    n_fail = 0
    for k, (f, sol) in enumerate(zip(freqs, result.nonlinear)):
        n_fail += not sol.converged
        line = (f"{f:8.3f} {'yes' if sol.converged else 'NO':>5} {sol.iterations:5d} {pk_nl[k]:18.2f} "
                f"{pk_lin[k]:14.2f} {pk_nl[k] / pk_lin[k]:6.2f}")
        if args.stability and sol.converged:
            from cvtfem.periodic.stability import floquet

            fl = floquet(sol)
            data["points"][k]["backlash"]["floquet_max_modulus"] = fl.spectral_radius
            line += f"  {fl.spectral_radius:.4f} ({'stable' if fl.stable else 'UNSTABLE'})"
        print(line)
        if not sol.converged:
            print(f"         {sol.message}")
    print(f"harmonic balance wall time {result.wall:.3f} s for {len(freqs)} frequencies")
    if args.json:
        data["probe"] = net.link_names[probe]
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=1, allow_nan=True)
        print(f"wrote {args.json}")
    if args.png:
        from cvtfem.post.periodic import plot_summary

        plot_summary(result, probe, args.png)
        print(f"wrote {args.png}")
    if n_fail:
        first = next(sol.message for sol in result.nonlinear if not sol.converged)
        print(f"cvtfem periodic: error: harmonic balance did not converge at {n_fail} of {len(freqs)} frequencies "
              f"(first: {first})", file=sys.stderr)
        return 3
    return 0
