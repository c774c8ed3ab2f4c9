"""A key the scene's model does not read is refused when the scene changes it (house rule: never a silently ignored
key). Found in session 11: `cvt.driving.tilt_stiffness` 10x higher ran variant (b) step for step as before."""
from __future__ import annotations

import tomllib

import pytest

from cvtfem.errors import InputError
from cvtfem.scene.loader import load_scene, scene_from_dict
from cvtfem.scene.schema.cvt import BAND_UNREAD, CHAIN_UNREAD, ELASTIC_SHAFT_KEYS


@pytest.mark.parametrize("key", sorted(CHAIN_UNREAD))
def test_a_chain_scene_changing_a_band_only_key_is_refused(key):
    shaft, name = key.split(".")[1:]
    doc = {"preset": ["variant-b", "regime-stationary"], "cvt": {shaft: {name: 1.2345e9}}}
    with pytest.raises(InputError, match=rf"`{key}` is not read by `chain-A1`.*got 1234500000"):
        scene_from_dict(doc)


def test_the_same_keys_pass_where_they_are_read_or_unchanged():
    band = scene_from_dict({"preset": "band-6+2n+8", "cvt": {"driving": {"tilt_stiffness": 1.2345e9}}})
    assert band.cvt.driving.tilt_stiffness == 1.2345e9                   # band-6+2n+8 reads it
    chain = load_scene("variant-b")
    same = scene_from_dict({"preset": "variant-b",
                            "cvt": {"driving": {"tilt_stiffness": chain.cvt.driving.tilt_stiffness}}})
    assert same.cvt.driving.tilt_stiffness == chain.cvt.driving.tilt_stiffness   # the presets' value: accepted
    stored = scene_from_dict(tomllib.loads(chain.to_toml()))             # a results file's resolved scene
    assert stored.data == chain.data


def test_cvtfem_run_refuses_it_in_one_line(tmp_path, cli):
    scene = tmp_path / "s.toml"
    scene.write_text('preset = "chain-S2"\n[cvt.driven]\nradial_stiffness = 3e8\n')
    res = cli("run", str(scene), "--until", "1e-5", "--results", "none")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    line = res.stderr.strip()
    assert len(line.splitlines()) == 1 and "`cvt.driven.radial_stiffness`" in line and "chain-S2" in line, line


def test_the_pin_face_keys_are_refused_where_they_are_not_read():
    """The face inclination is the refined contact's (H2) only; the crown radius sets every Hertz contact's constant;
    a band model reads neither (session 12)."""
    with pytest.raises(InputError, match=r"`cvt.chain.face_inclination` is not read by `chain-S2`.*got 0.1"):
        scene_from_dict({"preset": "chain-S2", "cvt": {"chain": {"face_inclination": 0.1}}})
    with pytest.raises(InputError, match=r"`cvt.chain.face_radius` is not read by `band-6\+2n`.*got 0.01"):
        scene_from_dict({"preset": "band-6+2n", "cvt": {"chain": {"face_radius": 0.01}}})
    with pytest.raises(InputError, match=r"`cvt.chain.face_inclination` is not read by `band-4dof`"):
        scene_from_dict({"preset": "band-4dof", "cvt": {"chain": {"face_inclination": 0.1}}})
    h1 = scene_from_dict({"preset": "chain-S2", "cvt": {"chain": {"face_radius": 0.01}}})
    assert h1.cvt.chain.face_radius == 0.01                               # H1's Hertz constant
    a = scene_from_dict({"preset": "variant-a", "cvt": {"chain": {"face_inclination": 0.1, "face_radius": 0.01}}})
    assert (a.cvt.chain.face_inclination, a.cvt.chain.face_radius) == (0.1, 0.01)
    with pytest.raises(InputError, match="face_inclination"):
        scene_from_dict({"preset": "variant-a", "cvt": {"chain": {"face_inclination": 0.8}}})   # beyond pi/4


