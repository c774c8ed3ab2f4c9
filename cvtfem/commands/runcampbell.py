"""``cvtfem runcampbell RESULTS [--start S] [--end S] [--points N] [--modes N] [--against time|speed]
[--fmax HZ] [--png OUT] [--csv OUT]``: Campbell diagram along a run of the chain on elastic shafts, from the
structure block J11 of the Jacobian at stored states, with the excitation lines k f_chain and k/3 f_link."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("runcampbell", help="Campbell diagram along a run (elastic shafts): modes of the shaft/sheave "
                                           "block J11 at stored states, MAC-tracked, with k f_chain, k/3 f_link")
    p.add_argument("results", metavar="RESULTS", help="HDF5 results file of a run with `output.state = true`")
    p.add_argument("--start", type=float, default=None, metavar="S", help="first time analysed, s (default: 0)")
    p.add_argument("--end", type=float, default=None, metavar="S", help="last time analysed, s (default: the end)")
    p.add_argument("--points", type=int, default=40, metavar="N",
                   help="stored times analysed, spread evenly over [start, end] (default 40)")
    p.add_argument("--modes", type=int, default=12, metavar="N", help="tracked modes (default 12)")
    p.add_argument("--against", choices=("time", "speed"), default="time",
                   help="abscissa: time (ms) or the driving shaft's speed (rpm) (default time)")
    p.add_argument("--fmax", type=float, default=None, metavar="HZ", help="top of the frequency axis, Hz")
    p.add_argument("--chain-orders", default="1,2,3", metavar="K,...",
                   help="draw the lines k f_chain for these k (default 1,2,3; '' for none)")
    p.add_argument("--png", metavar="OUT", help="write the diagram as PNG")
    p.add_argument("--csv", metavar="OUT", help="write tracked frequencies, damping, whirl, MAC and lines as CSV")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from cvtfem.analysis.run_campbell import run_campbell
    from cvtfem.analysis.stored_state import stored_model, stored_states
    from cvtfem.commands.spectrogram import chain_of
    from cvtfem.errors import InputError
    from cvtfem.io.results import read_results
    from cvtfem.post import spectrogram as sg

    try:
        orders = tuple(int(k) for k in args.chain_orders.split(",") if k.strip())
    except ValueError:
        raise InputError("--chain-orders", args.chain_orders, "must be comma-separated integers, e.g. 1,2,3") from None
    if args.points < 2:
        raise InputError("--points", args.points, "must be at least 2 stored times")
    if args.modes < 1:
        raise InputError("--modes", args.modes, "must be a positive number of modes")
    results = read_results(args.results)
    t = results.time
    start = t[0] if args.start is None else args.start
    end = t[-1] if args.end is None else args.end
    chosen = np.flatnonzero((t >= start - 1e-12) & (t <= end + 1e-12))
    if chosen.size < 2:
        raise InputError("--start/--end", (start, end), f"must hold at least 2 stored times of the run "
                         f"({t[0]:.6g} .. {t[-1]:.6g} s)")
    chosen = np.unique(chosen[np.linspace(0, chosen.size - 1, min(args.points, chosen.size)).round().astype(int)])
    model = stored_model(results)
    _, x = stored_states(results, model)
    result = run_campbell(model, t[chosen], x[chosen], args.modes)
    freqs = sg.chain_frequencies(results, *chain_of(results))
    fmax = args.fmax or 1.05 * float(result.wd.max()) / (2 * np.pi)
    lines = [(name, f[chosen]) for name, f in sg.excitation_lines(freqs, fmax, orders)]
    hz = result.wd / (2 * np.pi)
    print(f"J11 of {model.structure.n} structure coordinates at {chosen.size} stored times, {t[chosen[0]]:.6g} .. "
          f"{t[chosen[-1]]:.6g} s; f_chain {freqs.f_chain[chosen].min():.5g} .. {freqs.f_chain[chosen].max():.5g} Hz, "
          f"f_link = {freqs.n_pins} f_chain")
    print("tracked modes at the first / last time, Hz: "
          + ", ".join(f"{a:.5g}/{b:.5g} {w}" for a, b, w in zip(hz[0], hz[-1], result.whirl[-1])))
    for tj, j, m in result.jumps:
        print(f"tracking jump: mode {j} at t = {tj:.6g} s (MAC {m:.2f} with the previous time)")
    if args.csv:
        from cvtfem.post.run_campbell import write_run_campbell_csv

        write_run_campbell_csv(result, lines, args.csv)
        print(f"wrote {args.csv}")
    if args.png:
        from cvtfem.post.run_campbell import plot_run_campbell

        plot_run_campbell(result, lines, args.png, args.against, args.fmax,
                          title=f"{results.path.name}: modes of J11 (chain frozen) along the run")
        print(f"wrote {args.png}")
    return 0
