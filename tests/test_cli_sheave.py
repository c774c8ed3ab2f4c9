"""`cvtfem sheave`: the CLI path of the solid-sheave spectrum, wedge opening and renderings."""
import json

import numpy as np
import pytest


def test_sheave_spectrum_opening_and_pngs(cli, tmp_path):
    js, png = tmp_path / "s.json", tmp_path / "mode.png"
    r = cli("sheave", "cvt_sheave_shaft", "--diameters", "2", "--modes", "1", "--speed", "6000rpm", "--load", "20000",
            "--mesh", "12,2", "--json", str(js), "--png", str(png), "--mode", "2,0")
    assert r.returncode == 0, r.stderr
    data = json.loads(js.read_text())
    omega = 6000 * np.pi / 30
    rows = data["modes"]
    assert sorted((row["n"], row["wave"]) for row in rows) == [(0, "standing")] * 2 + [(n, w) for n in (1, 2)
                                                                                      for w in ("bw", "fw")]
    for row in rows:      # a fixed observer sees the wave of n diameters at f +- n Omega / 2 pi
        sense = {"fw": 1, "bw": -1, "standing": 0}[row["wave"]]
        assert row["fixed_hz"] - row["rotating_hz"] == pytest.approx(sense * row["n"] * omega / (2 * np.pi), rel=1e-12)
    assert 1e-6 < data["rim_opening_m"] < 1e-3                  # the face moves back under the clamping load
    for path in (png, tmp_path / "mode_load.png"):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_sheave_bad_input_is_one_line(cli):
    for args, key in ((("friswell_5_9_1",), "disk"), (("cvt_sheave_shaft", "--disk", "1"), None),
                      (("cvt_sheave_shaft", "--disk", "5"), "--disk"), (("cvt_sheave_shaft", "--mesh", "3"), "--mesh"),
                      (("cvt_sheave_shaft", "--diameters", "400"), "--diameters"),
                      (("cvt_sheave_shaft", "--load", "nan"), "--load")):
        r = cli("sheave", *args)
        if key is None:                                          # disk 1 is the movable sheave: a valid choice
            assert r.returncode == 0, r.stderr
            continue
        assert r.returncode == 2, (args, r.stderr)
        assert key in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_modes_and_campbell_with_reduced_sheaves(cli, tmp_path):
    """`[sheave] flexibility = "reduced"` on the preset: `cvtfem modes` gives shapes per node (the sheaves' modal
    coordinates left out) and the sheaves' own n = 2 waves, which a fixed observer sees 2 n Omega / 2 pi apart
    (less the small Coriolis split of the rotating frame); `cvtfem campbell` writes them as lines."""
    from cvtfem.scene.loader import preset_text

    scene = tmp_path / "flexible.toml"
    scene.write_text(preset_text("cvt_sheave_shaft")
                     + '\n[sheave]\nflexibility = "reduced"\nmodes = 4\ncells_radial = 8\ncells_axial = 1\n'
                       'diameters = 2\n')
    js = tmp_path / "m.json"
    r = cli("modes", str(scene), "--speed", "6000rpm", "--n-modes", "6", "--json", str(js), "--shapes")
    assert r.returncode == 0, r.stderr
    data = json.loads(js.read_text())
    assert np.array(data["shape_real"]).shape == (6, 12, 6)          # 11 shaft nodes + the elastic sheave's node
    waves = {w["label"]: w["hz"] for w in data["sheave_waves"]}
    assert set(waves) == {f"disk {i} sheave n=2 {w}" for i in (0, 1) for w in ("fw", "bw")}
    for i in (0, 1):
        gap = waves[f"disk {i} sheave n=2 fw"] - waves[f"disk {i} sheave n=2 bw"]
        assert gap == pytest.approx(2 * 2 * 6000 / 60, rel=0.05)
    js = tmp_path / "c.json"
    r = cli("campbell", str(scene), "--speeds", "0:6000rpm:3", "--n-modes", "6", "--json", str(js))
    assert r.returncode == 0, r.stderr
    lines = {w["label"]: w["hz"] for w in json.loads(js.read_text())["sheave_waves"]}
    assert lines["disk 0 sheave n=2 fw"][0] == pytest.approx(lines["disk 0 sheave n=2 bw"][0], rel=1e-12)
    assert lines["disk 0 sheave n=2 fw"][-1] == pytest.approx(waves["disk 0 sheave n=2 fw"], rel=1e-9)
