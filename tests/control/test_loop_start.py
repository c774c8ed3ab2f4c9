"""Start of the ratio loop's integral F11(0): at zero (the source) or at the chain's own clamping ratio."""
import numpy as np
import pytest

from cvtfem.control.loop_start import integral_start
from cvtfem.control.stabilisation import Stabilisation, StabilisationParams
from cvtfem.errors import InputError
from cvtfem.machines import build_model
from cvtfem.scene.loader import load_scene

F_APPL = np.array([29628.0, 35546.0])      # N, the band's split at the stationary regime (F1/F2 0.8335)


def seeded(scene, rho):
    return scene.replace({"cvt": {"control": {"ratio_loop_start": "force-ratio", "start_force_ratio": rho}}})


def test_the_seeded_integral_starts_f1_at_the_force_ratio():
    assert integral_start("zero", 0.0, F_APPL, 2.5) == 0.0
    F11 = integral_start("force-ratio", 1.094, F_APPL, 2.5)
    assert F11 == pytest.approx(1.094 * F_APPL[1] - F_APPL[0], rel=1e-15)
    ctl = Stabilisation(StabilisationParams(F11_start=F11))
    w1, i = 366.5, 2.4
    z0 = ctl.initial_state(w1, w1 / i)
    assert z0[2] == F11 and z0[3] == 0.0
    # at the target ratio the proportional part is zero: the first force is the seeded one, F1 = 1.094 F2
    F, _, dz, d = ctl.outputs(np.array([w1, w1 / i]), z0, i, w1 / i, 200.0, F_APPL)
    assert F[0] == pytest.approx(1.094 * F_APPL[1], rel=1e-12) and F[1] == F_APPL[1]
    assert not d["sat1"] and dz[2] == pytest.approx(0.0, abs=1e-6)


def test_a_seeded_band_scene_starts_at_its_force_ratio():
    """Through the scene: the band-6+2n preset's model with ``ratio_loop_start = 'force-ratio'`` starts the F1
    integral at ``rho F2 - F1a`` and applies ``rho F2`` at t = 0; the default start is the source's zero."""
    scene = load_scene("band-6+2n")
    plain = build_model(scene)
    x = plain.initial_state()
    o = plain.outputs(0.0, x)
    F1a, F2 = o["driving.clamping_force"], o["driven.clamping_force"]
    assert F1a / F2 == pytest.approx(0.8335, abs=1e-4)         # the band's Euler-arc ratio (docs/chain.md)
    m = build_model(seeded(scene, 1.0))
    xs = m.initial_state()
    assert m.control.p.F11_start == pytest.approx(F2 - F1a, rel=1e-12)
    np.testing.assert_array_equal(xs[:-8], x[:-8])                # same mechanical start
    os = m.outputs(0.0, xs)
    assert os["driving.clamping_force"] == pytest.approx(F2, rel=1e-9)
    assert os["driven.clamping_force"] == F2


@pytest.mark.parametrize("control, key, match", [
    ({"ratio_loop_start": "held-arc"}, "cvt.control.ratio_loop_start", "one of 'zero', 'force-ratio'"),
    ({"ratio_loop_start": "force-ratio"}, "cvt.control.start_force_ratio", "must be set"),
    ({"start_force_ratio": 1.1}, "cvt.control.start_force_ratio", "would be ignored"),
    ({"ratio_loop_start": "force-ratio", "start_force_ratio": -1.0}, "cvt.control.start_force_ratio", ">= 0"),
    ({"ratio_loop_start": "force-ratio", "start_force_ratio": "1.1"}, "cvt.control.start_force_ratio", "number"),
])
def test_bad_start_values_are_named(control, key, match):
    with pytest.raises(InputError, match=match) as err:
        load_scene("band-6+2n").replace({"cvt": {"control": control}})
    assert err.value.where == key


def test_a_start_beyond_the_saturation_band_is_named():
    """F1 = rho F2 must lie within [F1a / k_sat, k_sat F1a]: with k_sat 2.5 and F1a/F2 = 0.8335, rho in
    0.333 .. 2.084."""
    for rho in (0.3, 2.1):
        with pytest.raises(InputError, match="saturation band 0.3334 .. 2.084") as err:
            integral_start("force-ratio", rho, F_APPL, 2.5)
        assert err.value.where == "cvt.control.start_force_ratio" and err.value.value == rho
    with pytest.raises(InputError, match="saturation band") as err:
        build_model(seeded(load_scene("band-6+2n"), 2.5))
    assert err.value.where == "cvt.control.start_force_ratio"
    with pytest.raises(InputError) as err:
        integral_start("secant", 1.0, F_APPL, 2.5)
    assert err.value.where == "cvt.control.ratio_loop_start"
