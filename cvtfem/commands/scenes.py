"""``cvtfem scenes``: list the built-in presets."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("scenes", help="list built-in scene presets")
    p.add_argument("--show", metavar="NAME", help="print the TOML of one preset (with provenance comments)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.scene.loader import load_scene, preset_names, preset_text

    if args.show:
        print(preset_text(args.show), end="")
        return 0
    names = preset_names()
    width = max(map(len, names))
    for name in names:
        scene = load_scene(name)
        print(f"{name:<{width}}  {scene.kind:<9}  {scene.description}")
    return 0
