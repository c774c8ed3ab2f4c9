"""``cvtfem bench TOPIC``: benchmarks that print medians of several runs and the machine."""
from __future__ import annotations

import argparse
from importlib import import_module

#: Topic -> module with ``run(repeat=..., large=...)``.
TOPICS = {"campbell": "cvtfem.analysis.bench_campbell"}


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="benchmarks (wall time, medians of repeats, machine)")
    p.add_argument("topic", choices=sorted(TOPICS), help="what to benchmark")
    p.add_argument("--repeat", type=int, default=5, help="repeats of the fast cases (median reported)")
    p.add_argument("--quick", action="store_true", help="skip the large cases")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.errors import InputError

    if args.repeat < 1:
        raise InputError("--repeat", args.repeat, "must be >= 1")
    import_module(TOPICS[args.topic]).run(repeat=args.repeat, large=not args.quick)
    return 0
