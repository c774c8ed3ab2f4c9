"""Low-order CVT regimes (issue 7): the ratio limits 0.43 and 2.4, start-up from zero speed,
torque reversal, gross slip under a too-low clamping force and stick under a very high one.

Model: band-4dof preset (reference CVT, 3500 rpm, 200 N m), closed by the stabilisation loops.
Checks are balances: the held ratio and input speed, the work-integral efficiency against the
one corrected by the stored energy (power balance d(T+V)/dt = P_in - P_out - D), and the
contact radii against the sheave limits r_min, r_max of the scene.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.elements.band.geometry import phi_for_ratio, radii
from cvtfem.errors import InputError
from cvtfem.io.results import read_results
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

pytestmark = pytest.mark.hard

RPM = 30 / math.pi


@pytest.fixture(scope="module")
def base():
    return load_scene("band-4dof")


def _regime(scene, **regime):
    return scene.replace({"cvt": {"regime": regime}})


@pytest.mark.timeout(120)
@pytest.mark.parametrize("ratio", [0.43, 2.4])
def test_ratio_limits_are_held_with_balanced_power(base, ratio, tmp_path):
    scene = _regime(base, ratio=ratio)
    p = closed_loop(scene).clamping.p
    r = radii(phi_for_ratio(ratio, p.length, p.L), p.length, p.L)[0]
    g = scene.cvt.geometry
    assert g.r_min * (1 - 1e-3) <= r.min() and r.max() <= g.r_max * (1 + 1e-3)   # 0.43, 2.4 are the limits
    s = run_scene(scene, until=0.05, results=tmp_path / "r.h5", show_progress=False)
    assert s.status == "finished"
    assert s.ratio == pytest.approx(ratio, rel=2e-3)
    assert s.input_speed_rpm == pytest.approx(scene.cvt.regime.input_speed * RPM, rel=2e-3)
    assert s.output_speed_rpm == pytest.approx(s.input_speed_rpm / s.ratio, rel=1e-12)
    assert 0.99 < s.efficiency < 1.0 and 0.99 < s.efficiency_kinetic < 1.0
    # energy balance at every output: E - E0 = W_in - W_out + W_clamp - W_dissipated
    res = read_results(tmp_path / "r.h5")
    W, E = res.series["work"], res.series["energy"]
    E = E if E.ndim == 1 else E.sum(axis=1)
    imbalance = (E - E[0]) - (W[:, 0] - W[:, 1] + W[:, 3] - W[:, 2])
    assert np.all(np.isfinite(W)) and np.abs(imbalance).max() <= 1e-4 * W[-1, 0]
    assert all(np.isfinite(s.slip_speed_m_s)) and all(f > 0 for f in s.clamping_force_N)
    assert max(abs(v) for v in s.slip_speed_m_s) < 2 * scene.cvt.friction.v0      # no gross slip


@pytest.mark.parametrize("key, value, text", [
    ("input_speed", 0.0, "`cvt.regime.input_speed` must be > 0 rad/s, got 0.0"),
    ("torque", -200.0, "`cvt.regime.torque` must be >= 0 N m, got -200.0")])
def test_zero_speed_start_and_torque_reversal_are_rejected_at_load(base, key, value, text):
    """The regimes cannot express a start from standstill (the ratio w1/w2 and the clamping
    estimate are undefined there) nor a negative driving torque: both are validation errors that
    name the key, the rule and the value."""
    with pytest.raises(InputError) as err:
        _regime(base, **{key: value})
    assert str(err.value).startswith(text)


def test_cli_reports_the_rejected_regime_with_exit_status_2(cli, tmp_path):
    scene = tmp_path / "reverse.toml"
    scene.write_text('preset = "band-4dof"\n[cvt.regime]\ntorque = -50.0\n')
    out = cli("run", str(scene), "--until", "0.01")
    assert out.returncode == 2
    assert "`cvt.regime.torque` must be >= 0 N m, got -50.0" in out.stderr
    assert "Traceback" not in out.stderr


@pytest.mark.timeout(120)
def test_very_high_clamping_force_sticks_with_tiny_slip(base):
    """20x the clamping estimate: slip speeds fall ~20x below those at the default 1.1x
    (friction is linear in the slip below v0), ratio and efficiency stay put."""
    nominal = run_scene(base, until=0.05, show_progress=False)
    high = run_scene(_regime(base, clamping_safety=20.0), until=0.05, show_progress=False)
    assert high.status == "finished"
    assert high.ratio == pytest.approx(2.4, rel=2e-3)
    slip_n, slip_h = np.abs(nominal.slip_speed_m_s), np.abs(high.slip_speed_m_s)
    assert np.all(slip_h < slip_n / 10)
    assert high.efficiency > nominal.efficiency and high.efficiency < 1.0


@pytest.mark.timeout(120)
def test_too_low_clamping_force_gives_gross_slip_not_nan(base):
    """0.3x the estimate cannot transmit 200 N m: the driven pulley slips grossly (slip speed far
    above v0), the ratio runs away from its target, and the run still ends with finite results."""
    s = run_scene(_regime(base, clamping_safety=0.3), until=0.05, show_progress=False)
    assert s.status == "finished"
    assert max(abs(v) for v in s.slip_speed_m_s) > 100 * base.cvt.friction.v0
    assert abs(s.ratio / 2.4 - 1) > 0.5
    assert s.efficiency < 0.5 and np.isfinite(s.efficiency)


@pytest.mark.slow
@pytest.mark.timeout(300)
def test_start_up_from_near_standstill(base):
    """A speed ramp from 1 rad/s (the smallest regime the schema allows is > 0) to 100 rad/s in
    0.05 s: the loops bring input speed and ratio to target without NaN (measured: 15.6 s wall)."""
    s = run_scene(_regime(base, kind="speed-ramp", input_speed=1.0, end_value=100.0, ramp_time=0.05),
                  until=0.15, show_progress=False)
    assert s.status == "finished"
    assert s.input_speed_rpm == pytest.approx(100.0 * RPM, rel=2e-3)
    assert s.ratio == pytest.approx(2.4, rel=2e-3)
    assert s.output_speed_rpm == pytest.approx(s.target_output_speed_rpm, rel=2e-3)


# -- formerly pending (tests/hard/pending_loworder.py), fixed ------------------------------------

@pytest.mark.parametrize("ratio", [0.3, 3.0, 5.0])
def test_ratio_outside_the_sheave_range_is_an_input_error(base, ratio):
    """The reference geometry (r_min = 0.036 m, r_max = 0.088 m, L = 0.1746 m, band 0.756 m) admits
    ratios 0.4164..2.4014; ratio 3.0 used to run with contact radii (0.0306, 0.0919) m, below the
    hub and beyond the rim.  The range's ends put one radius exactly on r_min or r_max."""
    from cvtfem.elements.band.geometry import admissible_ratio_range

    p = closed_loop(base).clamping.p
    g = base.cvt.geometry
    lo, hi = admissible_ratio_range(p.length, p.L, g.r_min, g.r_max)
    for i, limits in ((lo, (g.r_max, g.r_min)), (hi, (g.r_min, g.r_max))):
        r = radii(phi_for_ratio(i, p.length, p.L), p.length, p.L)[0]
        assert r[0] >= g.r_min * (1 - 1e-9) and r[1] >= g.r_min * (1 - 1e-9)
        assert r.max() <= g.r_max * (1 + 1e-9)
        assert min(abs(r[0] - limits[0]), abs(r[1] - limits[1])) < 1e-9   # one radius on its limit
    assert lo < 0.43 and 2.4 < hi
    with pytest.raises(InputError, match="cvt.regime.ratio") as err:
        closed_loop(_regime(base, ratio=ratio))
    assert f"{lo:.4f}..{hi:.4f}" in str(err.value) and f"got {ratio!r}" in str(err.value)


