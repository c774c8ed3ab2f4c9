"""The per-plate chains A3 (plates clamped to the pins) and A4 (the ten plate states) running on two rigid shafts
(issue 13; the chains of Table 1.1 variants (g) and (d))."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.chain import plates as P
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.machines.chain_a_cvt import ChainACVT
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_jacobian_columns, perturbed

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])   # N per sheave, as the A1 tests


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


def _continued(model, x):
    """``model`` whose quasi-static solve starts from the chain and movable sheaves of the balance ``x``."""
    return replace(model, start_chain=x[:model.family.size], start_z=x[model._idx[2]])


@pytest.fixture(scope="module")
def balances(scene):
    """``{name: (model, x0, report)}`` of A1, then A3 from A1's balance, then A4 from A3's (the stages of A4's start)."""
    w1 = scene.cvt.regime.input_speed
    out, x = {}, None
    for name in ("chain-A1", "chain-A3", "chain-A4"):
        m = from_scene(scene, reference_geometry(), F_APPL, model=name)
        m = m if x is None else _continued(m, x)
        x, rep = m.static_state(RATIO, w1)
        out[name] = (m, x, rep)
    return out


def tilted(model, x, pins, angle: float = 4e-3):
    """``x`` with the pins ``pins`` tilted in the chain plane by ``angle`` (rad) about their in-plane normal: the plates
    of their two links tilt by about ``angle`` against the pin, more than their line contact bears (|psi| ~ 1e-3)."""
    y = x.copy()
    u = model.family.split(y[:model.family.size])[0]
    fam = model.family
    tau = u[0, fam.ip1[pins]] - u[0, (pins - 1) % fam.n]
    tau /= np.linalg.norm(tau, axis=1)[:, None]
    u[1, pins] += angle * fam.geom.l / 2 * tau
    return y


def _plate_strains(model, x):
    """``(psi_1, psi_2, Delta)`` of every plate of a per-plate chain at ``x`` (numpy reference of the plates)."""
    chain = model.family.chain
    return P.plate_strains(*chain._local(x[:model.family.size]), chain.xi, chain.l, chain.pitch)[0]


def test_the_start_stages_balance_and_agree(balances):
    """A1, A3 and A4 each balance (residual, each movable sheave's axial force = its clamping force). At the balance
    every plate is stretched and bears along a line (state 1), where A4's law is A3's (delta = 0), so A4's balance is
    A3's to the solver's tolerance. A3 and A1 (the homogenised layer of the same plates) agree to first order in the
    plate strain (chain-models-2 §8, check 4: same tensions for pure stretch; A1's extension is the Green-type
    ``(|V|^2 - L^2) / 2L``, A3's the exact ``|V| - L``): mean tension and F1 within the largest plate strain."""
    for name, (m, x, rep) in balances.items():
        assert rep["residual"] < 1e-8, name
        at_rest = x.copy()
        at_rest[m.n2:2 * m.n2] = 0.0
        np.testing.assert_allclose(m.outputs(0.0, at_rest)["contact.sheave_axial_force"], [rep["F1"], F_APPL[1]],
                                   rtol=1e-8)
    (m3, x3, r3), (m4, x4, r4), (_, _, r1) = balances["chain-A3"], balances["chain-A4"], balances["chain-A1"]
    assert np.all(m4.outputs(0.0, x4)["chain.plate_state"] == 1)
    assert np.abs(x4[:m4.n2] - x3[:m3.n2]).max() < 1e-9
    assert r4["tension"] == pytest.approx(r3["tension"], rel=1e-9) and r4["F1"] == pytest.approx(r3["F1"], rel=1e-9)
    strain = (_plate_strains(m3, x3)[:, 2] / m3.family.chain.pitch).max()
    assert 1e-4 < strain < 1e-2
    assert abs(r3["tension"] / r1["tension"] - 1) < strain and abs(r3["F1"] / r1["F1"] - 1) < strain


def test_a4_is_a3_while_every_plate_bears_along_a_line(balances):
    """Where every plate is in state 1, A4's right-hand side and Jacobian are A3's (two branches of the compiled plate
    law). Pins tilted against their plates put plates on a corner: there A4 bounds the end moments by ``T h/2``
    (``|m| <= 1``), A3's clamped plates exceed it, and the right-hand sides differ."""
    (m3, x3, _), (m4, _, _) = balances["chain-A3"], balances["chain-A4"]
    x = perturbed(m4, x3, seed=4, scale=np.full(m4.family.size, 0.1))     # 0.2 um: the plates stay on their lines
    assert np.all(m4.outputs(0.0, x)["chain.plate_state"] == 1)
    f3, f4 = m3.rhs(0.0, x), m4.rhs(0.0, x)
    assert np.abs(f4 - f3).max() <= 1e-12 * np.abs(f3).max()
    J3, J4 = m3.jac(0.0, x), m4.jac(0.0, x)
    assert abs(J4 - J3).max() <= 1e-12 * abs(J3).max()
    y = tilted(m4, x, np.array([3, 30, 57]))
    o3, o4 = m3.outputs(0.0, y), m4.outputs(0.0, y)
    assert np.isin(o4["chain.plate_state"], np.arange(2, 10)).sum() >= 6
    assert np.nanmax(np.abs(o4["chain.plate_reduced_moment"])) <= 1 + 1e-12
    assert np.nanmax(np.abs(o3["chain.plate_reduced_moment"])) > 1.5
    assert np.abs(m4.rhs(0.0, y) - m3.rhs(0.0, y)).max() > 1e-3 * np.abs(f3).max()


def test_plate_states_are_classified_exactly_one_each(balances):
    """On the sheaves with tilted pins (line, single- and double-corner contacts): every plate has one state in 1..10,
    the model's output, and its existence margin (the spec table's conditions written as moments) is the only
    positive one; states 2-9 all carry tension and the free-end moments sit at the bound ``|M| = T h/2``."""
    m4, x4, _ = balances["chain-A4"]
    y = tilted(m4, perturbed(m4, x4, seed=6), np.arange(5, 84, 6), angle=6e-3)   # 2 um offsets: some plates slack
    states = m4.outputs(0.0, y)["chain.plate_state"]
    chain = m4.family.chain
    margins, _ = P._state_margins(_plate_strains(m4, y), chain.c, chain.c1, chain.c2, chain.h)
    assert np.array_equal(states, np.argmax(margins, axis=1) + 1) and states.dtype.kind in "iuf"
    assert np.all((margins > 0).sum(axis=1) == 1)
    assert len(np.unique(states)) >= 4 and np.all(np.isin(states, np.arange(1, 11)))
    st = P.plate_state(_plate_strains(m4, y), chain.c, chain.c1, chain.c2, chain.h)
    corner = (states >= 2) & (states <= 9)
    assert np.all(st.tension[corner] > 0)
    m = P.reduced_moment(st, chain.h)[corner]
    assert np.all(np.isclose(np.abs(m), 1.0, atol=1e-9).any(axis=1))


@pytest.mark.parametrize("name", ["chain-A3", "chain-A4"])
def test_the_rhs_dissipated_power_is_the_plates_rayleigh_function(balances, name):
    """The work integral's dissipated power uses ``Phi`` of the compiled plate forces (``-v . Q_d / 2``, Euler's identity);
    it equals the numpy Rayleigh function of the plates and pins to 1e-10 with plates in all ten states, whether or
    not the forces were just evaluated at that state."""
    m, x0, _ = balances[name]
    x = perturbed(m, x0, seed=3)
    nc, n2 = m.family.size, m.n2
    q, v = x[:nc], x[n2:n2 + nc]
    if name == "chain-A4":
        assert len(np.unique(m.outputs(0.0, x)["chain.plate_state"])) == 10
    reference = float(m.family.chain.rayleigh(q, v))
    assert reference > 1.0
    assert m.family.rayleigh(q, v) == pytest.approx(reference, rel=1e-10)
    m.family.forces(q, v)
    assert m.family.rayleigh(q, v) == pytest.approx(reference, rel=1e-10)


@pytest.mark.parametrize("name", ["chain-A3", "chain-A4"])
def test_jacobian_against_differences_with_the_plate_blocks(balances, name):
    """``jac`` on its pattern and equal to central differences (1e-5 of each row's largest entry) on the coordinates
    and velocities of tilted pins and their neighbours (A4: plates in corner states, whose blocks use the state's
    ``A``), random chain columns, the shafts, sheaves and loops."""
    m, x0, _ = balances[name]
    pins = np.array([3, 30, 57])
    x = tilted(m, perturbed(m, x0, seed=2, scale=np.full(m.family.size, 0.3)), pins)
    if name == "chain-A4":
        assert np.isin(m.outputs(0.0, x)["chain.plate_state"], np.arange(2, 10)).sum() >= 6
    J = m.jac(0.0, x).toarray()
    assert not np.any(J[~m.jac_sparsity.toarray()])
    n2, nc = m.n2, m.family.size
    rng = np.random.default_rng(5)
    near = m.family.dof_index[np.concatenate([pins - 1, pins, pins + 1])][:, [0, 2, 4, 6, 8, 9]].ravel()
    cols = np.concatenate([near, n2 + near, rng.choice(nc, 8, replace=False), n2 + rng.choice(nc, 8, replace=False),
                           np.arange(nc, n2), n2 + np.arange(nc, n2), np.arange(2 * n2, 2 * n2 + 4)])
    assert_jacobian_columns(m, x, J, cols)


@pytest.mark.slow
def test_energy_balance_over_a_short_run_of_a4(balances):
    """A4 from its balance off balance by random offsets (0.6 um: a few plates start on a corner or slack and return to
    line contact), 10 us of Radau at rtol 1e-6: ``E(t) - E(0)`` = input - output + clamping - dissipated work to 1e-6
    of the input work (40 s at load 8: the perturbation's fast transients need ~600 LU factorisations)."""
    m, x0, rep = balances["chain-A4"]
    m = m.with_clamping([rep["F1"], F_APPL[1]])
    x = perturbed(m, x0, seed=9, scale=np.full(m.family.size, 0.3))
    assert np.sum(m.outputs(0.0, x)["chain.plate_state"] != 1) >= 3
    res = solve(m, (0.0, 1e-5), x, method="Radau", rtol=1e-6, atol=1e-9, n2=m.n2, jac=m.jac,
                jac_sparsity=m.jac_sparsity)
    assert res.status == 0
    W = m.split(res.y[:, -1])[3]
    assert W[0] > 0.5 and W[2] > 0.0
    assert m.energy(res.y[:, -1]) - m.energy(x) == pytest.approx(W[0] - W[1] + W[3] - W[2], abs=1e-6 * W[0])


def test_scene_path_runs_a3_and_a4_and_refuses_what_they_cannot_do():
    from cvtfem.machines import layout
    from cvtfem.machines.cvt import chain_loop, chain_refusal

    for name in ("chain-A3", "chain-A4"):
        scene = load_scene(name)
        assert chain_refusal(scene) is None
        m = chain_loop(scene)
        assert isinstance(m, ChainACVT) and m.family.chain.model == name[-2:]
        parts = layout(scene)
        assert sum(p.n2 for p in parts) == m.n2 == 10 * scene.cvt.chain.n_pins + 4
        assert sorted(o.name for p in parts for o in p.outputs) == sorted(o.name for o in m.output_specs)
    a4 = load_scene("chain-A4")
    assert chain_loop(a4.replace({"cvt": {"effects": {"contact": "hertz-refined"}}})).contact.refined
    for override, key in (({"effects": {"pin_bending": False}}, "cvt.effects.pin_bending"),
                          ({"effects": {"contact": "impact"}}, "cvt.effects.contact"),
                          ({"effects": {"friction": False}}, "cvt.effects.friction")):
        with pytest.raises(InputError, match=key.replace(".", r"\.")):
            chain_loop(a4.replace({"cvt": override}))


@pytest.mark.slow
def test_cvtfem_run_chain_a4_from_its_balance(cli, tmp_path):
    """`cvtfem run chain-A4,regime-stationary` for 20 us (output every 2 us) from the quasi-static start: the work
    integrals close the energy balance to 1e-5 of the input work, every output is finite, the plate states are
    integers in 1..10 at every output, the summary names the model and its 844 coordinates."""
    import json

    import h5py

    scene = tmp_path / "a4.toml"
    scene.write_text('preset = ["chain-A4", "regime-stationary"]\n[output]\nstep = 2e-6\n')
    h5, js = tmp_path / "a4.h5", tmp_path / "s.json"
    r = cli("run", str(scene), "--until", "2e-5", "--results", str(h5), "--summary-json", str(js), timeout=900)
    assert r.returncode == 0, r.stderr
    summary = json.loads(js.read_text())
    assert summary["model"] == "chain-A4" and summary["n_coordinates"] == 844 and summary["status"] == "finished"
    with h5py.File(h5) as f:
        s = f["series"]
        assert len(s["time"]) == 11
        for name in s:
            assert np.isfinite(s[name][:]).all(), name
        states = s["chain.plate_state"][:]
        W, E = s["work"][-1], s["energy"][:]
    assert np.all(np.isin(states, np.arange(1, 11)))
    assert W[0] > 0.1 and abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-5 * W[0]
