"""``cvtfem scenes``: list the built-in presets."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("scenes", help="list built-in scene presets and the parts (regimes, chain patterns) that combine with them")
    p.add_argument("--show", metavar="NAME", help="print the TOML of one preset (with provenance comments)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.scene.loader import load_scene, part_names, preset_names, preset_text

    if args.show:
        print(preset_text(args.show), end="")
        return 0
    names, parts = preset_names(), part_names()
    width = max(map(len, names + parts))
    for name in names:
        scene = load_scene(name)
        print(f"{name:<{width}}  {scene.kind:<9}  {scene.description}")
    print("\nparts, to follow a preset (preset = [\"variant-b\", \"regime-A\"], or variant-b,regime-A on the "
          "command line):")
    for name in parts:
        print(f"{name:<{width}}  {'part':<9}  {preset_text(name).splitlines()[1].lstrip('# ')}")
    return 0
