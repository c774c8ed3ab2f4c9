"""``cvtfem describe SCENE``: components, effects, coordinates and outputs."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("describe", help="print what a scene's model consists of")
    p.add_argument("scene", metavar="SCENE", help="scene file (.toml) or preset name")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.machines import describe
    from cvtfem.scene.loader import load_scene

    print(describe(load_scene(args.scene)))
    return 0