def test_ratio_change_ending_outside_the_sheave_range_is_an_input_error(base):
    with pytest.raises(InputError, match="cvt.regime.end_value") as err:
        closed_loop(_regime(base, kind="ratio-change", ratio=2.0, end_value=3.0, ramp_time=0.1))
    assert "cvt.regime.ratio" in str(err.value) and "got 3.0" in str(err.value)


def test_zero_torque_summary_has_no_nan(base, cli, tmp_path):
    """torque = 0 (allowed by the schema, ge=0): output over input work is 0/0.  The summary
    reports efficiency None (JSON null) with the reason, never NaN; speeds and ratio are held."""
    s = run_scene(_regime(base, torque=0.0), until=0.05, show_progress=False)
    assert s.status == "finished"
    assert s.efficiency is None and s.efficiency_kinetic is None
    assert "undefined" in s.efficiency_note and "input work 0 J" in s.efficiency_note
    floats = [v for v in s.to_dict().values() if isinstance(v, float)]
    floats += s.slip_speed_m_s + s.clamping_force_N
    assert all(math.isfinite(v) for v in floats)
    assert s.ratio == pytest.approx(2.4, rel=2e-3)
    scene, js = tmp_path / "zero.toml", tmp_path / "zero.json"
    scene.write_text('preset = "band-4dof"\n[cvt.regime]\ntorque = 0.0\n')
    out = cli("run", str(scene), "--until", "0.02", "--results", "none", "--summary-json", str(js))
    assert out.returncode == 0, out.stderr
    assert "NaN" not in js.read_text() and '"efficiency": null' in js.read_text()


