"""`cvtfem sheave`: the CLI path of the solid-sheave spectrum, wedge opening and renderings."""
import json

import numpy as np


def test_sheave_spectrum_opening_and_pngs(cli, tmp_path):
    js, png = tmp_path / "s.json", tmp_path / "mode.png"
    r = cli("sheave", "cvt_sheave_shaft", "--diameters", "2", "--modes", "1", "--speed", "6000rpm", "--load", "20000",
            "--mesh", "12,2", "--json", str(js), "--png", str(png), "--mode", "2,0")
    assert r.returncode == 0, r.stderr
    data = json.loads(js.read_text())
    omega = 6000 * np.pi / 30
    rows = data["modes"]
    assert {(row["n"], row["family"]) for row in rows} == {(0, "cos"), (0, "sin"), (1, "cos"), (2, "cos")}
    for row in rows:      # a fixed observer sees the wave of n diameters at f +- n Omega / 2 pi
        np.testing.assert_allclose([row["forward_hz"] - row["rotating_hz"], row["rotating_hz"] - row["backward_hz"]],
                                   row["n"] * omega / (2 * np.pi), rtol=1e-12)
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
