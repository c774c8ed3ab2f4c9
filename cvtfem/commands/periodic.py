"""``cvtfem periodic SCENE``: periodic response of a torsional network by harmonic balance."""
from __future__ import annotations

import argparse


def _sweep(text: str) -> tuple[float, float, int]:
    from cvtfem.errors import InputError

    try:
        a, b, n = text.split(":")
        out = (float(a), float(b), int(n))
    except ValueError:
        raise InputError("--sweep", text, "must be START:STOP:POINTS in Hz, e.g. 8:16:33 (16:8:33 sweeps down)") \
            from None
    if not (0 < out[0] < float("inf") and 0 < out[1] < float("inf") and out[0] != out[1] and out[2] >= 2):
        raise InputError("--sweep", text, "needs positive START != STOP (Hz; START > STOP sweeps down) "
                         "and POINTS >= 2")
    return out


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("periodic", help="periodic response of a torsional network (harmonic balance)")
    p.add_argument("scene", metavar="SCENE", help="scene file (.toml) or preset name")
    p.add_argument("--harmonics", type=int, metavar="N", help="number of harmonics (default: scene)")
    p.add_argument("--sweep", metavar="A:B:N",
                   help="cycle-frequency sweep in Hz from A to B (either direction), followed through folds "
                        "by arclength continuation (default: scene)")
    p.add_argument("--no-backlash", action="store_true", help="contact stiffness everywhere")
    p.add_argument("--no-stability", action="store_true",
                   help="skip the Floquet multipliers of each point (they cost one period of the variational "
                        "equations per point)")
    p.add_argument("--json", metavar="OUT", help="write per-point harmonics, link peaks/RMS and stability")
    p.add_argument("--csv", metavar="OUT", help="write one row per point: frequency, flags, stability, amplitudes")
    p.add_argument("--png", metavar="OUT", help="plot frequency response and moments over one period")
    p.set_defaults(func=run)


def write_csv(result, probe: int, path: str) -> None:
    """One row per reported point, in arclength order (amplitudes: half peak-to-peak, m)."""
    import csv

    import numpy as np

    net = result.nonlinear[0].network
    pk_nl, pk_lin = result.peaks("nonlinear")[:, probe], result.peaks("linear")[:, probe]
    amp = result.amplitudes()
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["frequency_hz", "omega_rad_s", "requested", "turning_point", "stable", "floquet_max_modulus",
                    "peak_moment_backlash_Nm", "peak_moment_no_backlash_Nm"] + [f"amplitude_{n}_m" for n in net.names])
        for k, f in enumerate(result.omega):
            fm = result.floquet_max[k]
            w.writerow([float(f / (2 * np.pi)), float(f), int(result.requested[k]), int(result.turning[k]),
                        "" if np.isnan(fm) else int(fm < 1), "" if np.isnan(fm) else float(fm),
                        float(pk_nl[k]), float(pk_lin[k])] + amp[k].tolist())


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
    result = response_sweep(net, 2 * np.pi * freqs, N, cfg.samples, cfg.tol, cfg.max_iter, backlash,
                            stability=not args.no_stability)
    nl_links = np.flatnonzero(net.law != 0)
    probe = (net.link_names.index(cfg.probe) if cfg.probe else int(nl_links[0]) if nl_links.size else 0)
    pk_nl, pk_lin = result.peaks("nonlinear")[:, probe], result.peaks("linear")[:, probe]
    print(f"{scene.title or scene.source}: {net.n_nodes} disks, {net.n_links} links "
          f"({nl_links.size} nonlinear), N = {N} harmonics, probe link `{net.link_names[probe]}`")
    print(f"{'f, Hz':>10} {'point':>6} {'iter':>5} {'peak M (backlash)':>18} {'peak M (none)':>14} {'ratio':>6}"
          f"  {'max|Floquet|':>12}")
    for k, f in enumerate(result.omega / (2 * np.pi)):
        kind = "fold" if result.turning[k] else ""
        fm = result.floquet_max[k]
        stab = "" if np.isnan(fm) else f"{fm:12.4f} ({'stable' if fm < 1 else 'UNSTABLE'})"
        print(f"{f:10.5f} {kind:>6} {result.nonlinear[k].iterations:5d} {pk_nl[k]:18.2f} {pk_lin[k]:14.2f} "
              f"{pk_nl[k] / pk_lin[k]:6.2f}  {stab}")
    br = result.branch
    folds = ", ".join(f"{w / (2 * np.pi):.5f}" for w in br.fold_omega) or "none"
    print(f"arclength continuation: {br.steps} steps ({br.rejected} rejected), {len(br.solutions)} points, "
          f"folds at {folds} Hz, wall time {result.wall:.3f} s")
    for text in result.warnings:
        print(f"cvtfem periodic: warning: {text}", file=sys.stderr)
    if args.json:
        data = result.to_dict()
        data["probe"] = net.link_names[probe]
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=1, allow_nan=False)
        print(f"wrote {args.json}")
    if args.csv:
        write_csv(result, probe, args.csv)
        print(f"wrote {args.csv}")
    if args.png:
        from cvtfem.post.periodic import plot_summary

        plot_summary(result, probe, args.png)
        print(f"wrote {args.png}")
    return 0
