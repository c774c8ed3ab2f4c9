"""The S1 chain on two rigid sheaves with rigid contact (its pin ends follow the faces): forces of the dependent
axial coordinate, friction through the end's axial balance, the start, the Jacobian and the energy balance."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.band.creep import creep_arc
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.errors import InputError
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_s1_cvt import ChainS1CVT
from cvtfem.machines.cvt import chain_refusal
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import (assert_energy_balance, assert_jacobian_on_pattern, band_reference, perturbed,
                                         stationary_means)

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])   # N per sheave


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module")
def model(scene):
    return from_scene(scene, reference_geometry(), F_APPL, model="chain-S1", contact="rigid")


@pytest.fixture(scope="module")
def static(model, scene):
    return model.static_state(RATIO, scene.cvt.regime.input_speed)


def test_layout_and_what_s1_refuses(model, scene):
    assert isinstance(model, ChainS1CVT)
    n = model.family.n
    assert model.n2 == 2 * n + 4                     # no axial pin coordinate
    with pytest.raises(InputError, match="'rigid' for chain-S1"):
        from_scene(scene, reference_geometry(), F_APPL, model="chain-S1", contact="hertz")
    with pytest.raises(InputError, match="'rigid' for chain-S1"):
        from_scene(scene, reference_geometry(), F_APPL, model="chain-S2", contact="rigid")
    s1 = load_scene("chain-S1")
    assert chain_refusal(s1) is None
    assert "must be 'rigid'" in str(chain_refusal(s1.replace({"cvt": {"effects": {"contact": "hertz"}}})))


def test_static_start_balances_the_clamping_forces(model, static):
    x0, rep = static
    assert rep["residual"] < 1e-8
    o = model.outputs(0.0, x0)
    # acceptance of issue 13 in the quasi-static state: pin axial forces on each sheave = its clamping force
    np.testing.assert_allclose(o["contact.sheave_axial_force"], [rep["F1"], F_APPL[1]], rtol=1e-8)
    # the pins on the arcs are compressed by the face: the same axial force as the pin spring, l/2 - u3 = P / (2 c_p)
    on = o["contact.penetration"].reshape(-1, 2).max(axis=1) > 0
    assert 30 < on.sum() < model.family.n
    assert np.all(o["contact.slip_speed"] < 1e-12)


def test_forces_are_minus_the_gradient_of_the_pin_energy(model, static):
    """Without friction the contact forces on (u1, u2, z) are minus the gradient of c_p (2 u3 - l)^2 / 2 with
    u3 = min(z + s(r), l/2) (the dependent coordinate, (1.89)-(1.91)); nothing acts on the axial slot or on phi."""
    x = perturbed(model, static[0])
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    pins, shafts, X, _ = model._contacts(q, v)
    frictionless = replace(model.contact, f0=0.0)
    Y, det = frictionless.local(X, shafts, details=True)
    on = det["delta"] > 0
    assert on.sum() > 40

    def U(Xm):
        return frictionless.local(Xm, shafts, details=True)[1]["potential"]
    for j in (0, 1, 3):
        h = 1e-9
        Xp, Xm = X.copy(), X.copy()
        Xp[:, j] += h
        Xm[:, j] -= h
        grad = (U(Xp) - U(Xm)) / (2 * h)
        np.testing.assert_allclose(Y[on, j], -grad[on], rtol=1e-6, atol=1e-6 * np.abs(Y[:, :4]).max())
    assert np.all(Y[:, 2] == 0) and np.abs(Y[:, 4]).max() < 1e-9 * np.abs(Y[:, :4]).max()


def test_friction_work_and_the_axial_balance_of_the_ends(model, static):
    """The friction power equals the work rate of the generalized friction forces; each end's contact force
    balances its pin's compression axially; normal and friction force obey |F_fr| <= f0 N."""
    x = perturbed(model, static[0], seed=1)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    pins, shafts, X, Y = model._contacts(q, v)
    Y0 = replace(model.contact, f0=0.0).local(X, shafts)
    Qfr = Y - Y0
    power = (Qfr[:, :2] * X[:, 4:6]).sum(1) + Qfr[:, 3] * X[:, 7] + Qfr[:, 4] * X[:, 8]
    np.testing.assert_allclose(Y[:, 5], power, rtol=1e-10, atol=1e-10 * np.abs(power).max())
    assert np.all(Y[:, 5] <= 0) and Y[:, 5].min() < -1.0
    _, det = model.contact.local(X, shafts, details=True)
    P = np.where(det["delta"] > 0, 2 * X[:, 2] * det["delta"], 0.0)
    np.testing.assert_allclose(det["F"][:, 2], -P, rtol=1e-12, atol=1e-9)
    assert np.all(np.linalg.norm(det["F_fr"], axis=1) <= model.contact.f0 * det["N"] * (1 + 1e-12))
    # the slip lies in the face's tangent plane: normal to the normal force F - F_fr
    on = det["N"] > 0
    F_n = det["F"] - det["F_fr"]
    assert np.abs((F_n * det["slip"]).sum(1)[on]).max() < 1e-12 * np.abs(F_n[on]).max() * np.abs(det["slip"]).max()


