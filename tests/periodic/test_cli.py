"""`cvtfem periodic` end to end, scenes and errors."""
from __future__ import annotations

import json

import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.machines.torsional import build
from cvtfem.scene.loader import load_scene, scene_from_dict

SMALL = """
title = "gear pair"
[periodic]
frequency = 15.0
harmonics = 16
[[torsional.disk]]
name = "motor"
inertia = 0.0225
radius = 0.15
damping = 0.045
[[torsional.disk]]
name = "pinion"
inertia = 0.01125
radius = 0.15
[[torsional.disk]]
name = "wheel"
inertia = 0.045
radius = 0.3
[[torsional.link]]
kind = "shaft"
a = "motor"
b = "pinion"
stiffness = 4500.0
damping = 0.45
[[torsional.link]]
kind = "backlash"
a = "pinion"
b = "wheel"
stiffness = 1e6
damping = 30.0
clearance = 2e-4
gap_stiffness = 3e4
[[torsional.link]]
kind = "shaft"
a = "wheel"
b = "ground"
stiffness = 4500.0
damping = 1.8
[[torsional.load]]
disk = "motor"
mean = 6.0
orders = [1]
amplitudes = [9.0]
"""


def test_scene_converts_to_circumferential_coordinates(tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(SMALL)
    net = build(load_scene(path))
    assert np.allclose(net.m, [1.0, 0.5, 0.5])             # I / r^2
    assert np.allclose(net.k_out, [2e5, 1e6, 5e4])          # k_phi / r^2 for shafts, N/m for the mesh
    assert np.allclose(net.d, [20.0, 30.0, 20.0])
    assert np.allclose(net.Q[:, list(net.orders).index(1)], [60.0, 0, 0])  # M / r
    assert net.k_in[1] == 3e4 and net.h[1] == 2e-4


def test_sampled_cycle_equals_harmonics():
    base = {"torsional": {"disk": [{"name": "d", "inertia": 1.0}],
                          "link": [{"kind": "shaft", "a": "d", "b": "ground", "stiffness": 1e3}]}}
    t = np.arange(64) / 64 * 2 * np.pi
    sampled = scene_from_dict({**base, "torsional": {**base["torsional"], "load": [
        {"disk": "d", "samples": list(5 + 3 * np.cos(2 * t + 0.3))}]}})
    harm = scene_from_dict({**base, "torsional": {**base["torsional"], "load": [
        {"disk": "d", "mean": 5.0, "orders": [2], "amplitudes": [3.0], "phases": [0.3]}]}})
    tt = np.linspace(0, 1, 7)
    assert np.allclose(build(sampled).load(tt, 2.0), build(harm).load(tt, 2.0), atol=1e-12)


@pytest.mark.parametrize("patch, where", [
    ({"kind": "shaft", "a": "motor", "b": "wheel", "stiffness": 1.0}, "torsional.link[3].b"),
    ({"kind": "backlash", "a": "motor", "b": "nope", "stiffness": 1.0, "clearance": 1e-4}, "torsional.link[3].b"),
    ({"kind": "backlash", "a": "motor", "b": "wheel", "stiffness": 1.0, "clearance": 1e-4,
      "gap_stiffness": 2.0}, "gap_stiffness"),
    ({"kind": "gap", "a": "motor", "b": "wheel", "stiffness": 1.0}, "clearance"),
])
def test_bad_links_are_named(tmp_path, patch, where):
    import tomllib

    data = tomllib.loads(SMALL)
    data["torsional"]["link"].append(patch)
    with pytest.raises(InputError, match=where.replace("[", r"\[").replace("]", r"\]")):
        scene_from_dict(data)


def test_cli_writes_json_and_png(cli, tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(SMALL)
    out = cli("periodic", str(path), "--sweep", "14:16:3", "--json", str(tmp_path / "r.json"),
              "--png", str(tmp_path / "r.png"))
    assert out.returncode == 0, out.stderr
    data = json.loads((tmp_path / "r.json").read_text())
    requested = [p for p in data["points"] if p["requested"]]
    assert [p["frequency"] for p in requested] == pytest.approx([14, 15, 16]) and data["probe"] == "pinion-wheel"
    assert len(data["points"]) == 3 + len(data["folds"])   # the turning points come on top
    point = requested[1]
    assert point["backlash"]["converged"]
    assert set(point["backlash"]["link_force_rms"]) == {"motor-pinion", "pinion-wheel", "wheel-ground"}
    assert len(point["backlash"]["harmonic_amplitudes"]["motor"]) == 17
    # mean 6 N m at the pinion becomes 6 x 0.3 / 0.15 = 12 N m on the wheel shaft (gear ratio 2):
    # n = 0 amplitude of the wheel is r M / k_phi
    assert point["no_backlash"]["harmonic_amplitudes"]["wheel"][0] == pytest.approx(0.3 * 12.0 / 4500, rel=1e-9)
    assert (tmp_path / "r.png").stat().st_size > 10_000


def test_cli_rejects_non_torsional_scene(cli):
    out = cli("periodic", "reference_cvt")
    assert out.returncode == 2 and "torsional" in out.stderr
    out = cli("periodic", "engine_gear_train", "--sweep", "3:3:4")
    assert out.returncode == 2 and "--sweep" in out.stderr
