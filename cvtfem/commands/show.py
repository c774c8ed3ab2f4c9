"""``cvtfem show RESULTS.h5``: summarise a results file."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("show", help="summarise a results file")
    p.add_argument("results", metavar="RESULTS.h5", help="results file written by a run")
    p.add_argument("--scene", action="store_true", help="also print the scene TOML stored in the file")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from cvtfem.io.results import read_results

    res = read_results(args.results)
    a = res.attrs
    print(f"{res.path}: {a.get('kind')} by cvtfem {a.get('cvtfem_version')}, created {a.get('created')}")
    print(f"status: {a.get('status')}" + (f" ({a['message']})" if a.get("message") else ""))
    if a.get("status") == "running":
        print("  (the run did not close this file: it was killed or is still going; rows up to its last flush)")
    n = res.time.size
    span = f"t = {res.time[0]:.6g} .. {res.time[-1]:.6g} s" if n else "no rows"
    print(f"rows: {n}, {span}")
    for name, data in res.series.items():
        finite = data[np.isfinite(data)]
        rng = f"{finite.min():.6g} .. {finite.max():.6g}" if finite.size else "-"
        print(f"  {name:<32} {res.units[name]:<6} shape {data.shape}, range {rng}")
    if res.stats:
        print("stats: " + ", ".join(f"{k}={v}" for k, v in sorted(res.stats.items())))
    if args.scene:
        print("\n" + res.scene_toml)
    return 0
