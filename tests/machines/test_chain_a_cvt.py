"""The asymmetric chain A1 (and A3/A4) on two rigid shafts with a fixed and a movable sheave each (issue 13)."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.assembly.model import Model
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.errors import InputError
from cvtfem.machines.chain_a_cvt import ChainACVT
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_energy_balance, assert_jacobian_on_pattern, perturbed

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])   # N per sheave, as the S2 tests


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module")
def model(scene):
    return from_scene(scene, reference_geometry(), F_APPL, model="chain-A1")


@pytest.fixture(scope="module")
def static(model, scene):
    return model.static_state(RATIO, scene.cvt.regime.input_speed)


def test_model_protocol(model):
    assert isinstance(model, Model) and isinstance(model, ChainACVT) and isinstance(model.contact, EndContact)
    n = model.family.n
    assert model.n2 == 10 * n + 4 and model.size == 2 * model.n2 + 4 + 4
    assert model.n_ends == 2 * n and len(model.output_specs) == len({o.name for o in model.output_specs})
    with pytest.raises(InputError, match="movable_side"):
        replace(model, movable_side=(1, 0))
    with pytest.raises(InputError, match="cvt.model"):
        ChainACVT.from_parameters(reference_geometry(), model="chain-A5", centre_distance=0.17,
                                  face=model.contact.faces[0], r_outer=0.095, J=(1, 1), m_sheave=(1, 1), f0=0.1,
                                  v0=0.02, regime=model.regime, F_appl=F_APPL)


def test_static_state_balances_every_sheave_and_agrees_with_s2(model, static, scene):
    """Quasi-static start: residual, penetration, each movable sheave's axial force = its clamping force, the
    chain's axial balance (fixed sheaves take the rest), no slip; F1 and the link tension as the symmetric S2
    (an independent implementation: mirrored pin ends, one axial coordinate per pin) with aligned sheaves."""
    x0, rep = static
    assert rep["residual"] < 1e-8
    o = model.outputs(0.0, x0)
    N = o["contact.normal_force"]
    assert rep["max_penetration"] == pytest.approx((N.max() / model.contact.c[0]) ** (2 / 3), rel=1e-9)
    assert rep["max_penetration"] < 5e-5
    np.testing.assert_allclose(o["contact.sheave_axial_force"], [rep["F1"], F_APPL[1]], rtol=1e-8)
    # the chain's axial balance: the x3 > 0 sheaves (driving movable, driven fixed) push as hard as the x3 < 0 ones
    mov, fix = o["contact.sheave_axial_force"], o["contact.fixed_sheave_axial_force"]
    assert mov[0] + fix[1] == pytest.approx(fix[0] + mov[1], rel=1e-8)
    np.testing.assert_allclose(fix, mov, rtol=1e-3)       # aligned pulleys: little axial force through the spans
    assert np.all(o["contact.slip_speed"] < 1e-12) and o["contact.friction_power"] == pytest.approx([0, 0], abs=1e-9)
    s2 = from_scene(scene, reference_geometry(), F_APPL)
    _, rep2 = s2.static_state(RATIO, scene.cvt.regime.input_speed)
    assert rep["F1"] == pytest.approx(rep2["F1"], rel=2e-3)
    assert rep["tension"] == pytest.approx(rep2["tension"], rel=2e-3)
    # aligned sheaves: the chain runs centred, nearly untwisted and unsheared
    u, w = model.family.split(x0[:model.family.size])
    assert np.abs(w[0]).max() < 5e-5 and np.abs(o["chain.twist"]).max() < 1e-3 and np.abs(o["chain.shear"]).max() < 1e-3


def _contact_forces(model, q, v):
    """Generalized contact forces on ``q`` (chain and sheaves; no clamping, no torque) and the friction power."""
    Q, Pf = model._forces(q, v, np.zeros(2), np.zeros(2))
    nc = model.family.size
    Q[:nc] -= model.family.forces(q[:nc], v[:nc])
    return Q, Pf


def test_contact_forces_are_minus_the_gradient_of_the_hertz_potential(model, static):
    """Through the contact map (ends u_0 -+ u_1, w_0 -+ w_1 mirrored, movable or fixed sheave): the generalized
    normal forces on the chain and sheave coordinates equal minus the gradient of the summed Hertz potentials."""
    q = perturbed(model, static[0])[:model.n2]
    v = np.zeros(model.n2)
    Q, _ = _contact_forces(model, q, v)

    def U(qq):
        return model._contacts(qq, v, details=True)[3][1]["potential"].sum()
    ends, shafts, _, (_, c) = model._contacts(q, v, details=True)
    touching = np.unique(model.pin_of(ends[c["delta"] > 0]))
    assert len(touching) > 40
    rng = np.random.default_rng(3)
    pins = rng.choice(touching, 8, replace=False)
    cols = np.concatenate([model.family.dof_index[pins][:, [0, 1, 2, 3, 8, 9]].ravel(), model._idx[2]])
    scale = np.abs(Q).max()
    for j in cols:
        h = 1e-10
        qp, qm = q.copy(), q.copy()
        qp[j] += h
        qm[j] -= h
        assert Q[j] == pytest.approx(-(U(qp) - U(qm)) / (2 * h), rel=1e-6, abs=1e-6 * scale), j
    assert np.abs(Q[model._idx[1]]).max() < 1e-9 * scale      # H1 normal force: no moment about the axis


def test_friction_power_is_the_work_rate_of_the_friction_forces(model, static):
    x = perturbed(model, static[0], seed=1)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    Q, Pf = _contact_forces(model, q, v)
    frictionless = replace(model, contact=EndContact(replace(model.contact.pair, f0=0.0)))
    Q0, Pf0 = _contact_forces(frictionless, q, v)
    assert Pf0 == 0.0 and Pf < -1.0
    assert Pf == pytest.approx(float((Q - Q0) @ v), rel=1e-10)


def test_jacobian_against_differences_and_on_its_pattern(model, static):
    assert_jacobian_on_pattern(model, perturbed(model, static[0], seed=2), n_chain=16)


def test_energy_balance_over_a_short_run(model, static):
    x0, rep = static
    m = model.with_clamping([rep["F1"], F_APPL[1]])
    assert_energy_balance(m, x0, 5e-5)


def test_scene_path_builds_a1_and_describes_its_outputs_once():
    from cvtfem.machines import layout
    from cvtfem.machines.cvt import chain_loop

    scene = load_scene("chain-A1")
    m = chain_loop(scene)
    assert isinstance(m, ChainACVT) and m.family.size == 10 * scene.cvt.chain.n_pins
    listed = [o.name for part in layout(scene) for o in part.outputs]
    assert sorted(listed) == sorted(o.name for o in m.output_specs)
    assert sum(p.n2 for p in layout(scene)) == m.n2
    assert isinstance(chain_loop(scene.replace({"cvt": {"model": "chain-A4"}})), ChainACVT)   # runs (session 8)
    with pytest.raises(InputError, match=r"cvt\.effects\.pin_bending"):
        chain_loop(scene.replace({"cvt": {"effects": {"pin_bending": False}}}))


@pytest.mark.slow
def test_cvtfem_run_chain_a1_closes_the_energy_balance(cli, tmp_path):
    """0.3 ms of the chain-A1 preset through `cvtfem run` from its quasi-static start: the work integrals close
    the energy balance to 1e-5 of the input work, every output is finite, the ratio holds within 5 %."""
    import json

    import h5py

    h5, js = tmp_path / "a1.h5", tmp_path / "s.json"
    r = cli("run", "chain-A1", "--until", "3e-4", "--results", str(h5), "--summary-json", str(js), timeout=900)
    assert r.returncode == 0, r.stderr
    summary = json.loads(js.read_text())
    assert summary["ratio"] == pytest.approx(2.4, rel=0.05) and summary["n_coordinates"] == 844
    with h5py.File(h5) as f:
        s = f["series"]
        for name in s:
            assert np.isfinite(s[name][:]).all(), name
        W, E = s["work"][-1], s["energy"][:]
    assert W[0] > 1.0 and abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-5 * W[0]


@pytest.mark.slow
def test_a3_start_continues_from_the_a1_balance(scene, static):
    """A3's quasi-static start, continued from the A1 balance of its own A1 layout, converges (from the placement
    guess it stalls at 1.1e-2 of F2): residual, each movable sheave's axial force = its clamping force, and the
    per-plate chain's tension within 2 % of A1's (the homogenised layer of the same plates)."""
    a3 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A3")
    x0, rep = a3.static_state(RATIO, scene.cvt.regime.input_speed)
    assert rep["residual"] < 1e-8 and rep["nfev"] < 100
    at_rest = x0.copy()
    at_rest[a3.n2:2 * a3.n2] = 0.0
    o = a3.outputs(0.0, at_rest)
    np.testing.assert_allclose(o["contact.sheave_axial_force"], [rep["F1"], F_APPL[1]], rtol=1e-8)
    assert rep["tension"] == pytest.approx(static[1]["tension"], rel=2e-2)
