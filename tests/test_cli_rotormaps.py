"""``cvtfem rotormaps`` through a real subprocess: ROSS's rotor_example against ROSS 3.1's numbers."""
import json
from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).resolve().parent / "data" / "ross"


def test_rotormaps_matches_ross_and_writes_figures(cli, tmp_path):
    ref = json.loads((DATA / "rotor_example.json").read_text())
    k = ref["ucs"]["stiffness"]
    r = cli("rotormaps", str(DATA / "rotor_example.toml"), "--stiffness", f"{k[0]}:{k[-1]}:{len(k)}",
            "--gravity", "9.8065", "--speed", "500rad/s", "--json", str(tmp_path / "m.json"),
            "--png", str(tmp_path / "m.png"))
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "m.json").read_text())
    assert d["supports"] == [0, 6]
    assert np.allclose(d["static_rigid_u2_m"], ref["static"]["disp_y"], rtol=1e-9, atol=1e-15)
    assert np.allclose(np.array(d["critical_wn_rad_s"]).T, ref["ucs"]["wn"], rtol=1e-8)
    assert np.allclose(d["modes"]["wd_rad_s"], ref["modal_500"]["wd"][:4], rtol=1e-8)
    # the constant kxx = 1 MN/m crosses mode 1 where ROSS's map does (1e6 is on its grid: exact there)
    assert d["crossings"][0]["speed_rad_s"] == pytest.approx(ref["ucs"]["intersection_speed"][0], rel=1e-8)
    # on the (softer) bearings the shaft sags more than on rigid supports, by the bearing compression
    weight = -min(d["static_bearings_u2_m"][0], d["static_bearings_u2_m"][-1])
    assert weight > 0 and min(d["static_bearings_u2_m"]) < min(d["static_rigid_u2_m"])
    for name in ("m.png", "m_static.png", "m_shapes.png"):
        assert (tmp_path / name).stat().st_size > 10_000


def test_rotormaps_bad_input_one_line_exit_2(cli):
    cases = [("friswell_5_9_1", "--stiffness", "1e9:1e5:10"), ("friswell_5_9_1", "--supports", "0,99"),
             ("engine_gear_train",)]
    for args in cases:
        r = cli("rotormaps", *args)
        assert r.returncode == 2, (args, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr, r.stderr
