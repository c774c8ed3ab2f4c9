"""``cvtfem describe SCENE``: components, effects, coordinates and outputs."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("describe", help="print what a scene's model consists of")
    p.add_argument("scene", metavar="SCENE", help="scene file (.toml) or preset name")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from cvtfem.machines import layout
    from cvtfem.scene.loader import load_scene

    scene = load_scene(args.scene)
    parts = layout(scene)
    print(f"scene: {scene.title or scene.source} ({scene.kind}; from {scene.source})")
    if scene.description:
        print(f"  {scene.description}")
    if scene.kind == "cvt":
        print(f"model: {scene.cvt.model}")
        effects = scene.cvt.effects
        print("effects: " + ", ".join(f"{k}={'on' if v is True else 'off' if v is False else v}"
                                      for k, v in effects.items()))
    print("\ncomponents:")
    print(f"  {'name':<16} {'family':<24} {'coords':>7} {'states':>7} {'discrete':>9}  how")
    for part in parts:
        print(f"  {part.name:<16} {part.kind:<24} {part.n2:>7} {part.n1:>7} {part.discrete:>9}  {part.note}")
    n2 = sum(p.n2 for p in parts)
    n1 = sum(p.n1 for p in parts)
    print(f"  {'total':<16} {'':<24} {n2:>7} {n1:>7} {sum(p.discrete for p in parts):>9}"
          f"  ODE size 2 x {n2} + {n1} = {2 * n2 + n1}")
    print("\noutputs:")
    for part in parts:
        for out in part.outputs:
            size = f"[{out.size}]" if out.size > 1 else ""
            print(f"  {out.name + size:<34} {out.unit:<6} {out.doc}")
    return 0
