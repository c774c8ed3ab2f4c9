"""``cvtfem report SWEEP_DIR [--format md|html] --out FILE``: a sweep's table and plots in a report."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("report", help="Markdown or HTML report of a sweep folder: table of variants and maps")
    p.add_argument("folder", metavar="SWEEP_DIR", help="folder of a `cvtfem sweep` (holds index.json)")
    p.add_argument("--format", default=None, choices=("md", "html"), help="default: from the --out suffix, else md")
    p.add_argument("--out", required=True, metavar="FILE", help="report file; its PNG figures are written beside it")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from cvtfem.analysis.sweep import INDEX, read_index
    from cvtfem.post.sweep import write_report

    fmt = args.format or ("html" if Path(args.out).suffix.lower() in (".html", ".htm") else "md")
    index = read_index(args.folder)
    out = write_report(index, args.out, fmt, str(Path(args.folder) / INDEX))
    figures = sorted(p.name for p in out.parent.glob(f"{out.stem}_*.png"))
    print(f"wrote {out}" + (f" and {', '.join(figures)}" if figures else ""))
    return 0
