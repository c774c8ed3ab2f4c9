"""Hard cases of the compressible band model band-6+2n (issue 7): ratio limits, torque reversal and a torque
ramp towards zero, with n = 2 Ritz functions per arc and 8 quadrature nodes to keep the runs quick."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.errors import InputError
from cvtfem.io.results import read_results
from cvtfem.scene.loader import load_scene

pytestmark = pytest.mark.hard

RPM = 30 / np.pi
SMALL = {"ritz_order": 2, "quadrature_nodes": 8}


def _scene(**regime):
    return load_scene("band-6+2n", {"cvt": {**SMALL, "regime": regime}})


def _imbalance(path):
    """max |(E - E0) - (W_in - W_out + W_clamp - W_diss)| / W_in(end) over every output sample."""
    res = read_results(path)
    W, E = res.series["work"], res.series["energy"]
    E = E if E.ndim == 1 else E.sum(axis=1)
    assert np.all(np.isfinite(W)) and np.all(np.isfinite(E))
    return np.abs((E - E[0]) - (W[:, 0] - W[:, 1] + W[:, 3] - W[:, 2])).max() / W[-1, 0]


@pytest.mark.timeout(120)
@pytest.mark.parametrize("ratio", [0.43, 2.4])
def test_ratio_limits_are_held_with_balanced_power(ratio, tmp_path):
    """At both ends of the ratio range (3500 rpm, 200 N m, 0.05 s): ratio and input speed held to 2e-3
    (measured 0.430518 / 2.404541, 3504.2 / 3506.5 rpm), efficiency in (0.98, 1) (0.9842 / 0.9934),
    slips below 2 v0, positive normal forces along both arcs, and the energy balance of the work
    integrals closed to 1e-6 W_in at every output (measured 2.5e-8 / 2.0e-8)."""
    scene = _scene(ratio=ratio)
    s = run_scene(scene, until=0.05, results=tmp_path / "r.h5", show_progress=False)
    assert s.status == "finished"
    assert s.ratio == pytest.approx(ratio, rel=2e-3)
    assert s.input_speed_rpm == pytest.approx(scene.cvt.regime.input_speed * RPM, rel=2e-3)
    assert 0.98 < s.efficiency < 1.0 and 0.98 < s.efficiency_kinetic < 1.0
    assert max(abs(v) for v in s.slip_speed_m_s) < 2 * scene.cvt.friction.v0
    assert _imbalance(tmp_path / "r.h5") <= 1e-6
    N = read_results(tmp_path / "r.h5").series["band.normal_force"]
    assert np.all(np.isfinite(N)) and N.min() > 0


def test_torque_reversal_is_rejected_at_load(cli, tmp_path):
    """A negative driving torque is a validation error for the band-6+2n model as for band-4dof;
    the CLI exits 2 with the one line."""
    with pytest.raises(InputError) as err:
        _scene(torque=-200.0)
    assert str(err.value).startswith("`cvt.regime.torque` must be >= 0 N m, got -200.0")
    scene = tmp_path / "reverse.toml"
    scene.write_text('preset = "band-6+2n"\n[cvt]\nritz_order = 2\n[cvt.regime]\ntorque = -50.0\n', encoding="utf-8")
    res = cli("run", str(scene), "--until", "0.01", "--results", "none")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "`cvt.regime.torque` must be >= 0 N m, got -50.0" in res.stderr


@pytest.mark.timeout(120)
def test_torque_ramp_towards_reversal_stays_stable(tmp_path):
    """Torque ramp 200 -> 1e-3 N m in 0.05 s, 0.1 s simulated (the edge of a reversal): finishes with the
    ratio held (2.39897), clamping on the 1 kN floor (F2 = 1.2 F1 by the equilibrium split), slips far
    below v0 and the energy balance closed (2.5e-8 W_in). The plain efficiency over the last window
    (W_out / W_in = 2.50) is meaningless at ~0 input power (kinetic energy comes back); the
    kinetic-energy corrected one stays below 1 (0.801)."""
    scene = _scene(kind="torque-ramp", torque=200.0, end_value=1e-3, ramp_time=0.05)
    s = run_scene(scene, until=0.1, results=tmp_path / "r.h5", show_progress=False)
    assert s.status == "finished" and s.ratio == pytest.approx(2.4, rel=2e-3)
    assert s.clamping_force_N[0] == pytest.approx(scene.cvt.regime.min_clamping_force, rel=1e-2)
    assert max(abs(v) for v in s.slip_speed_m_s) < 1e-2 * scene.cvt.friction.v0
    assert 0 < s.efficiency_kinetic < 1
    assert _imbalance(tmp_path / "r.h5") <= 1e-6