@pytest.mark.parametrize("key", sorted(ELASTIC_SHAFT_KEYS))
def test_the_elastic_shaft_keys_are_refused_on_rigid_shafts_and_band_models(key):
    """The beam and bearing keys are read by a discrete chain on elastic shafts only (session 12's audit)."""
    shaft, name = key.split(".")[1:]
    value = load_scene("variant-b").data["cvt"][shaft][name] * 2
    with pytest.raises(InputError, match=rf"`{key}` is not read by `chain-A1`"):
        scene_from_dict({"preset": "variant-a", "cvt": {shaft: {name: value}}})             # A1 on rigid shafts
    with pytest.raises(InputError, match=rf"`{key}` is not read by `band-6\+2n\+8`"):
        scene_from_dict({"preset": "band-6+2n+8", "cvt": {shaft: {name: value}}})
    elastic = scene_from_dict({"preset": "variant-b", "cvt": {shaft: {name: value}}})      # read there
    assert elastic.data["cvt"][shaft][name] == value


@pytest.mark.parametrize("doc", [
    {"preset": "chain-S2"}, {"preset": "chain-S1"}, {"preset": "variant-zh"}, {"preset": "band-6+2n"},
    {"preset": "band-6+2n+8"}, {"preset": "band-4dof"},
    {"preset": "variant-a", "cvt": {"effects": {"contact": "hertz"}}},
    {"preset": "variant-a", "cvt": {"effects": {"contact": "impact"}}},
], ids=lambda d: f"{d['preset']}-{d.get('cvt', {}).get('effects', {}).get('contact', 'preset')}")
def test_the_presets_inclined_face_does_not_refuse_a_model_that_does_not_read_it(doc):
    """Since session 13 `reference_cvt` inclines the pin face at the flank angle: every scene on it whose model does
    not read `face_inclination` (H1, impact, rigid contacts, band models) loads, the presets' 10 deg unread."""
    scene = scene_from_dict(doc)
    assert scene.cvt.chain.face_inclination == scene.cvt.geometry.flank_angle > 0
    assert (scene.cvt.model.startswith("band") or scene.cvt.effects.contact != "hertz-refined")


def test_a_face_inclination_written_for_a_model_that_does_not_read_it_is_still_refused():
    """Written by the scene itself and unread: refused, whatever its presets; the presets' value (10 deg) and the
    schema's neutral default (0, every stored scene before session 13) pass."""
    for doc, model in (({"preset": "variant-a", "cvt": {"effects": {"contact": "hertz"}}}, "chain-A1"),
                       ({"preset": "chain-S1"}, "chain-S1"), ({"preset": "band-6+2n+8"}, "band-6\\+2n\\+8")):
        bad = {**doc, "cvt": {**doc.get("cvt", {}), "chain": {"face_inclination": 0.1}}}
        with pytest.raises(InputError, match=rf"`cvt.chain.face_inclination` is not read by `{model}`.*presets' "
                                             r"value 0.1745.* or the default 0.0 .*got 0.1$"):
            scene_from_dict(bad)
        for value in (load_scene("variant-a").cvt.geometry.flank_angle, 0.0):
            ok = {**doc, "cvt": {**doc.get("cvt", {}), "chain": {"face_inclination": value}}}
            assert scene_from_dict(ok).cvt.chain.face_inclination == value
    stored = tomllib.loads(load_scene("chain-S2").to_toml())           # a results file's scene before session 13
    stored["cvt"]["chain"]["face_inclination"] = 0.0
    assert scene_from_dict(stored).cvt.chain.face_inclination == 0.0


@pytest.mark.parametrize("key", sorted(BAND_UNREAD))
def test_the_discrete_chains_keys_are_refused_on_band_models(key):
    """Pins, plates, links and the pin-sheave contact model are the discrete chain's: a band model reads none of them
    (session 13's audit); a discrete chain does."""
    table, name = key.split(".")[1:]
    chain = load_scene("variant-b").data["cvt"][table][name]
    value = "hertz" if name == "contact" else chain * 2
    for preset in ("band-4dof", "band-6+2n", "band-6+2n+8"):
        with pytest.raises(InputError, match=rf"`{key}` is not read by `{preset.replace('+', chr(92) + '+')}`"):
            scene_from_dict({"preset": preset, "cvt": {table: {name: value}}})
    read = scene_from_dict({"preset": "variant-b", "cvt": {table: {name: value}}})
    assert read.data["cvt"][table][name] == value
