"""The discrete chain through `cvtfem run` and `cvtfem describe`: the CLI path of the chain transmission."""
import json

import h5py
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.machines import layout
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene


def test_run_chain_s2_balances_energy_and_holds_the_regime(cli, tmp_path):
    """2 ms of the chain-S2 preset from its quasi-static start: the work integrals close the energy balance
    (input - output - dissipated + clamping work = change of kinetic + elastic energy) to 1e-5 of the input
    work, every output is finite, the ratio stays at the target within 5 %, and over the second millisecond
    the pins' axial forces on each sheave balance its clamping force on average to 2 % (they swing +-4 % at
    the link-passing frequency)."""
    h5, js = tmp_path / "c.h5", tmp_path / "s.json"
    r = cli("run", "chain-S2", "--until", "2e-3", "--results", str(h5), "--summary-json", str(js), timeout=900)
    assert r.returncode == 0, r.stderr
    summary = json.loads(js.read_text())
    assert summary["ratio"] == pytest.approx(2.4, rel=0.05) and summary["n_coordinates"] == 256
    with h5py.File(h5) as f:
        s = f["series"]
        for name in s:
            assert np.isfinite(s[name][:]).all(), name
        W, E = s["work"][-1], s["energy"][:]
        assert abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-5 * W[0]
        late = s["time"][:] >= 1e-3 - 1e-12
        axial = s["contact.sheave_axial_force"][late]
        clamping = np.column_stack([s["driving.clamping_force"][late], s["driven.clamping_force"][late]])
    np.testing.assert_allclose(axial.mean(axis=0), clamping.mean(axis=0), rtol=0.02)


def test_describe_lists_every_output_of_the_running_chain_once():
    scene = load_scene("chain-S2")
    listed = [o.name for part in layout(scene) for o in part.outputs]
    assert sorted(listed) == sorted(o.name for o in chain_loop(scene).output_specs)
    assert sum(p.n2 for p in layout(scene)) == chain_loop(scene).n2


@pytest.mark.parametrize("override, key", [
    ({"cvt": {"model": "chain-A4", "effects": {"pin_bending": False}}}, "cvt.effects.pin_bending"),
    ({"cvt": {"model": "chain-S3", "effects": {"pin_bending": True, "contact": "hertz-refined",
                                               "shaft_elasticity": True}}}, "cvt.effects.shaft_elasticity"),
    ({"cvt": {"model": "chain-A2", "effects": {"contact": "impact", "pin_bending": True}}}, "cvt.effects.contact"),
    ({"cvt": {"model": "chain-S3"}}, "cvt.effects.pin_bending"),
    ({"cvt": {"effects": {"friction": False}}}, "cvt.effects.friction"),
])
def test_what_does_not_run_is_refused_by_name(override, key):
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        chain_loop(load_scene("chain-S2").replace(override))
