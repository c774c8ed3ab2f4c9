"""``cvtfem sweep SCENE --vary KEY=a:b:n [--list FILE] --out DIR``: variants of a scene on a process pool or dask."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sweep", help="parameter sweep: variants of a scene run on a local pool or a dask cluster")
    p.add_argument("scene", metavar="SCENE", help="base scene file (.toml) or preset name")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=A:B:N",
                   help="grid axis: N values from A to B, or KEY=V1,V2,... (dotted scene key, repeatable)")
    p.add_argument("--list", metavar="FILE", help="variants from a CSV (header of dotted keys) or TOML ([[variant]])")
    p.add_argument("--analysis", default="run", choices=("run", "modes", "campbell", "periodic"))
    p.add_argument("--until", type=float, metavar="T", help="simulated end time of --analysis run, s")
    p.add_argument("--speeds", metavar="A:B<unit>:N", help="speeds of --analysis campbell (0:4000rpm:21)")
    p.add_argument("--engine", default="local", choices=("local", "dask"),
                   help="local: a process pool; dask: a LocalCluster, or --scheduler")
    p.add_argument("--workers", type=int, metavar="N", help="worker processes (default: CPU count)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="external dask scheduler (tcp://HOST:8786)")
    p.add_argument("--connect-timeout", type=float, default=10.0, metavar="S", help="wait for --scheduler, s")
    p.add_argument("--retries", type=int, default=2, metavar="R",
                   help="retries of a variant whose worker died or that raised an unexpected error")
    p.add_argument("--retry-failed", action="store_true", help="rerun variants that failed in an earlier sweep")
    p.add_argument("--no-files", action="store_true",
                   help="keep only the summaries in the index (workers that do not share the folder)")
    # dest "folder", not "out": cli.check_output_args takes an --out of other commands for a file
    p.add_argument("--out", dest="folder", required=True, metavar="DIR", help="sweep folder (index.json, variants/)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.analysis.sweep import expand, parse_vary, read_list, run_sweep
    from cvtfem.commands.paths import check_output_dir
    from cvtfem.errors import InputError
    from cvtfem.scene.loader import load_scene

    check_output_dir("--out", args.folder)
    varies = [parse_vary(v) for v in args.vary]
    rows = read_list(args.list) if args.list else None
    if not varies and not rows:
        raise InputError("--vary", None, "or --list is required: a sweep needs variants")
    if not 0 <= args.retries <= 100:
        raise InputError("--retries", args.retries, "must be a whole number in 0..100")
    if args.until is not None and args.analysis != "run":
        raise InputError("--until", args.until, "applies to --analysis run only")
    variants = expand(varies, rows)
    options = {"until": args.until} if args.analysis == "run" else {}
    if args.analysis == "campbell":
        options["speeds"] = args.speeds
    index = run_sweep(load_scene(args.scene), variants, args.analysis, args.folder, args.engine, args.workers,
                      args.scheduler, options, files=not args.no_files, retries=args.retries,
                      retry_failed=args.retry_failed, connect_timeout=args.connect_timeout)
    ids = {v.id for v in variants}
    counts: dict[str, int] = {}
    for e in index["variants"]:
        if e["id"] in ids:
            counts[e["status"]] = counts.get(e["status"], 0) + 1
    print(f"sweep of {len(variants)} variants ({args.analysis}, {args.engine}): "
          + ", ".join(f"{n} {status}" for status, n in sorted(counts.items())))
    for e in index["variants"]:
        if e["id"] in ids and e["status"] != "finished":
            print(f"  {e['id']} {e['status']}: {e['error']}")
    print(f"index: {args.folder}/index.json")
    return 0 if counts.get("finished", 0) == len(variants) else 3
