"""``cvtfem render SCENE [--mode K] --png OUT``: off-screen rendering of a rotor or one of its modes, or of a
chain transmission in its start state; ``cvtfem render RESULTS.h5 [--time T] --png OUT``, ``--gif/--mp4 OUT``,
``--vtu DIR`` with ``--window T0 T1``: stills, animations and VTU time series of a chain-CVT run."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="render a rotor scene or a mode shape, or a chain transmission, off-screen "
                       "(PNG, GIF, VTU)")
    p.add_argument("scene", metavar="SCENE", help="rotor or chain-CVT scene file (.toml) or preset name, or the "
                   "results file (.h5) of a chain-CVT run")
    p.add_argument("--mode", type=int, help="mode index (ascending damped frequency); omit for the geometry")
    p.add_argument("--speed", help="spin speed with unit (default [rotor].speed)")
    p.add_argument("--scale", type=float, help="rotor: displacement scale (default: 8 %% of the shaft length); "
                   "results file: axial positions exaggerated by this factor about the first row (default 1)")
    p.add_argument("--color", default="chain.link_tension",
                   help="chain transmission: output colouring the chain (per link, per plate: the plates drawn, per "
                   "pin, per pin half, or per pin end and shaft)")
    p.add_argument("--zoom", type=float, help="chain transmission: camera zoom over the whole transmission "
                   "(default 1)")
    p.add_argument("--look-at", type=float, nargs=2, metavar=("X1", "X2"), help="chain transmission: chain-plane "
                   "point the camera aims at, m (the driven shaft at the origin, the driving one at (L, 0); default "
                   "the transmission's centre)")
    p.add_argument("--png", metavar="OUT", help="PNG file")
    p.add_argument("--gif", metavar="OUT", help="animated GIF of the mode over one period, or of a run's window")
    p.add_argument("--mp4", metavar="OUT", help="results file: MP4 of the window (needs imageio-ffmpeg)")
    p.add_argument("--vtu", metavar="OUT", help="VTU file (meshio) with all computed modes for ParaView; results "
                   "file: a directory for a VTU time series of the window (chain.pvd, sheaves.pvd)")
    p.add_argument("--time", type=float, metavar="T", help="results file: time of the still, s (the nearest "
                   "stored row is drawn; default the last)")
    p.add_argument("--window", type=float, nargs=2, metavar=("T0", "T1"),
                   help="results file: time window of --gif/--mp4/--vtu, s (default: every stored row)")
    p.add_argument("--fps", type=float, default=10.0, help="results file: frames per second of --gif/--mp4")
    p.add_argument("--frames", type=int, help="results file: frames of the window (the rows nearest equally "
                   "spaced times; default every stored row)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.commands.modes import load_rotor
    from cvtfem.errors import InputError

    if not (args.png or args.gif or args.vtu or args.mp4):
        raise InputError("--png/--gif/--mp4/--vtu", None, "needs at least one output file")
    if _is_results_file(args.scene):
        return _render_run(args)
    for name in ("time", "window", "frames", "mp4"):
        if getattr(args, name) is not None:
            raise InputError(f"--{name}", getattr(args, name), "is for the results file (.h5) of a chain-CVT run")
    from cvtfem.scene.loader import load_scene

    if load_scene(args.scene).kind == "cvt":
        return _render_chain(args)
    for name in ("zoom", "look_at"):
        if getattr(args, name) is not None:
            raise InputError(f"--{name.replace('_', '-')}", getattr(args, name), "is for chain transmissions")
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


def _view(args: argparse.Namespace):
    """The camera of ``--zoom`` and ``--look-at`` (InputError for a zoom that is not positive and finite, or a
    point that is not finite)."""
    import math

    from cvtfem.errors import InputError
    from cvtfem.render.transmission import View

    zoom = 1.0 if args.zoom is None else args.zoom
    if not (math.isfinite(zoom) and zoom > 0):
        raise InputError("--zoom", args.zoom, "must be a positive, finite zoom factor")
    if args.look_at is not None and not all(math.isfinite(v) for v in args.look_at):
        raise InputError("--look-at", args.look_at, "must be two finite coordinates x1 x2, m")
    return View(zoom, None if args.look_at is None else tuple(args.look_at))


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
    view = _view(args)
    x0, report = model.start()
    path = render_transmission(model, x0, args.png, color_by=args.color, view=view,
                               title=f"{args.scene}: start state ({report['kind']}), coloured by {args.color}")
    print(f"wrote {path}")
    return 0


def _is_results_file(spec: str) -> bool:
    """True for an existing file that starts with the HDF5 signature (a results file, whatever its suffix)."""
    from pathlib import Path

    from cvtfem.io.results import HDF5_SIGNATURE

    path = Path(spec)
    if not path.is_file():
        return spec.endswith(".h5")      # a missing results file: read_results names it
    with open(path, "rb") as f:
        return f.read(8) == HDF5_SIGNATURE


def _render_run(args: argparse.Namespace) -> int:
    """A chain-CVT results file: the still at --time, the window as GIF/MP4 and as a VTU time series."""
    from cvtfem.errors import InputError
    from cvtfem.render.run_frames import check_animation, render_row, write_animation
    from cvtfem.render.vtk_series import write_vtu_series

    for name in ("mode", "speed"):
        if getattr(args, name) is not None:
            raise InputError(f"--{name}", getattr(args, name), "is for rotor scenes, not for a results file")
    scale = 1.0 if args.scale is None else args.scale
    if not (scale == scale and abs(scale) != float("inf") and scale > 0):
        raise InputError("--scale", args.scale, "must be a positive, finite exaggeration factor")
    view = _view(args)
    run = open_run(args.scene)
    if args.time is not None and not args.png:
        raise InputError("--time", args.time, "is the time of the --png still (animations take --window)")
    animated = args.gif or args.mp4 or args.vtu
    if not animated and (args.window is not None or args.frames is not None):
        raise InputError("--window/--frames", args.window or args.frames, "is for --gif, --mp4 or --vtu")
    row = run.row_at(run.time[-1] if args.time is None else args.time)
    if animated:
        t0, t1 = args.window if args.window is not None else (run.time[0], run.time[-1])
        rows = run.rows_in(t0, t1, args.frames)
    run.check_colour(args.color)
    for option, path in (("--gif", args.gif), ("--mp4", args.mp4)):
        if path:
            check_animation(path, args.fps, option)
    if args.png:
        asked = "" if args.time is None else f" (nearest to --time {args.time:g} s)"
        path = render_row(run, row, args.png, args.color, scale, view=view)
        print(f"wrote {path}: t = {run.time[row]:.9g} s, row {row}{asked}")
    if not animated:
        return 0
    span = f"{len(rows)} frames, t = {run.time[rows[0]]:.9g} .. {run.time[rows[-1]]:.9g} s"
    for option, path in (("--gif", args.gif), ("--mp4", args.mp4)):
        if path:
            print(f"wrote {write_animation(run, rows, path, args.color, scale, args.fps, option, view=view)}: {span}")
    if args.vtu:
        chain, sheaves = write_vtu_series(run, rows, args.vtu, scale)
        print(f"wrote {chain} and {sheaves}: {span}")
    return 0


def open_run(path):
    """The results file ``path`` of a chain-CVT run with its stored scene (:class:`StoredRun`)."""
    import tomllib

    from cvtfem.io.results import read_results
    from cvtfem.render.stored_run import StoredRun
    from cvtfem.scene.loader import scene_from_dict

    results = read_results(path)
    return StoredRun.of(results, scene_from_dict(tomllib.loads(results.scene_toml), source=str(results.path)))
