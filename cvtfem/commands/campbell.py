"""``cvtfem campbell SCENE --speeds 0:4000rpm:51 [--json OUT] [--png OUT]``: Campbell diagram."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("campbell", help="Campbell diagram of a rotor scene: tracked modes, orders, critical speeds")
    p.add_argument("scene", metavar="SCENE", help="rotor scene file (.toml) or preset name")
    p.add_argument("--speeds", required=True, help="START:STOP<unit>:COUNT, unit rpm, rad/s or Hz (0:4000rpm:51)")
    p.add_argument("--n-modes", type=int, help="tracked modes (default [rotor].n_modes)")
    p.add_argument("--orders", default="1", help="shaft orders k (lines k x speed), comma separated")
    p.add_argument("--chain", metavar="R,LCHAIN,LLINK",
                   help="CVT lines k f_chain and k/3 f_link for contact radius R, chain and link length (m)")
    p.add_argument("--method", default="auto", choices=("auto", "dense", "sparse", "slepc"))
    p.add_argument("--json", metavar="OUT", help="write per-speed modes, tracked curves, crossings as JSON")
    p.add_argument("--csv", metavar="OUT", help="write tracked curves as CSV")
    p.add_argument("--png", metavar="OUT", help="plot the diagram")
    p.add_argument("--fmax", type=float, metavar="HZ", help="upper frequency limit of the plot, Hz (default: all modes)")
    p.set_defaults(func=run)


def _orders(args: argparse.Namespace) -> tuple[tuple[str, float], ...]:
    from cvtfem.errors import InputError
    from cvtfem.modal import chain_orders, shaft_orders

    try:
        ks = tuple(float(k) for k in args.orders.split(",") if k.strip())
    except ValueError:
        raise InputError("--orders", args.orders, "must be comma-separated numbers, e.g. 1,2") from None
    lines = shaft_orders(ks)
    if args.chain:
        try:
            r, lc, ll = (float(v) for v in args.chain.split(","))
        except ValueError:
            raise InputError("--chain", args.chain, "must be three numbers R,LCHAIN,LLINK in m") from None
        lines += chain_orders(r, lc, ll)
    return lines


def _sheave_waves(scene, speeds, orders):  # noqa: ANN001, ANN202
    """Flexible sheaves' own waves (n >= 2) as Campbell lines, printed with their order crossings."""
    import numpy as np

    from cvtfem.commands.sheave import own_waves

    out = own_waves(scene, speeds)
    if out:
        print("sheaves' own waves (bore on the shaft, not coupled with it), fixed frame:")
    for label, hz in out:
        cross = [f"{name} at {s * 30 / np.pi:.5g} rpm" for name, k in orders
                 for s in _roots(speeds, hz - k * speeds / (2 * np.pi))]
        print(f"  {label:<20} {hz[0]:9.1f} .. {hz[-1]:9.1f} Hz  {', '.join(cross)}")
    return out


def _roots(x, y):  # noqa: ANN001, ANN202
    """Where the piecewise-linear ``y(x)`` changes sign."""
    import numpy as np

    i = np.flatnonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)
    return x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])


def run(args: argparse.Namespace) -> int:
    import json

    import numpy as np

    from cvtfem.commands.modes import load_rotor
    from cvtfem.modal import ModalProblem, campbell
    from cvtfem.units import parse_speeds

    speeds = parse_speeds(args.speeds)
    if args.fmax is not None and not 0.0 < args.fmax < 1e9:
        from cvtfem.errors import InputError

        raise InputError("--fmax", args.fmax, "must be a frequency in Hz with 0 < fmax < 1e9")
    scene, model = load_rotor(args.scene)
    n_modes = args.n_modes or (scene.rotor.n_modes if scene.rotor else 12)
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, args.method,
                           speed_terms=model.speed_terms)
    result = campbell(problem, speeds, n_modes, _orders(args))
    print(f"{scene.title or scene.source}: {len(speeds)} speeds x {n_modes} modes, backend {problem.method}")
    print("critical speeds (mode crossing an excitation line):")
    for c in result.crossings:
        print(f"  {c['order']:>12}  mode {c['mode']:>2} ({c['whirl']:<9}) at {c['speed_rad_s']:10.4g} rad/s "
              f"= {c['speed_rad_s'] * 30 / np.pi:9.5g} rpm")
    if not result.crossings:
        print("  none in the speed range")
    for jump in result.jumps:
        print(f"  warning: tracked mode {jump['mode']} changed identity at {jump['speed_rad_s']:.4g} rad/s "
              f"(MAC {jump['mac']:.2f} with the previous speed): refine the speeds there")
    waves = _sheave_waves(scene, speeds, result.orders)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"scene": scene.source, "backend": problem.method, **result.to_dict(),
                       "sheave_waves": [{"label": lab, "hz": hz.tolist()} for lab, hz in waves]}, fh)
        print(f"wrote {args.json}")
    if args.csv:
        result.write_csv(args.csv)
        print(f"wrote {args.csv}")
    if args.png:
        from cvtfem.post.campbell import plot_campbell

        plot_campbell(result, args.png, title=scene.title or scene.source, fmax=args.fmax, lines=waves)
        print(f"wrote {args.png}")
    return 0
