"""Campbell: MAC tracking, excitation lines, critical speeds, CLI."""
import json

import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem, campbell, chain_orders, shaft_orders
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def friswell():
    m = build_model(load_scene("friswell_5_9_1"))
    return ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)


def test_tracking_follows_whirl_through_crossing_curves(friswell):
    """The backward 3rd pair and the (gyro-free) torsional mode cross near 3000 rpm; MAC keeps identities."""
    res = campbell(friswell, np.linspace(0, 4000 * np.pi / 30, 26), 8)
    for j in range(8):
        assert len(set(res.whirl[1:, j])) == 1          # each tracked curve keeps its class over speed
    tors = np.flatnonzero(res.whirl[-1] == "torsional")[0]
    assert np.ptp(res.wd[:, tors]) < 1e-8 * res.wd[0, tors]    # torsion does not depend on speed
    fw = res.whirl[-1] == "forward"
    assert np.all(np.diff(res.wd[:, fw], axis=0) > 0)     # forward branches rise (spec §4.4)


def test_critical_speeds_lie_on_the_lines(friswell):
    res = campbell(friswell, np.linspace(0, 4000 * np.pi / 30, 41), 4, shaft_orders((1.0, 2.0)))
    assert len(res.crossings) == 8
    for c in res.crossings:
        k = float(c["order"].rstrip("x"))
        modes = friswell.solve(c["speed_rad_s"], 4)
        err = np.min(np.abs(modes.wd - k * c["speed_rad_s"])) / c["frequency_rad_s"]
        assert err < 2e-3, c                               # linear interpolation between 41 speeds


def test_chain_orders():
    lines = dict(chain_orders(radius=0.05, chain_length=0.8, link_length=0.009, k_chain=2, k_link=3))
    assert lines["1 f_chain"] == pytest.approx(2 * np.pi * 0.05 / 0.8)
    assert lines["3/3 f_link"] == pytest.approx(2 * np.pi * 0.05 / 0.009)
    with pytest.raises(InputError, match="link_length"):
        chain_orders(0.05, 0.8, 0.0)


def test_cli_modes_and_campbell(cli, tmp_path):
    out = tmp_path / "m.json"
    r = cli("modes", "friswell_5_9_1", "--speed", "4000rpm", "--json", str(out), "--shapes")
    assert r.returncode == 0, r.stderr
    data = json.loads(out.read_text())
    for key in ("speed_rad_s", "wn_rad_s", "wd_rad_s", "damping_ratio", "whirl"):
        assert key in data
    assert data["wd_rad_s"] == sorted(data["wd_rad_s"])
    np.testing.assert_allclose(data["wd_rad_s"][:2], [85.39, 87.80], rtol=1e-3)
    shape = np.array(data["shape_real"][1]) + 1j * np.array(data["shape_imag"][1])
    assert shape.shape == (7, 6) and np.max(np.abs(shape)) == pytest.approx(1.0)
    assert np.imag(np.vdot(shape[:, 0], shape[:, 1])) < 0          # forward orbit: Im(conj(u1) u2) < 0
    js, csv = tmp_path / "c.json", tmp_path / "c.csv"
    r = cli("campbell", "friswell_5_9_1", "--speeds", "0:4000rpm:11", "--n-modes", "4", "--json", str(js),
            "--csv", str(csv))
    assert r.returncode == 0, r.stderr
    c = json.loads(js.read_text())
    assert len(c["per_speed"]) == 11 and "whirl" in c["per_speed"][0]
    assert len(csv.read_text().splitlines()) == 1 + 11 * 4
    r = cli("campbell", "friswell_5_9_1", "--speeds", "0:4000:11")
    assert r.returncode == 2 and "--speeds" in r.stderr


def test_overdamped_mode_has_no_critical_speed():
    """A mode damped near critically (zeta ~0.9) crossing the 1x line is not a critical speed (API 684:
    amplification factor below 2.5); the lightly damped mode crossing it still is (issue 18)."""
    from cvtfem.modal.campbell import CRITICALLY_DAMPED, crossings

    speeds = np.linspace(0.0, 200.0, 5)
    wd = np.column_stack([np.full(5, 110.0), np.full(5, 140.0)])
    zeta = np.column_stack([np.full(5, 0.9), np.full(5, 0.01)])
    whirl = np.full((5, 2), "forward")
    found = crossings(speeds, wd, whirl, zeta, (("1x", 1.0),))
    assert [c["mode"] for c in found] == [1] and found[0]["speed_rad_s"] == pytest.approx(140.0)
    assert found[0]["damping_ratio"] == pytest.approx(0.01) and CRITICALLY_DAMPED == 0.2


def test_tracking_flags_a_lost_mode():
    """MAC tracking records where a tracked mode's shape has no match at the next speed."""
    from cvtfem.modal.campbell import MAC_JUMP, track
    from cvtfem.modal.eigen import Modes

    e = np.eye(3, dtype=complex)
    first = Modes(0.0, np.array([1j, 2j]), e[:, :2], ("forward", "forward"), np.ones(2))
    swapped = Modes(1.0, np.array([1j, 2j]), e[:, [1, 2]], ("forward", "forward"), np.ones(2))
    index, match = track([first, swapped], 2)
    assert index[1].tolist() == [1, 0] and match[1].tolist() == [0.0, 1.0] and MAC_JUMP == 0.5


def test_speeds_returning_different_mode_counts_are_tracked():
    """A speed may return more converged modes than another (``min_modes`` only bounds from below): the tracked
    arrays take each speed's own modes (the slow fuzzer's friswell_5_9_1 with a heavy disk and a negative bearing
    stiffness stacked ragged lists)."""
    scene = load_scene("friswell_5_9_1").replace({"disk": [{"node": 2, "mass": 32.59, "Id": 0.1781, "Ip": 29807481.0},
                                                           {"node": 4, "mass": 51.53, "Id": 0.4236, "Ip": 0.8051}],
                                                  "bearing": [{"node": 0, "kxx": 1e6, "kyy": 1e6},
                                                              {"node": 6, "kxx": -1e6, "kyy": 1e6}]})
    m = build_model(scene)
    problem = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)
    speeds = np.array([0.0, 157.07963267948966, 314.1592653589793])
    modes = [problem.solve(s, 16, min_modes=12) for s in speeds]
    assert len({len(m.wd) for m in modes}) > 1                      # the case: counts differ between speeds
    result = campbell(problem, speeds, 12)
    assert result.wd.shape == result.wn.shape == result.whirl.shape == (3, 12)
    assert np.all(result.wn >= 0)
