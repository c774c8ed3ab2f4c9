"""The chain with independent pin halves (A5) on two rigid shafts, H1 contact at both ends of every half (issue 13)."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.assembly.model import Model
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.errors import InputError
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT, HalvesFamily
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_jacobian_columns

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])   # N per sheave, as the S2 and A1 tests


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module")
def model(scene):
    return from_scene(scene, reference_geometry(), F_APPL, model="chain-A5")


@pytest.fixture(scope="module")
def placed(model, scene):
    """The start of the quasi-static solve as a running state (halves rolling on each other on the path)."""
    return model.placed_state(RATIO, scene.cvt.regime.input_speed)


def _perturbed(model, x0, seed=0):
    """A running state off balance: random chain offsets (0.2 um) and velocities, sheave and shaft rates."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    x[n2 + nc:n2 + nc + 4] += rng.normal(0.0, 0.05, 4)
    return x


def test_model_protocol_and_contact_map(model, placed):
    """21 n + 4 coordinates, four contact ends per pin, and the contact map reads each half end ``u_0 -+ u_1``,
    ``x3 = s (w_0 -+ w_1)`` (mirrored for ``x3 < 0``) of the right half."""
    assert isinstance(model, Model) and isinstance(model, ChainHalvesCVT) and isinstance(model.contact, EndContact)
    assert isinstance(model.family, HalvesFamily)
    n = model.family.n
    assert model.n2 == 21 * n + 4 and model.n_ends == 4 * n
    assert len(model.output_specs) == len({o.name for o in model.output_specs})
    x = _perturbed(model, placed)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    ends = np.arange(model.n_ends)
    cols, coef = model._contact_map(ends, np.zeros(model.n_ends, int))
    X = (coef * np.concatenate([q, v, model._constants])[cols]).sum(axis=2)
    u, w, _ = model.family.split(q[:model.family.size])
    p, h, s = ends // 4, (ends // 2) % 2, ends % 2
    sign = np.where(s == 1, 1.0, -1.0)
    np.testing.assert_array_equal(X[:, :2], u[h, 0, p] + sign[:, None] * u[h, 1, p])
    np.testing.assert_array_equal(X[:, 2], sign * (w[h, 0, p] + sign * w[h, 1, p]))
    with pytest.raises(InputError, match="cvt.model"):
        ChainHalvesCVT._family_for("chain-A1", reference_geometry(), None, 2.1e11)


def test_placed_state_rolls_the_halves_on_links_at_the_wedge_tension(model, placed):
    """The start of the solve: inside each arc (pins whose neighbours lie on the same arc) every link carries one
    tension, the wedge estimate (the placement stretches the links and presses the rolling faces for it), and every
    rolling contact carries it too (to 1e-3 of F2); every half end of those pins presses its sheave.  (Where arcs
    meet spans the pins' axial compressions differ and the plates' stations with them.)"""
    fam = model.family
    out = fam.outputs(placed[:fam.size], None)
    piece = model._placement(RATIO).piece
    inner = (piece >= 0) & (np.roll(piece, 1) == piece) & (np.roll(piece, -1) == piece)
    links = inner & inner[fam.ip1]
    assert inner.sum() > 30
    T = out["chain.link_tension"][links]
    assert T.mean() > 0.1 * F_APPL[1]
    assert np.ptp(T) < 1e-3 * F_APPL[1]
    assert np.abs(out["chain.roll_force"][inner] - T.mean()).max() < 1e-3 * F_APPL[1]
    ends, _, _, (_, c) = model._contacts(placed[:model.n2], placed[model.n2:2 * model.n2], details=True)
    pressed = np.bincount(model.pin_of(ends), c["delta"] > 0, fam.n)
    assert np.all(pressed[inner] == 4)


@pytest.mark.slow
def test_static_state_balances_every_sheave(model, scene):
    """Quasi-static start (issue 13's acceptance): the pin-half axial forces on each sheave balance its clamping force
    (the movable sheaves: the solve's balance; the fixed ones: the chain's axial balance) to 1e-3 (measured 2e-5;
    the issue asks for 1 %); residual below 1e-4 of F2 (the axial positions of the span halves, which no stiffness of
    their own holds, keep about 1 N); every link carries the wedge tension of the whole-pin chain A1 (an independent
    implementation) to 1 %, the halves press on each other all round and nothing slips."""
    x0, rep = model.static_state(RATIO, scene.cvt.regime.input_speed)
    assert rep["residual"] < 1e-4
    o = model.outputs(0.0, x0)
    mov, fix = o["contact.sheave_axial_force"], o["contact.fixed_sheave_axial_force"]
    np.testing.assert_allclose(mov, [rep["F1"], F_APPL[1]], rtol=1e-6)
    np.testing.assert_allclose(fix, mov, rtol=1e-3)
    assert mov[0] + fix[1] == pytest.approx(fix[0] + mov[1], rel=1e-4)
    a1 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A1")
    _, rep1 = a1.static_state(RATIO, scene.cvt.regime.input_speed)
    T = model.family.outputs(x0[:model.family.size], None)["chain.link_tension"]
    np.testing.assert_allclose(T, rep1["tension"], rtol=1e-2)
    assert np.all(o["contact.slip_speed"] < 1e-12)
    assert np.all(o["chain.roll_force"] > 0.99 * rep1["tension"])


