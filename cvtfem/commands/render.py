"""``cvtfem render SCENE [--mode K] --png OUT``: off-screen rendering of a rotor or one of its modes, or of a
chain transmission in its start state."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a rotor scene or a mode shape, or a chain transmission, off-screen "
                       "(PNG, GIF, VTU)")
    p.add_argument("scene", metavar="SCENE", help="rotor or chain-CVT scene file (.toml) or preset name")
    p.add_argument("--mode", type=int, help="mode index (ascending damped frequency); omit for the geometry")
    p.add_argument("--speed", help="spin speed with unit (default [rotor].speed)")
    p.add_argument("--scale", type=float, help="displacement scale (default: 8 %% of the shaft length)")
    p.add_argument("--color", default="chain.link_tension",
                   help="chain transmission: output colouring the links (per link, per pin, or per pin end and shaft)")
    p.add_argument("--png", metavar="OUT", help="PNG file")
    p.add_argument("--gif", metavar="OUT", help="animated GIF of the mode over one period")
    p.add_argument("--vtu", metavar="OUT", help="VTU file (meshio) with all computed modes for ParaView")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.commands.modes import load_rotor
    from cvtfem.errors import InputError

    if not (args.png or args.gif or args.vtu):
        raise InputError("--png/--gif/--vtu", None, "needs at least one output file")
    from cvtfem.scene.loader import load_scene

    if load_scene(args.scene).kind == "cvt":
        return _render_chain(args)
    scene, model = load_rotor(args.scene)
    from cvtfem.render import rotor as r

    if args.mode is None:
        if args.gif or args.vtu:
            raise InputError("--mode", None, "is required for --gif and --vtu")
        print(f"wrote {r.render_rotor(model, args.png)}")
        return 0
    from cvtfem.modal import ModalProblem
    from cvtfem.units import parse_speed

    if args.mode < 0:
        raise InputError("--mode", args.mode, "must be >= 0")
    speed = parse_speed(args.speed) if args.speed else (scene.rotor.speed if scene.rotor else 0.0)
    modes = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind,
                         speed_terms=model.speed_terms).solve(speed, args.mode + 1)
    k = args.mode
    print(f"mode {k}: wd = {modes.wd[k]:.6g} rad/s, {modes.whirl[k]}")
    if args.png:
        print(f"wrote {r.render_mode(model, modes, k, args.png, args.scale)}")
    if args.gif:
        print(f"wrote {r.write_mode_gif(model, modes, k, args.gif, scale=args.scale)}")
    if args.vtu:
        print(f"wrote {r.write_mode_vtu(model, modes, args.vtu)}")
    return 0


def _render_chain(args: argparse.Namespace) -> int:
    """The chain transmission of a CVT scene in its start state (the quasi-static state on the sheaves)."""
    from cvtfem.errors import InputError
    from cvtfem.machines.cvt import chain_loop
    from cvtfem.render.transmission import check_colour, render_transmission
    from cvtfem.scene.loader import load_scene

    for name in ("mode", "gif", "vtu", "speed", "scale"):
        if getattr(args, name) is not None:
            raise InputError(f"--{name}", getattr(args, name), "is for rotor scenes; a chain transmission renders "
                             "its start state to --png")
    model = chain_loop(load_scene(args.scene))
    check_colour(model, args.color)
    x0, report = model.start()
    path = render_transmission(model, x0, args.png, color_by=args.color,
                               title=f"{args.scene}: start state ({report['kind']}), links coloured by {args.color}")
    print(f"wrote {path}")
    return 0
