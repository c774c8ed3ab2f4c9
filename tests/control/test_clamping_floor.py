"""The clamping-force floor `cvt.regime.min_clamping_force` (a preload) reaches the prescribed forces."""
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.elements.band.equilibrium import forces_for_angle
from cvtfem.errors import InputError
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene


def _ramp_down(**regime):
    """Torque ramp 200 -> 5 N m in 0.02 s: the estimate (1.13) x 1.1 falls to ~0.9 kN, below an 8 kN floor."""
    return load_scene("band-4dof", {"cvt": {"regime": {"kind": "torque-ramp", "torque": 200.0, "end_value": 5.0,
                                                        "ramp_time": 0.02, **regime}}})


def test_floor_holds_the_forces_where_the_estimate_goes_below_it():
    scene = _ramp_down(min_clamping_force=8000.0)
    cl = closed_loop(scene).clamping
    rho = forces_for_angle(cl.span_angle(2.4), cl.p.sheaves, cl.p.length, cl.p.L)  # F1/F2 of ratio 2.4 (< 1)
    assert max(cl.safety * cl.estimates(5.0, 2.4)) < 1000.0  # the estimate alone would go below the floor
    assert cl.forces(5.0, 2.4) == pytest.approx([8000.0, 8000.0 / rho], rel=1e-12)  # equilibrium split: F1 = floor
    assert cl.forces(200.0, 2.4)[0] > 8000.0  # above the floor the estimate rules
    default = closed_loop(_ramp_down()).clamping
    assert default.f_min == 1000.0 and default.forces(5.0, 2.4)[0] == pytest.approx(1000.0, rel=1e-12)
    per_shaft = closed_loop(_ramp_down(min_clamping_force=8000.0, clamping_split="per-shaft")).clamping
    assert per_shaft.forces(5.0, 2.4) == pytest.approx([8000.0, 8000.0], rel=1e-12)


def test_floor_reaches_the_run():
    """After the ramp the uncontrolled driven force sits on the floor (F1 is the ratio loop's)."""
    scene = _ramp_down(min_clamping_force=8000.0)
    s = run_scene(scene, until=0.04, show_progress=False)
    F_floor = closed_loop(scene).clamping.forces(5.0, 2.4)
    assert s.clamping_force_N[1] == pytest.approx(F_floor[1], rel=1e-12)
    assert s.ratio == pytest.approx(2.4, rel=0.01)


@pytest.mark.parametrize("value", [0.0, -1.0])
def test_floor_must_be_positive(value):
    with pytest.raises(InputError, match="min_clamping_force"):
        _ramp_down(min_clamping_force=value)
