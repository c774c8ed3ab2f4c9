"""``cvtfem response SCENE --unbalance NODE:ME:PHASE --speeds A:B:N --node N [--orders K,...]``: forced response."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("response", help="unbalance response over speed (Bode, orbit) and order map of a rotor scene")
    p.add_argument("scene", metavar="SCENE", help="rotor scene file (.toml) or preset name")
    p.add_argument("--unbalance", action="append", required=True, metavar="NODE:ME:PHASE",
                   help="unbalance m e (kg m) at phase (deg) on the disk at shaft node NODE; repeatable")
    p.add_argument("--speeds", required=True, help="START:STOP<unit>:COUNT, unit rpm, rad/s or Hz (0:4000rpm:201)")
    p.add_argument("--node", type=int, required=True, help="shaft node whose x, y response is reported")
    p.add_argument("--orders", help="excitation orders k (lines k x speed), comma separated, e.g. 14,28,42")
    p.add_argument("--force-node", type=int, help="node of the unit x force of the order map (default: first "
                                                  "unbalance node)")
    p.add_argument("--n-modes", type=int, default=12, help="modes of the modal superposition (default 12)")
    p.add_argument("--results", metavar="OUT.h5", help="write the response as an HDF5 results file")
    p.add_argument("--json", metavar="OUT", help="write amplitudes, phases, orbit, order map as JSON")
    p.add_argument("--csv", metavar="OUT", help="write the unbalance response per speed as CSV")
    p.add_argument("--png", metavar="OUT", help="Bode plot (amplitude, phase, orbit axes over speed); with "
                                                "--orders also OUT with suffix _orders.png: the order map")
    p.set_defaults(func=run)


def _unbalance(text: str):
    from math import radians

    from cvtfem.analysis.response import Unbalance
    from cvtfem.errors import InputError

    try:
        node, me, phase = text.split(":")
        u = Unbalance(int(node), float(me), radians(float(phase)))
    except ValueError:
        raise InputError("--unbalance", text, "must be NODE:ME:PHASE (node, kg m, deg), e.g. 4:1e-4:0") from None
    if not u.me > 0 or u.me == float("inf"):
        raise InputError("--unbalance", text, "needs a finite m e > 0 kg m")
    return u


def parse_orders(text: str | None) -> tuple[float, ...]:
    from cvtfem.errors import InputError

    if not text:
        return ()
    try:
        return tuple(float(k) for k in text.split(",") if k.strip())
    except ValueError:
        raise InputError("--orders", text, "must be comma-separated numbers, e.g. 14,28,42") from None


def sweep_speeds(text: str):
    """``--speeds`` as an array of speeds (rad/s) starting at >= 0."""
    from cvtfem.errors import InputError
    from cvtfem.units import parse_speeds

    speeds = parse_speeds(text)
    if speeds[0] < 0:
        raise InputError("--speeds", text, "must start at a speed >= 0")
    return speeds


def print_crossings(crossings, order_width: int, whirl_width: int) -> None:
    """One line per Campbell crossing of an order line (order, mode, whirl, speed in rpm)."""
    import math

    for c in crossings:
        rpm = c["speed_rad_s"] * 30 / math.pi
        print(f"    {c['order']:>{order_width}} mode {c['mode']:>2} ({c['whirl']:<{whirl_width}}) at {rpm:9.5g} rpm")


def write_data(res, scene, args, write_results) -> None:
    """``--results`` (HDF5 by ``write_results``) and ``--json`` of a response or spectrum ``res``."""
    import json

    if args.results:
        write_results(res, args.results, scene)
        print(f"wrote {args.results}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"scene": scene.source, **res.to_dict()}, fh)
        print(f"wrote {args.json}")


def run(args: argparse.Namespace) -> int:
    import csv
    from pathlib import Path

    import numpy as np

    from cvtfem.analysis.response import scene_response, write_results
    from cvtfem.errors import InputError
    from cvtfem.scene.loader import load_scene

    speeds = sweep_speeds(args.speeds)
    if args.n_modes < 1:
        raise InputError("--n-modes", args.n_modes, "must be >= 1")
    unbalances = [_unbalance(u) for u in args.unbalance]
    scene = load_scene(args.scene)
    res = scene_response(scene, unbalances, speeds, args.node, parse_orders(args.orders), args.force_node,
                         n_modes=args.n_modes)
    rpm = res.speeds * 30 / np.pi
    i = int(np.argmax(res.major))
    print(f"{scene.title or scene.source}: unbalance response at node {res.node}, {len(speeds)} speeds")
    print(f"  peak orbit major semi-axis {res.major[i]:.4g} m at {res.speeds[i]:.5g} rad/s = {rpm[i]:.5g} rpm "
          f"(phase x {np.degrees(np.angle(res.x[i])):.1f} deg)")
    if res.orders:
        for j, k in enumerate(res.orders):
            m = int(np.argmax(res.order_amplitude[:, j]))
            print(f"  order {k:g}: peak {res.order_amplitude[m, j]:.4g} m/N at {rpm[m]:.5g} rpm")
        print("  Campbell crossings of the order lines (lateral, torsional, axial):")
        print_crossings(res.campbell.crossings, 8, 9)
    write_data(res, scene, args, write_results)
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            csv.writer(fh).writerows(res.csv_rows())
        print(f"wrote {args.csv}")
    if args.png:
        from cvtfem.post.response import plot_bode, plot_order_map

        plot_bode(res, args.png, title=scene.title or scene.source)
        print(f"wrote {args.png}")
        if res.orders:
            path = Path(args.png)
            omap = path.with_name(f"{path.stem}_orders.png")
            plot_order_map(res, omap, title=scene.title or scene.source)
            print(f"wrote {omap}")
    return 0
