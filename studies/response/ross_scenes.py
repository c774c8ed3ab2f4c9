"""ROSS 3.1's compressor example as a cvtfem scene: ``tests/data/ross/compressor.toml``.

Reads ROSS's own data file (``ross/data/compressor_example.toml`` inside the ROSS 3.1 wheel; it is not copied
into this repository) with the standard library and writes the equivalent cvtfem rotor scene:

    .venv/bin/python studies/response/ross_scenes.py PATH/TO/ross/data/compressor_example.toml

Mapping: ROSS shaft elements sharing an element index ``n`` lie on the same two nodes; the first is the shaft,
the others become ``parallel = true`` sleeves. Disks with zero inertia (point masses) become bearings with only
a lumped ``mass`` (a disk needs ``Id, Ip > 0``). Bearings and seals keep their speed tables
(``speeds``, ``kxx_table`` ..). Materials are named by their ROSS names.
"""
from __future__ import annotations

import sys
import tomllib
from pathlib import Path

OUT = Path(__file__).resolve().parents[2] / "tests" / "data" / "ross" / "compressor.toml"
TABLES = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")


def _fmt(x: float) -> str:
    return repr(float(x))


def _row(key: str, values) -> str:
    return f"{key} = [{', '.join(_fmt(v) for v in values)}]"


def convert(data: dict) -> str:
    """The cvtfem scene text of a ROSS rotor data dict (shafts, disks, bearings and seals)."""
    shafts = sorted((v for k, v in data.items() if k.startswith("ShaftElement")), key=lambda v: v["n"])
    lines = ["# ROSS 3.1 `compressor_example()` (ross/data/compressor_example.toml; Timbo & Ritto 2019), converted",
             "# by studies/response/ross_scenes.py. Reference numbers: tests/data/ross/compressor.json.",
             'title = "ROSS compressor_example()"',
             'description = "91 shaft elements (sleeves as parallel elements), 7 point masses, 2 bearings and 12 '
             'seals with speed-dependent coefficients."', "",
             "[rotor]", 'theory = "timoshenko"', "rotary_inertia = true", "gyroscopic = true",
             "shear_coefficient = 0.0", ""]
    mats = {}
    for v in shafts:
        mats[v["material"]["name"]] = v["material"]
    for name, m in mats.items():
        lines += ["[[material]]", f'name = "{name}"', f"E = {_fmt(m['E'])}", f"G = {_fmt(m['G_s'])}",
                  f"rho = {_fmt(m['rho'])}", ""]
    previous = None
    for v in shafts:
        if v["idl"] != v["idr"] or v["odl"] != v["odr"]:
            raise SystemExit(f"tapered element {v['tag']}: not converted")
        lines += ["[[shaft]]", f"length = {_fmt(v['L'])}", f"outer_diameter = {_fmt(v['odl'])}",
                  f"inner_diameter = {_fmt(v['idl'])}", f'material = "{v["material"]["name"]}"']
        if v["n"] == previous:
            lines.append("parallel = true")
        previous = v["n"]
        lines.append("")
    for k, v in data.items():
        if k.startswith("DiskElement"):
            if v["Id"] > 0 and v["Ip"] > 0:
                lines += ["[[disk]]", f"node = {v['n']}", f"mass = {_fmt(v['m'])}", f"Id = {_fmt(v['Id'])}",
                          f"Ip = {_fmt(v['Ip'])}", ""]
            else:
                lines += [f"[[bearing]]  # {v['tag']}: a point mass", f"node = {v['n']}", f"mass = {_fmt(v['m'])}",
                          ""]
    for k, v in data.items():
        if k.startswith(("BearingElement", "SealElement")):
            if any(v.get(f"m{ij}") and any(v[f"m{ij}"]) for ij in ("xx", "xy", "yx", "yy")):
                raise SystemExit(f"{k}: added mass coefficients are not converted")
            lines += [f"[[bearing]]  # {v['tag']}", f"node = {v['n']}", _row("speeds", v["speed"])]
            lines += [_row(f"{c}_table", v[c]) for c in TABLES]
            lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    src = Path(sys.argv[1])
    OUT.write_text(convert(tomllib.loads(src.read_text())))
    print(f"wrote {OUT}")