@pytest.mark.timeout(120)
def test_torque_ramp_towards_zero_finishes_or_fails_clearly(base):
    """Torque ramp 200 -> 1e-3 N m over 0.05 s, 0.1 s simulated.  It used to stall: clamping forces
    (1.13) vanish with the torque (0.37 / 0.18 N), gross slip, the step collapsed to ~1e-13 s and
    stepped in place.  With the minimum clamping force (preload) MIN_CLAMPING_FORCE = 1 kN it
    finishes with the targets held and the floor on the pulleys (equilibrium split: F1 = f_min)."""
    from cvtfem.control.clamping import MIN_CLAMPING_FORCE

    scene = _regime(base, kind="torque-ramp", torque=200.0, end_value=1e-3, ramp_time=0.05)
    s = run_scene(scene, until=0.1, show_progress=False)
    assert s.status == "finished"
    assert s.ratio == pytest.approx(2.4, rel=2e-3)
    assert s.input_speed_rpm == pytest.approx(base.cvt.regime.input_speed * RPM, rel=2e-3)
    F_appl = closed_loop(scene).clamping.forces(1e-3, 2.4)      # floor: F1 = f_min, F2 = f_min / rho
    assert F_appl[0] == pytest.approx(MIN_CLAMPING_FORCE, rel=1e-12) and F_appl[1] > MIN_CLAMPING_FORCE
    assert s.clamping_force_N[1] == pytest.approx(F_appl[1], rel=1e-12)   # F2 is not controlled
    assert max(abs(v) for v in s.slip_speed_m_s) < base.cvt.friction.v0


@pytest.mark.timeout(120)
def test_stalled_step_size_is_a_clear_numerical_error(base):
    """The same ramp without the clamping floor reproduces the collapse; the run driver's stall guard
    (STALL_STEPS consecutive steps each < STALL_FRACTION t_end) stops it with a NumericalError that
    names the method, t, h and the likely cause instead of stepping in place until max_steps."""
    from cvtfem.analysis import run as run_mod
    from cvtfem.errors import NumericalError

    scene = _regime(base, kind="torque-ramp", torque=200.0, end_value=1e-3, ramp_time=0.05, min_clamping_force=1e-9)
    with pytest.raises(NumericalError) as err:
        run_scene(scene, until=0.1, show_progress=False)
    text = str(err.value)
    assert "step size stalled" in text and scene.solver.method in text
    assert f"{run_mod.STALL_STEPS} consecutive" in text and "last h = " in text and "at t = " in text
    assert "clamping forces" in text and "Likely cause" in text
    assert 0.05 < err.value.t < 0.1
