"""Presets combined with parts (regimes, chain patterns): `preset = ["variant-b", "regime-A"]` (issue 14).

The regime parts carry the source's Table 1.2 and section 1.8 values; the targets a model builds from them
are checked here against those values in the source's own units (rpm, N m), so a unit slip in a part
(rad/s written as rpm) fails.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.io.results import read_results
from cvtfem.machines.cvt import chain_geometry, closed_loop
from cvtfem.scene.loader import load_scene, part_names, preset_names, scene_from_dict

RPM = math.pi / 30

#: part -> (targets at t = 0, targets at the end of the ramp): (input speed rpm, torque N m, ratio), end time s
SOURCE = {"regime-stationary": ((3500, 200, 2.4), (3500, 200, 2.4), 1.0),
          "regime-A": ((4000, 150, 0.45), (4000, 380, 0.45), 2.0),
          "regime-B": ((1000, 200, 0.45), (6000, 200, 0.45), 2.0),
          "regime-V": ((3000, 200, 0.45), (3000, 200, 2.4), 5.0),
          "regime-efficiency": ((3000, 20, 1.8), (3000, 450, 1.8), 10.0),
          "regime-acoustic": ((3000, 100, 2.38), (3000, 100, 0.43), 3.0),
          "regime-chapter2": ((2000, 150, 0.45), (2000, 150, 0.45), None)}


def test_every_regime_part_has_a_source_entry_here():
    assert {n for n in part_names() if n.startswith("regime-")} == set(SOURCE)
    assert not set(part_names()) & set(preset_names())


@pytest.mark.parametrize("part", sorted(SOURCE))
def test_regime_parts_give_the_source_targets(part):
    start, end, t_end = SOURCE[part]
    scene = load_scene(f"band-4dof,{part}")
    regime = closed_loop(scene).regime
    rg = scene.cvt.regime
    for t, (n1, M1, i) in ((0.0, start), (rg.ramp_time or 1.0, end)):
        w1, m1, ratio = regime.targets(t)
        assert (w1 / RPM, m1, ratio) == pytest.approx((n1, M1, i), rel=1e-12), (part, t)
    if t_end is not None:
        assert scene.solver.t_end == t_end
    # the machine is the preset's: parts set nothing outside the regime, solver span and output step
    assert scene.cvt.model == "band-4dof" and scene.cvt.chain == load_scene("band-4dof").cvt.chain


def test_list_and_comma_forms_merge_in_order_and_round_trip():
    listed = scene_from_dict({"preset": ["band-6+2n", "regime-A", "regime-B"]})
    comma = load_scene("band-6+2n, regime-A,regime-B")
    assert listed.data == comma.data
    assert listed.cvt.regime.kind == "speed-ramp" and listed.cvt.regime.end_value == pytest.approx(6000 * RPM)
    assert listed.data["preset"] == "band-6+2n, regime-A, regime-B"
    again = scene_from_dict(__import__("tomllib").loads(listed.to_toml()))
    assert again.data == listed.data
    own = scene_from_dict({"preset": ["band-6+2n", "regime-A"], "cvt": {"regime": {"torque": 99.0}}})
    assert own.cvt.regime.torque == 99.0 and own.cvt.regime.end_value == 380.0   # the scene's keys come last


def test_chain_parts_set_the_link_pattern():
    uniform = chain_geometry(load_scene("chain-S2,chain-uniform")).L
    random = chain_geometry(load_scene("chain-S2,chain-random")).L
    assert np.all(uniform == 0.009)
    assert sorted(set(random)) == [0.0085, 0.0095] and np.sum(random == 0.0095) == 42
    assert np.sum(random) == pytest.approx(84 * 0.009, rel=1e-12) == np.sum(uniform)


@pytest.mark.parametrize("value,needle", [
    ("regime-A", "is a part"),
    ("regime-A,chain-uniform", "are parts"),
    ("band-4dof,regime-Q", "did you mean"),
    ("band-4dof,,regime-A", "empty name"),
    (",".join(["band-4dof"] * 17), "at most 16"),
])
def test_bad_combinations_are_clear_errors(value, needle):
    with pytest.raises(InputError, match=needle):
        load_scene(value)


@pytest.mark.parametrize("value", [[], [1, 2], 3, ["band-4dof", None]])
def test_preset_value_must_be_names(value):
    with pytest.raises(InputError, match="must be a preset name or a list"):
        scene_from_dict({"preset": value})


def test_run_a_combination_from_the_command_line(cli, tmp_path):
    results = tmp_path / "r.h5"
    res = cli("run", "band-4dof,regime-A", "--until", "0.002", "--results", str(results))
    assert res.returncode == 0, res.stderr
    stored = read_results(results)
    assert 'preset = "band-4dof, regime-A"' in stored.scene_toml
    assert stored.series["driving.torque"][0] == pytest.approx(150.0, rel=1e-3)   # regime A starts at 150 N m
