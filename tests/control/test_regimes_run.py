"""Non-stationary regimes through the run driver (spec 6.2): torque ramp, ratio change, efficiency forms."""
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.io.results import read_results
from cvtfem.post.history import windowed_efficiency
from cvtfem.scene.loader import load_scene


def test_torque_ramp_holds_targets_and_scales_clamping(tmp_path):
    scene = load_scene("band-4dof", {"cvt": {"regime": {"kind": "torque-ramp", "torque": 150.0, "end_value": 250.0,
                                                         "ramp_time": 0.3}}})
    s = run_scene(scene, until=0.5, results=tmp_path / "r.h5", show_progress=False)
    assert s.ratio == pytest.approx(2.4, rel=0.01)
    assert s.input_speed_rpm == pytest.approx(3500, rel=0.01)
    r = read_results(tmp_path / "r.h5")
    F2 = r.series["driven.clamping_force"][:, 0]
    assert F2[-1] / F2[0] == pytest.approx(250 / 150, rel=1e-9)  # (1.13): F proportional to M
    assert r.series["driving.torque"][-1, 0] == pytest.approx(250.0)


def test_ratio_change_needs_the_kinetic_energy_correction(tmp_path):
    scene = load_scene("band-4dof", {"cvt": {"regime": {"kind": "ratio-change", "ratio": 2.4, "end_value": 2.0,
                                                         "ramp_time": 0.4}}})
    run_scene(scene, until=0.6, results=tmp_path / "r.h5", show_progress=False)
    r = read_results(tmp_path / "r.h5")
    t, W, E = r.time, r.series["work"], r.series["energy"]
    late = t > 0.1
    plain = windowed_efficiency(t, W)[late]
    corrected = windowed_efficiency(t, W, energy=E)[late]
    assert plain.max() > 1.0  # shaft speeds change: plain output/input is not an efficiency
    assert 0.99 < corrected.min() and corrected.max() < 1.0
    ratio = r.series["ratio"][:, 0]
    assert ratio[-1] < 2.1 and ratio[0] == pytest.approx(2.4, rel=1e-3)