def test_contact_forces_are_minus_the_gradient_of_the_hertz_potential(model, placed):
    """Through the contact map of four half ends per pin (movable or fixed sheave, mirrored for x3 < 0): the
    generalized normal forces on the chain and sheave coordinates equal minus the gradient of the Hertz potentials."""
    q = _perturbed(model, placed)[:model.n2]
    v = np.zeros(model.n2)
    Q, _ = model._forces(q, v, np.zeros(2), np.zeros(2))
    nc = model.family.size
    Q[:nc] -= model.family.forces(q[:nc], v[:nc])

    def U(qq):
        return model._contacts(qq, v, details=True)[3][1]["potential"].sum()
    ends, _, _, (_, c) = model._contacts(q, v, details=True)
    touching = np.unique(model.pin_of(ends[c["delta"] > 0]))
    rng = np.random.default_rng(3)
    pins = rng.choice(touching, 6, replace=False)
    cols = np.concatenate([model.family.dof_index[pins][:, [0, 1, 2, 3, 8, 9, 10, 11, 12, 13, 18, 19]].ravel(),
                           model._idx[2]])
    scale = np.abs(Q).max()
    for j in cols:
        h = 1e-10
        qp, qm = q.copy(), q.copy()
        qp[j] += h
        qm[j] -= h
        assert Q[j] == pytest.approx(-(U(qp) - U(qm)) / (2 * h), rel=1e-6, abs=1e-6 * scale), j


def test_dissipated_power_and_its_gradient(model, placed):
    """The family's ``rayleigh`` is half the power of the damping and friction forces, ``dissipative_forces``
    minus half its gradient in the velocities (central differences)."""
    x = _perturbed(model, placed, seed=4)
    fam = model.family
    q, v = x[:fam.size], x[model.n2:model.n2 + fam.size]
    D = 2 * fam.rayleigh(q, v)
    assert D > 0
    g = fam.dissipative_forces(q, v)
    rng = np.random.default_rng(2)
    for j in rng.choice(fam.size, 12, replace=False):
        hstep = 1e-4
        vp, vm = v.copy(), v.copy()
        vp[j] += hstep
        vm[j] -= hstep
        fd = (fam.rayleigh(q, vp) - fam.rayleigh(q, vm)) / (2 * hstep)
        assert -g[j] == pytest.approx(fd, rel=1e-4, abs=1e-6 * np.abs(g).max()), j


def test_jacobian_against_differences_and_on_its_pattern(model, placed):
    """``jac`` against central differences of ``rhs``, all coordinate kinds.  With the smooth clamped plates of
    A3-keep: A4's plates near zero tension switch states within a difference step (their moment bound T h/2
    vanishes), so no difference quotient is a derivative there."""
    from cvtfem.elements.chain.symmetric import damping_from_ratio
    from cvtfem.machines.chain_halves_cvt import halves_family

    geom = reference_geometry()
    model = replace(model, family=halves_family(geom, damping_from_ratio(geom, 0.05), 2.1e11, plate_model="A3-keep"))
    x = _perturbed(model, placed, seed=2)
    J = model.jac(0.0, x).toarray()
    assert not np.any(J[~model.jac_sparsity.toarray()])
    rng = np.random.default_rng(5)
    n2, nc = model.n2, model.family.size
    cols = np.concatenate([rng.choice(nc, 12, replace=False), n2 + rng.choice(nc, 12, replace=False),
                           np.arange(nc, n2), n2 + np.arange(nc, n2), np.arange(2 * n2, 2 * n2 + 4)])
    assert_jacobian_columns(model, x, J, cols)


@pytest.mark.slow
def test_energy_balance_over_a_short_run(model, placed):
    """From the placed state (off balance: the chain settles on the sheaves), 2 us of Radau: the work integrals,
    with the chain's internal friction and damping in the dissipated work, close the energy balance to 1e-6 of the
    input work (``assert_energy_balance`` without its 1 J floor: 2 us put in about 0.15 J)."""
    from cvtfem.integrate import solve

    res = solve(model, (0.0, 2e-6), placed, method="Radau", rtol=1e-6, atol=1e-9, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity)
    assert res.status == 0
    x1 = res.y[:, -1]
    W = model.split(x1)[3]
    assert W[0] > 0.05 and W[2] > 0.01 * W[0]
    assert model.energy(x1) - model.energy(placed) == pytest.approx(W[0] - W[1] + W[3] - W[2], abs=1e-6 * W[0])


def test_scene_path_builds_a5_and_describes_its_outputs_once():
    from cvtfem.machines import layout
    from cvtfem.machines.cvt import chain_loop

    scene = load_scene("chain-A5")
    m = chain_loop(scene)
    assert isinstance(m, ChainHalvesCVT) and m.family.size == 21 * scene.cvt.chain.n_pins
    listed = [o.name for part in layout(scene) for o in part.outputs]
    assert sorted(listed) == sorted(o.name for o in m.output_specs)
    assert sum(p.n2 for p in layout(scene)) == m.n2
    with pytest.raises(InputError, match=r"cvt\.effects\.contact"):
        chain_loop(scene.replace({"cvt": {"model": "chain-A5-point", "effects": {"contact": "hertz-refined"}}}))
    assert replace(m, movable_side=(-1, 1)).movable_side == (-1, 1)
