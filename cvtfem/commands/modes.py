"""``cvtfem modes SCENE [--speed 4000rpm] [--json OUT]``: natural frequencies of a rotor."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("modes", help="natural frequencies, damping and whirl of a rotor scene at one speed")
    p.add_argument("scene", metavar="SCENE", help="rotor scene file (.toml) or preset name")
    p.add_argument("--speed", help="spin speed with unit (4000rpm, 420rad/s, 50Hz); default [rotor].speed")
    p.add_argument("--n-modes", type=int, help="number of modes (default [rotor].n_modes)")
    p.add_argument("--method", default="auto", choices=("auto", "dense", "sparse", "slepc"),
                   help="eigen-solver backend")
    p.add_argument("--undamped", action="store_true", help="ignore damping matrices")
    p.add_argument("--json", metavar="OUT", help="write the modes as JSON")
    p.add_argument("--shapes", action="store_true", help="include the mode shapes (per node, 6 DOF) in the JSON")
    p.set_defaults(func=run)


def load_rotor(spec: str):
    """Scene -> (scene, RotorModel); InputError unless it is a rotor scene."""
    from cvtfem.errors import InputError
    from cvtfem.machines.rotor import build_model
    from cvtfem.scene.loader import load_scene

    scene = load_scene(spec)
    if scene.kind != "rotor":
        raise InputError("SCENE", spec, f"must be a rotor scene ([[shaft]] tables), this one is {scene.kind!r}")
    return scene, build_model(scene)


def run(args: argparse.Namespace) -> int:
    import json

    import numpy as np

    from cvtfem.errors import InputError
    from cvtfem.modal import ModalProblem
    from cvtfem.units import parse_speed

    scene, model = load_rotor(args.scene)
    opts = scene.rotor
    speed = parse_speed(args.speed) if args.speed else (opts.speed if opts else 0.0)
    n_modes = args.n_modes or (opts.n_modes if opts else 12)
    if n_modes < 1:
        raise InputError("--n-modes", n_modes, "must be >= 1")
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, args.method,
                           damped=not args.undamped, speed_terms=model.speed_terms)
    modes = problem.solve(speed, n_modes)
    print(f"{scene.title or scene.source}: {model.n_dof} DOF, speed {speed:.6g} rad/s "
          f"({speed * 30 / np.pi:.6g} rpm), backend {problem.method}")
    print(f"  {'#':>3} {'wn rad/s':>12} {'wd rad/s':>12} {'wd Hz':>10} {'zeta':>10} {'log dec':>10}  whirl")
    share, diameters = model.sheave_share(modes.shapes)
    for i in range(len(modes.wd)):
        sheave = f" (sheave n={diameters[i]}: {100 * share[i]:.0f} % of the strain energy)" if share[i] > 0.5 else ""
        print(f"  {i:>3} {modes.wn[i]:>12.6g} {modes.wd[i]:>12.6g} {modes.wd[i] / (2 * np.pi):>10.5g} "
              f"{modes.damping_ratio[i]:>10.3g} {modes.log_dec[i]:>10.3g}  {modes.whirl[i]}{sheave}")
    from cvtfem.commands.sheave import own_waves

    waves = own_waves(scene, np.array([speed]))
    for label, hz in waves:
        print(f"  {label:<24} {hz[0]:>10.5g} Hz  (the sheave's own wave: not coupled with the shaft)")
    if args.json:
        if model.extra_kinds:                 # shapes per node: the sheaves' modal coordinates are left out
            from dataclasses import replace

            modes = replace(modes, shapes=modes.shapes[:model.n_node_dofs])
        with open(args.json, "w") as fh:
            json.dump({"scene": scene.source, "backend": problem.method, **modes.to_dict(shapes=args.shapes),
                       "sheave_waves": [{"label": lab, "hz": float(hz[0])} for lab, hz in waves]}, fh, indent=1)
        print(f"wrote {args.json}")
    return 0
