"""``cvtfem demo``: the main demo on the built-in reference scene."""
from __future__ import annotations

import argparse

#: Demo parts: modules ``cvtfem.demo.<part>`` with ``run(outdir) -> list[str]``.
PARTS = ("foundation", "rotor", "integrators", "lowered", "periodic")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the main demo (reference scene) and write figures")
    p.add_argument("--out", default="out/demo", help="output folder")
    p.add_argument("--only", nargs="*", choices=PARTS, help="run only these parts")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time
    from importlib import import_module
    from pathlib import Path

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for part in args.only or PARTS:
        module = import_module(f"cvtfem.demo.{part}")
        start = time.perf_counter()
        print(f"== {part}")
        for line in module.run(out):
            print(f"   {line}")
        print(f"   ({time.perf_counter() - start:.1f} s)")
    print(f"demo outputs in {out}/")
    return 0
