"""``cvtfem revolution RESULTS (--follow P [--start T] | --at T) [--quantity NAME ...] [--average PITCHES]
[--png OUT] [--csv OUT]``: chain quantities of a chain-CVT run over one revolution of an element, or along the
chain at an instant, against the loop position from the middle of the tight span."""
from __future__ import annotations

import argparse

DEFAULT_QUANTITIES = ("chain.link_tension", "chain.pin_axial_force", "contact.normal_force", "contact.radius",
                      "contact.friction_circumferential", "contact.friction_radial")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("revolution", help="chain quantities over one revolution of a pin/link, or along the chain "
                                          "at an instant (link tension, pin axial force, contact, friction)")
    p.add_argument("results", metavar="RESULTS", help="HDF5 results file of a discrete-chain run")
    view = p.add_mutually_exclusive_group(required=True)
    view.add_argument("--follow", type=int, metavar="P", help="follow pin P (link P for per-link quantities)")
    view.add_argument("--at", type=float, metavar="T", help="every element at the stored time nearest T, s")
    p.add_argument("--start", type=float, default=None, metavar="T",
                   help="with --follow: from this time on, s (default: the first row)")
    p.add_argument("--quantity", action="append", metavar="NAME",
                   help="a per-pin or per-link series, or contact.friction_circumferential/_radial/_axial; "
                        "repeatable (default: " + ", ".join(DEFAULT_QUANTITIES) + ")")
    p.add_argument("--average", type=float, default=3.0, metavar="PITCHES",
                   help="moving average over this many link pitches (default 3, one lacing period; 0: none)")
    p.add_argument("--png", metavar="OUT", help="write the curves as PNG")
    p.add_argument("--csv", metavar="OUT", help="write the smoothed curves as CSV")
    p.set_defaults(func=run)


#: API argument names and the options that carry them.
OPTIONS = {"element": "--follow", "name": "--quantity", "rows": "--start"}


def run(args: argparse.Namespace) -> int:
    from cvtfem.errors import InputError

    try:
        return _run(args)
    except InputError as err:               # the API names its arguments; the command names its options
        if err.where in OPTIONS:
            raise InputError(OPTIONS[err.where], err.value, err.rule, err.hint) from None
        raise


def _run(args: argparse.Namespace) -> int:
    import numpy as np

    from cvtfem.errors import InputError
    from cvtfem.analysis.chain_results import pin_positions
    from cvtfem.io.results import read_results
    from cvtfem.post import chain_revolution as cr

    if not args.average >= 0.0:
        raise InputError("--average", args.average, "must be a number of link pitches >= 0")
    results = read_results(args.results)
    t = results.time
    u, L = pin_positions(results)
    positions = [cr.loop_position(row, L) for row in u]
    s_pin = np.array([p[0] for p in positions])
    s_link = np.array([p[1] for p in positions])
    stored = cr.quantities(results.series, u.shape[1])
    names = args.quantity or [q for q in DEFAULT_QUANTITIES if q in stored]
    series = {q: cr.chain_series(results.series, results.units, q, u, L) for q in dict.fromkeys(names)}
    if args.at is not None:
        if not t[0] <= args.at <= t[-1]:
            raise InputError("--at", args.at, f"must be a time within the run, {t[0]:.6g} .. {t[-1]:.6g} s")
        row = int(np.argmin(abs(t - args.at)))
        curves = {q: cr.distribution(cs, s_pin, s_link, row, args.average) for q, cs in series.items()}
        title = f"{results.path.name}: along the chain at t = {t[row]:.6g} s"
        print(f"along the chain at t = {t[row]:.6g} s (row {row}), loop length {positions[row][2]:.5g} m")
    else:
        start = t[0] if args.start is None else args.start
        if not t[0] <= start < t[-1]:
            raise InputError("--start", start, f"must be a time within the run before its end, {t[0]:.6g} .. <{t[-1]:.6g} s")
        rows = slice(int(np.searchsorted(t, start)), None)
        curves = {q: cr.revolution(cs, s_pin, s_link, args.follow, rows, args.average) for q, cs in series.items()}
        c = next(iter(curves.values()))
        covered = c.s[-1] - c.s[0]
        title = (f"{results.path.name}: element {args.follow} from t = {t[rows][0]:.6g} s, "
                 f"{100 * min(covered, 1.0):.0f} % of a revolution")
        print(f"element {args.follow} followed from t = {t[rows][0]:.6g} to {t[-1]:.6g} s: loop position "
              f"{c.s[0]:.4f} -> {c.s[-1]:.4f} ({100 * covered:.1f} % of a revolution"
              + ("" if covered >= 1 else "; run longer for a whole one") + ")")
    for q, c in curves.items():
        print(f"  {q}: {np.nanmin(c.y):.5g} .. {np.nanmax(c.y):.5g} {series[q].unit}")
    if args.csv:
        print(f"wrote {cr.write_curves_csv(curves, {q: cs.components for q, cs in series.items()}, args.csv)}")
    if args.png:
        print(f"wrote {cr.plot_curves(curves, series, args.png, title)}")
    return 0
