"""``cvtfem sheave SCENE [--disk I] [--diameters N] [--modes K] [--speed S] [--load F] [--json OUT] [--png OUT]``:
modes of a rotor scene's sheave as a solid body, per nodal diameter (spinning: forward and backward travelling
waves, Coriolis-coupled), and the wedge opening under a ring load."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sheave", help="solid sheave of a rotor scene: modes per nodal diameter, wedge opening")
    p.add_argument("scene", metavar="SCENE", help="rotor scene file (.toml) or preset name with a sheave [[disk]]")
    p.add_argument("--disk", type=int, help="index of the [[disk]] (default: the first sheave)")
    p.add_argument("--diameters", type=int, default=4, help="nodal diameters 0..N (default 4)")
    p.add_argument("--modes", type=int, default=2, help="modes per nodal diameter (default 2)")
    p.add_argument("--speed", help="spin speed with unit, e.g. 6000rpm (default 0)")
    p.add_argument("--load", type=float, help="clamping ring load at the rim, N (pushes the face back): prints the "
                                              "wedge opening")
    p.add_argument("--mesh", default="24,2", help="section cells NR,NZ (default 24,2)")
    p.add_argument("--mode", default="2,0", help="mode drawn by --png: N,K (nodal diameters, index; default 2,0)")
    p.add_argument("--json", metavar="OUT", help="write the spectrum (and the opening) as JSON")
    p.add_argument("--png", metavar="OUT", help="render the --mode shape (and OUT with _load before the suffix "
                                                "for --load)")
    p.set_defaults(func=run)


def _pair(text: str, where: str, low: tuple[int, int], high: tuple[int, int]) -> tuple[int, int]:
    from cvtfem.errors import InputError

    try:
        a, b = (int(v) for v in text.split(","))
    except ValueError:
        raise InputError(where, text, "must be two integers A,B") from None
    if not (low[0] <= a <= high[0] and low[1] <= b <= high[1]):
        raise InputError(where, text, f"must lie within {low[0]}..{high[0]}, {low[1]}..{high[1]}")
    return a, b


def own_waves(scene, speeds):  # noqa: ANN001, ANN201 - Scene, array -> list of (label, array)
    """Fixed-frame Hz over ``speeds`` (rad/s) of the own waves (n = 2..[sheave].diameters, those beyond
    ``model_diameters``: the rotor model solves the others) of each flexible sheave of a rotor scene, labelled
    ``"disk I sheave n=2 fw"``; none when the sheaves are rigid."""
    if scene.sheave is None or scene.sheave.flexibility == "rigid":
        return []
    from cvtfem.machines.sheave import sheave_indices, sheave_section
    from cvtfem.modal.sheave import sheave_waves

    opts, out = scene.sheave, []
    for i in sheave_indices(scene):
        lines = sheave_waves(sheave_section(scene, i), opts.diameters, speeds, (opts.cells_radial, opts.cells_axial),
                             first=opts.model_diameters + 1)
        out += [(f"disk {i} {label}", hz) for label, hz in lines]
    return out


def run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from cvtfem.commands.modes import load_rotor
    from cvtfem.machines.sheave import sheave_section
    from cvtfem.modal.sheave import MAX_DIAMETERS, MAX_MODES, mode_shape, sheave_spectrum, wedge_opening
    from cvtfem.units import parse_speed

    scene, _ = load_rotor(args.scene)
    section = sheave_section(scene, args.disk)
    mesh = _pair(args.mesh, "--mesh", (4, 1), (400, 40))
    n_draw, k_draw = _pair(args.mode, "--mode", (0, 0), (MAX_DIAMETERS, MAX_MODES - 1))
    speed = parse_speed(args.speed) if args.speed else 0.0
    rows = sheave_spectrum(section, args.diameters, args.modes, speed, mesh)
    print(f"{scene.title or scene.source}: sheave of outer diameter {2e3 * section.outer_radius:.0f} mm, "
          f"bore clamped, {args.diameters + 1} nodal diameters at {speed:g} rad/s")
    print(f"  {'n':>3} {'wave':<9} {'rotating Hz':>12} {'fixed-frame Hz':>15}")
    for r in rows:
        print(f"  {r['n']:>3} {r['wave']:<9} {r['rotating_hz']:12.1f} {r['fixed_hz']:15.1f}")
    out = {"scene": scene.source, "speed_rad_s": speed, "modes": rows}
    if args.load is not None:
        model, u = wedge_opening(section, args.load, mesh)
        out["rim_opening_m"] = -model.rim_mean(u)
        print(f"the rim moves back by {-model.rim_mean(u) * 1e6:.2f} um under a {args.load:g} N ring load "
              "(per sheave: the wedge opens by the sum of both sheaves')")
    if args.json:
        Path(args.json).write_text(json.dumps(out))
        print(f"wrote {args.json}")
    if args.png:
        from cvtfem.render.sheave import render_sheave

        family = "cos"
        model, shape, f = mode_shape(section, n_draw, family, k_draw, mesh)
        print(f"wrote {render_sheave(model, shape, args.png, f'n = {n_draw}, mode {k_draw} at rest: {f:.1f} Hz')}")
        if args.load is not None:
            png = Path(args.png)
            load_png = png.with_name(f"{png.stem}_load{png.suffix}")
            model, u = wedge_opening(section, args.load, mesh)
            print(f"wrote {render_sheave(model, u, load_png, f'ring load {args.load:g} N at the rim')}")
    return 0
