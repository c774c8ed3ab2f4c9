"""Time-domain torsional network model: sparse Jacobians (coloured FD against analytic), energy balance."""
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.assembly.model import Model
from cvtfem.elements.torsional import BACKLASH, GAP, LINEAR, build_network
from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.machines.torsional import TorsionalModel, build_model
from cvtfem.scene.loader import load_scene


def chain(S, seed=0):
    """S masses in a line, the last tied to ground; every 7th link with backlash, every 11th a gap."""
    rng = np.random.default_rng(seed)
    i = np.arange(S)
    j = np.r_[np.arange(1, S), -1]
    law = np.where(i % 7 == 3, BACKLASH, np.where(i % 11 == 5, GAP, LINEAR))
    Q = np.zeros((S, 1), complex)
    Q[0, 0] = 50.0
    net = build_network(rng.uniform(0.5, 2, S), rng.uniform(0, 1, S), i, j, rng.uniform(1e4, 1e5, S),
                        d=rng.uniform(0, 5, S), law=law, k_in=np.full(S, 1e2), h=np.full(S, 1e-3), Q=Q)
    return TorsionalModel(net, 10.0), rng


def counting(model):
    """Replace ``model.rhs`` by a counting wrapper; returns the counter."""
    calls, rhs = [0], model.rhs

    def counted(t, x):
        calls[0] += 1
        return rhs(t, x)

    object.__setattr__(model, "rhs", counted)
    return calls


def test_coloured_jacobian_of_3500_states_costs_few_calls():
    model, rng = chain(1750)
    assert isinstance(model, Model) and model.size == 3500 and model.n2 == 1750
    x = rng.normal(size=3500) * 1e-3
    calls = counting(model)
    J = model.fd_jac(0.1, x)
    assert calls[0] <= 30 and calls[0] == model.colouring[1].max() + 2   # colours + F(x)
    Ja = model.jac(0.1, x)
    assert sp.issparse(J) and sp.issparse(Ja)
    # forward-difference truncation: |f''| <= (k_out - k_in) / (zone h) over delta = sqrt(eps) max(|x|, 1)
    net = model.net
    bound = ((net.k_out - net.k_in) / (net.zone * np.where(net.h > 0, net.h, 1))).max() * 1.5e-8 / net.m.min()
    assert abs(J - Ja).max() <= bound + 1e-9 * abs(Ja).max()
    nz = (Ja != 0).astype(int)
    assert not (nz - nz.multiply(model.jac_sparsity)).nnz          # analytic non-zeros lie on the pattern


def test_analytic_jacobian_equals_central_differences():
    net = build_network([1.0, 2.0, 0.5, 1.5], [0.1, 0.0, 0.2, 0.3], [0, 1, 1, 2, 3], [1, 2, 3, -1, -1],
                        [1e4, 2e4, 3e4, 5e3, 1e3], d=[1.0, 0.0, 2.0, 0.5, 0.0],
                        law=[LINEAR, BACKLASH, GAP, LINEAR, BACKLASH], k_in=[0.0, 1e2, 1e2, 0.0, 10.0],
                        h=[0.0, 1e-3, 2e-3, 0.0, 1e-3], Q=[[1.0], [0.0], [2.0], [0.0]])
    model = TorsionalModel(net, 3.0)
    x = np.array([0.0, 4e-4, 1.1e-3, -2e-3, 0.1, -0.2, 0.3, 0.05])
    h = 1e-7
    Jfd = np.stack([(model.rhs(0.2, x + h * e) - model.rhs(0.2, x - h * e)) / (2 * h) for e in np.eye(8)], axis=1)
    Ja = model.jac(0.2, x).toarray()
    assert np.allclose(Ja, Jfd, rtol=1e-6, atol=1e-6 * np.abs(Ja).max())
    lin = model.linearize(x)     # the same tangent as second-order matrices
    A = np.block([[np.zeros((4, 4)), np.eye(4)],
                  [-np.linalg.solve(lin.M.toarray(), lin.K.toarray()), -np.linalg.solve(lin.M.toarray(), lin.C.toarray())]])
    assert np.array_equal(A, Ja) and not lin.G.nnz


def test_energy_balance():
    """dE/dt along the flow equals the load power minus the dissipated power."""
    model, rng = chain(40, seed=2)
    x = rng.normal(size=80) * 1e-3
    t = 0.3
    f = model.rhs(t, x)
    h = 1e-6
    dE = (model.energy(x + h * f) - model.energy(x - h * f)) / (2 * h)
    P = model.power(t, x)
    assert abs(dE - (P["input"] - P["dissipated"])) <= 1e-6 * (abs(P["input"]) + P["dissipated"])


def test_time_run_with_coloured_jacobians():
    """An implicit run of the 3,500-state chain with only the sparsity pattern: each Jacobian <= 30 RHS calls."""
    model, _ = chain(1750)
    res = solve(model.rhs, (0.0, 2e-3), model.initial_state(), method="trapezoidal", rtol=1e-4, atol=1e-8,
                jac_sparsity=model.jac_sparsity, n2=model.n2)
    st = res.stats
    assert res.success and st["njev"] >= 1
    assert st["nfev_jac"] <= 30 * st["njev"]
    ref = solve(model, (0.0, 2e-3), model.initial_state(), method="trapezoidal", rtol=1e-4, atol=1e-8)
    assert ref.success and ref.stats["nfev_jac"] == 0       # analytic Jacobian through the protocol
    assert np.allclose(res.y[:, -1], ref.y[:, -1], rtol=1e-3, atol=1e-3 * np.abs(ref.y[:, -1]).max())


def test_scene_model_outputs_match_specs():
    scene = load_scene("engine_gear_train")
    model = build_model(scene, 100.0)
    x = np.random.default_rng(1).normal(size=model.size) * 1e-4
    out = model.outputs(0.0, x)
    assert [s.name for s in model.output_specs] == list(out)
    assert all(np.size(out[s.name]) == s.size for s in model.output_specs)
    net = model.net
    assert np.allclose(out["link.moment"], out["link.force"] * net.radius[net.i])
    assert model.omega == 100.0 and build_model(scene).omega == 2 * np.pi * scene.periodic.frequency
    with pytest.raises(InputError):
        build_model(scene, 0.0)


def test_every_machine_kind_builds_a_model():
    from cvtfem.machines import build_model as build_any

    for name in ("engine_gear_train", "friswell_5_9_1", "band-4dof"):
        model = build_any(load_scene(name))
        x0 = model.initial_state()
        assert isinstance(model, Model) and x0.shape == (model.size,) == model.rhs(0.0, x0).shape
        assert model.layout.size == model.size and model.n2 == model.layout.n2
