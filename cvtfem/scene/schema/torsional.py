"""Torsional networks (disks, shafts, gear meshes with backlash) and periodic-analysis settings.

A torsional scene is a ``[torsional]`` table with ``[[torsional.disk]]``,
``[[torsional.link]]`` and ``[[torsional.load]]`` entries; ``[periodic]`` holds
the harmonic-balance settings (spec numerics-and-periodic.md, section 8).
Each shaft carries one gear; every disk states the radius of the gear of its
shaft (``radius``), the scale of its circumferential coordinate ``x = r phi``.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cvtfem.errors import InputError
from cvtfem.scene.schema.base import Key, Table, TableArray, _suggest

#: Most harmonics a periodic solution may keep (blocks of (2N+1)^2 per node: 1000 -> 32 MB each).
MAX_HARMONICS = 1000

LINK_KINDS = ("shaft", "mesh", "backlash", "gap", "damper")

DISK = TableArray("disk", "Rigid disks (crank throws, flywheels, gears, damper rings, loads).", Table(
    "disk", "A rigid disk rotating about its shaft axis.", (
        Key("name", "str", "Unique name used by links and loads.", ""),
        Key("inertia", "float", "Polar moment of inertia.", "kg m^2", gt=0.0),
        Key("radius", "float", "Pitch radius of the gear on this disk's shaft (same for all disks of a shaft).",
            "m", 1.0, gt=0.0),
        Key("damping", "float", "External viscous damping to ground (bearings, pumping losses).",
            "N m s/rad", 0.0, ge=0.0),
    )))

LINK = TableArray("link", "Links between disks (or to ground).", Table("link", "An elastic link.", (
    Key("name", "str", "Name shown in outputs (default: `a-b`).", "", ""),
    Key("kind", "str", "Link type: shaft (torsion spring, stiffness in N m/rad), damper (like shaft), mesh (linear tooth "
        "spring along the pitch line, N/m), backlash (mesh with clearance on both flanks), gap (one-sided "
        "contact: closes when the deflection exceeds `clearance`).", "", choices=LINK_KINDS),
    Key("a", "str", "First disk.", ""),
    Key("b", "str", "Second disk, or \"ground\".", ""),
    Key("stiffness", "float", "Contact / shaft stiffness: N m/rad for shaft and damper, N/m for mesh, "
        "backlash and gap.", "N/m | N m/rad", ge=0.0),
    Key("damping", "float", "Viscous damping of the link: N m s/rad for shaft and damper, N s/m otherwise.",
        "N s/m | N m s/rad", 0.0, ge=0.0),
    Key("clearance", "float", "Backlash h (total free play along the pitch line) or gap width.", "m", 0.0, ge=0.0),
    Key("gap_stiffness", "float", "Weak residual stiffness inside the clearance (spec 8.3 errata: the weak "
        "stiffness belongs in the gap).", "N/m", 0.0, ge=0.0),
    Key("zone", "float", "Transition zone width as a fraction of `clearance` (0.2: the source's 0.4h..0.6h).",
        "-", 0.2, gt=0.0, le=1.0),
)))

LOAD = TableArray("load", "Periodic external moments on disks.", Table("load", "A periodic moment.", (
    Key("disk", "str", "Disk the moment acts on.", ""),
    Key("mean", "float", "Mean moment.", "N m", 0.0),
    Key("orders", "int[]", "Harmonic orders n of the cycle frequency.", "-", (), ge=1),
    Key("amplitudes", "float[]", "Amplitude of each order.", "N m", (), ge=0.0),
    Key("phases", "float[]", "Phase of each order: A cos(n omega t + phase) (empty: zeros).", "rad", ()),
    Key("samples", "float[]", "Alternative: the moment sampled at equal steps over one cycle (end excluded).",
        "N m", ()),
)))

TORSIONAL = Table("torsional", "A branched torsional network (section 8 of the periodic spec).", (
    DISK, LINK, LOAD,
), optional=True)

PERIODIC = Table("periodic", "Harmonic-balance settings (`cvtfem periodic`).", (
    Key("frequency", "float", "Cycle frequency (base harmonic), e.g. rpm / 120 for a four-stroke engine.",
        "Hz", 10.0, gt=0.0),
    Key("harmonics", "int", "Number of harmonics N (n = -N..N); at most 1000 (the Newton blocks grow as N^2).",
        "-", 24, ge=1, le=MAX_HARMONICS),
    Key("samples", "int", "AFT time samples per period (0: power of two >= 8N).", "-", 0, ge=0, le=1 << 20),
    Key("backlash", "bool", "Use the nonlinear backlash and gap laws (false: contact stiffness everywhere).",
        "", True),
    Key("tol", "float", "Newton stop: relative residual norm.", "-", 1e-10, gt=0.0, lt=1.0),
    Key("max_iter", "int", "Newton iterations per attempt.", "-", 30, ge=1),
    Key("sweep", "float[]", "Frequency sweep [start, stop, points] (empty: only `frequency`).", "Hz | -", ()),
    Key("probe", "str", "Link whose moment the plots show (default: the first backlash link).", "", ""),
), optional=True)


def _check_network(scene: Mapping[str, Any], path: str) -> None:
    net = scene["torsional"]
    names = [d["name"] for d in net["disk"]]
    for k, name in enumerate(names):
        if name == "ground" or names.index(name) != k:
            raise InputError(f"torsional.disk[{k}].name", name, "must be unique and not \"ground\"")
    radius = {d["name"]: d["radius"] for d in net["disk"]}

    def disk(where: str, name: str, ground: bool = False) -> None:
        if name not in radius and not (ground and name == "ground"):
            raise InputError(where, name, "must name a `[[torsional.disk]]`" + (" or \"ground\"" if ground else ""),
                             _suggest(name, names) or f"defined: {', '.join(names) or 'none'}")

    for k, link in enumerate(net["link"]):
        where = f"torsional.link[{k}]"
        disk(f"{where}.a", link["a"])
        disk(f"{where}.b", link["b"], ground=True)
        if link["a"] == link["b"]:
            raise InputError(f"{where}.b", link["b"], "must differ from `a`")
        if link["kind"] in ("shaft", "damper") and link["b"] != "ground" \
                and radius[link["a"]] != radius[link["b"]]:
            raise InputError(f"{where}.b", link["b"], f"must lie on the same shaft as `a` (equal `radius`, "
                             f"{radius[link['a']]} vs {radius[link['b']]} m) for a {link['kind']} link")
        if link["kind"] in ("backlash", "gap"):
            if link["clearance"] <= 0:
                raise InputError(f"{where}.clearance", link["clearance"], f"must be > 0 for a {link['kind']} link")
            if not link["gap_stiffness"] < link["stiffness"]:
                raise InputError(f"{where}.gap_stiffness", link["gap_stiffness"],
                                 f"must be smaller than `stiffness` = {link['stiffness']:g} N/m (weak spring in the gap)")
        elif link["clearance"] or link["gap_stiffness"]:
            raise InputError(f"{where}.clearance", link["clearance"],
                             f"applies only to backlash and gap links, not {link['kind']!r}")
    for k, load in enumerate(net["load"]):
        where = f"torsional.load[{k}]"
        disk(f"{where}.disk", load["disk"])
        n = len(load["orders"])
        if len(load["amplitudes"]) != n or (load["phases"] and len(load["phases"]) != n):
            raise InputError(f"{where}.amplitudes", load["amplitudes"],
                             f"must have one entry per order ({n}); `phases` too if given")
        if load["samples"] and n:
            raise InputError(f"{where}.samples", "...", "cannot be combined with `orders`: give one or the other")
    per = scene.get("periodic")
    if per is not None and per["sweep"]:
        sweep = per["sweep"]
        if len(sweep) != 3 or not (0 < sweep[0] != sweep[1] > 0) or sweep[2] < 2 or sweep[2] != int(sweep[2]):
            raise InputError("periodic.sweep", list(sweep), "must be [start, stop, points] with 0 < start, 0 < stop, "
                             "start != stop (Hz; start > stop sweeps down) and an integer number of points >= 2")
    if per is not None and per["probe"] and per["probe"] not in link_names(net):
        raise InputError("periodic.probe", per["probe"], "must name a link",
                         _suggest(per["probe"], link_names(net)))


def link_names(net: Mapping[str, Any]) -> list[str]:
    """Names of the links (``a-b`` when not given)."""
    return [link["name"] or f"{link['a']}-{link['b']}" for link in net["link"]]


ROOT_ITEMS = (TORSIONAL, PERIODIC)
ROOT_CHECKS = (_check_network,)
