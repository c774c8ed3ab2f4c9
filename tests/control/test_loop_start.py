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


@pytest.mark.slow
def test_s1_seeded_at_its_clamping_ratio_drifts_towards_the_target():
    """S1 on rigid shafts (band-6+2n scene values, reference chain), stationary regime, loops on: started at its
    measured clamping ratio F1/F2 = 1.00 (``studies/chain/clamping_ratio.py``, docs/chain.md) against the source's
    zero start (the band's 0.8335).

    Linearised, the ratio loop on a chain is ``e' = k (F1 - F1*)``, ``F1 = F1a + c_f0 e + F11``, ``F11' = c_f1 e``
    (k ~ -6.8e-5 1/(s N) for S1, from the open-loop drifts +0.37 / -0.64 1/s at F1/F2 0.8335 / 1.25), and its
    equilibrium is ``e = 0``, ``F11 = F1* - F1a``.  The zero start is 5.9 kN short of it: the ratio error grows
    (drift away from the target) until the integral has moved F1 over ~0.3 s.  The seeded start is at the integral's
    equilibrium; only the speed ratio's slip offset (w1/w2 ~ 2.415 at the geometric 2.4) is left, which the
    proportional part turns into a drift towards the target.  Asserted over 5-10 ms of rock4 (rtol 1e-4; 164 s wall
    at load 11): the seeded run drifts towards 2.4 (drift and error of opposite signs; observed -0.12 1/s at
    +0.57 %), the zero start away from it (+0.15 1/s at +0.71 %); the seeded mean error is the smaller and within
    1 %; the integral (F1 less the proportional part) stays within 1 kN of its seeded start (it integrates c_f1 e,
    below ~300 N over 10 ms at e < 1 %), while the zero start's is still more than 4 kN below that equilibrium."""
    from cvtfem.elements.chain.geometry import reference_geometry
    from cvtfem.integrate import solve
    from cvtfem.machines.chain_cvt import from_scene

    scene = load_scene("band-6+2n")
    band = build_model(scene)
    o = band.outputs(0.0, band.initial_state())
    F = np.array([o["driving.clamping_force"], o["driven.clamping_force"]])
    rg = scene.cvt.regime
    t_eval = np.linspace(5e-3, 10e-3, 201)
    out = {}
    for name, sc in (("zero", scene), ("seeded", seeded(scene, 1.0))):
        m = from_scene(sc, reference_geometry(), F, model="chain-S1", contact="rigid")
        x0, _ = m.static_state(rg.ratio, rg.input_speed)
        res = solve(m, (0.0, t_eval[-1]), x0, method="rock4", rtol=1e-4, atol=1e-7, n2=m.n2, jac=m.jac,
                    jac_sparsity=m.jac_sparsity, t_eval=t_eval)
        assert res.status == 0
        outs = [m.outputs(t, y) for t, y in zip(res.t, res.y.T)]
        e = np.array([o["ratio"] for o in outs]) / rg.ratio - 1
        F1 = np.array([o["driving.clamping_force"] for o in outs])
        F11 = F1 - F[0] - sc.cvt.control.c_f0 * (np.array([o["control.ratio_estimate"] for o in outs]) - rg.ratio)
        out[name] = (e.mean(), np.polyfit(res.t, e, 1)[0], F11)
        print(f"{name}: mean ratio error {e.mean():+.4f}, drift {np.polyfit(res.t, e, 1)[0] * rg.ratio:+.3f} 1/s, "
              f"F1 {F1.mean():.0f} N (F1/F2 {F1.mean() / F[1]:.4f}), integral {F11[0]:.0f} -> {F11[-1]:.0f} N")
    (e0, r0, F11_zero), (e1, r1, F11_seeded) = out["zero"], out["seeded"]
    assert e0 * r0 > 0 and e1 * r1 < 0
    assert abs(e1) < abs(e0) and abs(e1) < 0.01
    np.testing.assert_allclose(F11_seeded, F[1] - F[0], atol=1000.0)
    assert np.all(F11_zero < F[1] - F[0] - 4000.0)
