"""``cvtfem history RESULTS [--window S] [--png OUT] [--csv OUT]``: regime history of a CVT run (speeds, ratio,
efficiency steady and kinetic-energy corrected, slip, clamping forces), the run's energy balance, where a refined
contact's points lie on the pin end face (a warning when more than 5 % lie off it) and any non-finite series."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("history", help="speeds, ratio, efficiency, slip and clamping forces of a CVT run over time")
    p.add_argument("results", metavar="RESULTS", help="HDF5 results file of a CVT run (band or chain)")
    p.add_argument("--window", type=float, default=None, metavar="S",
                   help="efficiency window, s (default: a tenth of the run, at most 0.05 s)")
    p.add_argument("--png", metavar="OUT", help="write the history as PNG")
    p.add_argument("--csv", metavar="OUT", help="write the history columns as CSV")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from cvtfem.io.results import read_results
    from cvtfem.analysis.chain_results import OFF_FACE_WARNING, off_face
    from cvtfem.post.history import energy_residual, history, nonfinite_series, plot_history, write_history_csv

    results = read_results(args.results)
    t = results.time
    window = args.window if args.window is not None else min(0.1 * (t[-1] - t[0]), 0.05)
    cols = history(results, window)
    last = {k: v[-1] for k, v in cols.items()}
    print(f"{results.path.name}: {t[0]:.6g} .. {t[-1]:.6g} s, {t.size} rows; at the end: n1 {last['n1_rpm']:.1f} rpm, "
          f"n2 {last['n2_rpm']:.1f} rpm, ratio {last['ratio']:.4f}")
    print(f"efficiency over the last {window:g} s: {last['efficiency']:.4f} (kinetic-energy corrected "
          f"{last['efficiency_kinetic']:.4f})")
    if "slip_driving" in cols:
        print(f"slip speed at the end: driving {last['slip_driving']:.4g} m/s, driven {last['slip_driven']:.4g} m/s")
    if not np.isfinite(last["efficiency"]):
        print("no input work in the last window: efficiency undefined (NaN)")
    print(f"energy balance over the run: residual {energy_residual(results)[-1]:.2e} of the input work "
          f"(input + clamping work = output + dissipated work + change of stored energy)")
    face = off_face(results)
    if face is not None:
        f, h = face["fraction"], face["half_height"]
        print(f"contact points off the pin end face (farther than width_n / 2 = {h * 1e3:.3g} mm from the pin axis), "
              f"all rows: driving {f[0]:.1%}, driven {f[1]:.1%}; offset |x_*| mean {face['mean'][0] * 1e3:.3g} / "
              f"{face['mean'][1] * 1e3:.3g} mm, max {face['max'][0] * 1e3:.3g} / {face['max'][1] * 1e3:.3g} mm")
        if f.max() > OFF_FACE_WARNING:
            print(f"warning: {f.max():.0%} of the contacts on a shaft lie off the pin end face (more than "
                  f"{OFF_FACE_WARNING:.0%}): the face model (cvt.chain.face_radius, face_inclination) puts the "
                  "contact point beyond the pin; see docs/transmission.md, 'Session 12: the inclined pin face'")
    bad = nonfinite_series(results)
    print("non-finite values: " + (", ".join(bad) if bad else "none"))
    if args.csv:
        print(f"wrote {write_history_csv(cols, args.csv)}")
    if args.png:
        print(f"wrote {plot_history(results, args.png, window, title=results.path.name)}")
    return 0