def test_jacobian_against_differences_and_on_its_pattern(model, static):
    assert_jacobian_on_pattern(model, perturbed(model, static[0], seed=2))


def test_energy_balance_over_a_short_run(model, static):
    x0, rep = static
    assert_energy_balance(model.with_clamping([rep["F1"], F_APPL[1]]), x0, 5e-5)


@pytest.mark.slow
def test_stationary_regime_against_the_band_model(scene):
    """Issue 13's acceptance for S1: 3500 rpm, 200 N m, ratio 2.4, from the quasi-static state with the band model's
    stationary clamping forces, 20 ms of rock4 at rtol 1e-4, means over 10-20 ms (every 25 us): pin axial forces on
    each sheave balance its clamping force to 1 %, both span tensions agree with the 6+2n band model's to 5 %
    (observed +1.4 %, +2.7 %).  Before 10 ms the slack span is still in the start transient (+5.5 % over 5-10 ms); at
    rtol 1e-3 rock4's error in the pins' slip, through the concave friction law, biases it by +3-4 %.  This window is
    not a settled state: with the ratio loop raising F1 the slack span drifts on to +5.9 % over 60-80 ms, and with the
    clamping forces held it sits at -5 % (docs/chain.md, "The span tensions against the band model").

    Why the chain runs above the band: the band's slip is uniform along the arc, the chain's grows with its link
    stretch and pin give.  The band's own span tensions are the arc balance with uniform slip (1e-4); with the
    chain's creep the arc balance gives the chain's to 2 % (observed -0.2 %, -1.2 %)."""
    F, T_band, arc = band_reference(scene)
    m = from_scene(scene, reference_geometry(), F, model="chain-S1", contact="rigid")
    x0, _ = m.static_state(RATIO, scene.cvt.regime.input_speed)
    T, axial, clamp = stationary_means(m, x0, t_end=20e-3, window=10e-3, method="rock4", rtol=1e-4)
    geom = m.family.geom
    creep = creep_arc(**arc["args"], EA=geom.c_link[0] * geom.L[0], c_pin=geom.c_pin[0], pitch=geom.L[0])["T"]
    print(f"band: tight {T_band[0]:.0f} N, slack {T_band[1]:.0f} N; S1: tight {T[0]:.0f} N, slack {T[1]:.0f} N; "
          f"creeping band {creep[0]:.0f} N, {creep[1]:.0f} N; axial/clamping {axial / clamp}")
    np.testing.assert_allclose(axial, clamp, rtol=0.01)
    assert np.all(np.abs(T / T_band - 1) <= 0.05)
    np.testing.assert_allclose(creep_arc(**arc["args"])["T"], arc["T"], rtol=1e-4)
    np.testing.assert_allclose(T, creep, rtol=0.02)


def test_pin_end_axial_positions_follow_the_faces(model, static):
    """What the renderings draw: each pin end at l/2 less the deepest face intrusion among its contacts."""
    x = perturbed(model, static[0], seed=3)
    q = x[:model.n2]
    nc, _, iz, _ = model._idx
    pins, shafts, X, _ = model._contacts(q, np.zeros(model.n2))
    delta = model.contact.local(X, shafts, details=True)[1]["delta"]
    deepest = np.zeros(model.family.n)
    np.maximum.at(deepest, pins, delta)
    expected = model.contact.half_length - deepest
    np.testing.assert_allclose(model.pin_end_axial(q[:nc], q[iz]), expected, rtol=0, atol=1e-15)
    assert (deepest > 0).sum() > 30
