"""``cvtfem docs scenes``: generate the scene-key reference from the schema."""
from __future__ import annotations

import argparse
from pathlib import Path


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("docs", help="generate reference documentation")
    p.add_argument("topic", choices=["scenes"], help="what to document")
    p.add_argument("--out", default="docs/scenes.md", help="output file ('-' for stdout)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.scene.docs import scene_reference

    text = scene_reference()
    if args.out == "-":
        print(text, end="")
    else:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
        print(f"wrote {out}")
    return 0
