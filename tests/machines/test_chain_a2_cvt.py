"""Variant (v) on rigid shafts: A1 with coupled pin halves in the refined sheave contact (A2, (1.210))."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.half_contact import CoupledHalvesContact
from cvtfem.elements.chain.halves import CoupledHalvesA2
from cvtfem.errors import InputError
from cvtfem.machines.chain_a2_cvt import H_PIN, ChainA2CVT
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_jacobian_columns

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])


@pytest.fixture(scope="module")
def models():
    scene = load_scene("band-6+2n")
    a1 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A1", contact="hertz-refined")
    a2 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A2", contact="hertz-refined")
    return a1, a2


@pytest.fixture(scope="module")
def state(models):
    """A running state near balance: A1-with-H2's quasi-static state (the halves share its end loads, so their
    penetration is smaller) with random pin offsets, tilts and velocities."""
    a1, a2 = models
    x0, _ = a1.static_state(RATIO, load_scene("band-6+2n").cvt.regime.input_speed)
    rng = np.random.default_rng(0)
    x = x0.copy()
    nc, n2 = a2.family.size, a2.n2
    scale = np.ones(nc)
    scale[a2.family.dof_index[:, 4:8].ravel()] = 1e-3 / a2.family.geom.l
    x[:nc] += rng.normal(0.0, 2e-6, nc) * scale
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc) * scale
    x[n2 + nc:n2 + nc + 4] += rng.normal(0.0, 0.05, 4)
    return x


def _contact_forces(model, q, v):
    Q, Pf = model._forces(q, v, np.zeros(2), np.zeros(2))
    nc = model.family.size
    Q[:nc] -= model.family.forces(q[:nc], v[:nc])
    return Q, Pf


def test_scene_and_construction(models):
    from cvtfem.machines.cvt import chain_loop, chain_refusal

    _, a2 = models
    assert isinstance(a2, ChainA2CVT) and isinstance(a2.contact.pair, CoupledHalvesContact)
    assert a2.n_ends == 4 * a2.family.n and a2.contact.pair.h_pin == H_PIN
    scene = load_scene("variant-v")
    assert chain_refusal(scene) is None       # on elastic shafts: ElasticChainA2CVT (test_chain_cvt_elastic_refined)
    rigid = scene.replace({"cvt": {"effects": {"shaft_elasticity": False}}})
    assert chain_refusal(rigid) is None and isinstance(chain_loop(rigid), ChainA2CVT)
    with pytest.raises(InputError, match=r"cvt\.effects\.contact"):
        chain_loop(rigid.replace({"cvt": {"effects": {"contact": "hertz"}}}))
    with pytest.raises(InputError, match="h_pin"):
        CoupledHalvesContact(a2.contact.pair.pair, 0.0)


def test_half_axes_equal_the_a2_element_family(models):
    """The contact's half-axis ends equal CoupledHalvesA2.contact_points (the element family's (1.210) with the
    link-length bisector (1.103)) where the links are at their lengths, and to 1e-3 of h_pin when stretched."""
    _, a2 = models
    fam = a2.family
    pl = a2.wedge_guess(RATIO, F_APPL[1])[0]
    ref = CoupledHalvesA2(fam.chain, H_PIN)
    rng = np.random.default_rng(1)
    for q_chain, tol in ((a2._placed(pl, np.full(fam.n, fam.geom.l / 2)), 1e-12), (None, 1e-3)):
        if q_chain is None:                            # stretched links, tilted pins
            q_chain = a2._placed(pl, np.full(fam.n, fam.geom.l / 2)) + rng.normal(0.0, 5e-6, fam.size)
        q = np.zeros(a2.n2)
        q[:fam.size] = q_chain
        ends = np.arange(a2.n_ends)
        shafts = np.zeros(a2.n_ends, int)
        cols, coef = a2._contact_map(ends, shafts)
        X = (coef * np.concatenate([q, np.zeros(a2.n2), a2._constants])[cols]).sum(axis=2)
        Xk, _, _ = a2.contact.pair.shifted(X)
        side = np.where(ends % 2 == 1, 1.0, -1.0)
        P = ref.contact_points(q_chain, a2.pin_of(ends), a2.half_of(ends), side)
        assert np.abs(Xk[:, 2:4] - P[:, :2]).max() < tol * H_PIN
        assert np.abs(Xk[:, 6] - side * P[:, 2]).max() < 1e-15          # x3 mirrored, as the pin end's


def test_contact_forces_are_minus_the_gradient_of_the_hertz_potential(models, state):
    """Through the offset of the halves (turning with the pin): the frictionless generalized forces on the ten
    coordinates of a pin, its neighbours' positions and the sheaves = minus the gradient of the potentials."""
    _, a2 = models
    q, v = state[:a2.n2], np.zeros(a2.n2)
    Q, _ = _contact_forces(a2, q, v)

    def U(qq):
        return a2._contacts(qq, v, details=True)[3][1]["potential"].sum()
    ends, shafts, _, (_, c) = a2._contacts(q, v, details=True)
    touching = np.unique(a2.pin_of(ends[c["delta"] > 0]))
    assert len(touching) > 40
    pins = np.random.default_rng(3).choice(touching, 5, replace=False)
    idx = a2.family.dof_index
    cols = np.concatenate([idx[pins].ravel(), idx[(pins + 1) % a2.family.n, :2].ravel(),
                           idx[(pins - 1) % a2.family.n, :2].ravel(), a2._idx[2]])
    scale = np.abs(Q).max()
    for j in cols:
        h = 1e-10 if j not in idx[:, 4:8] else 1e-8
        qp, qm = q.copy(), q.copy()
        qp[j] += h
        qm[j] -= h
        assert Q[j] == pytest.approx(-(U(qp) - U(qm)) / (2 * h), rel=1e-6, abs=1e-6 * scale), j


def test_halves_without_offset_are_one_contact_of_twice_the_stiffness(models, state):
    """With h_pin -> 0 both halves of an end sit at the pin end: two H2 contacts at one penetration, each with
    ``c``, are one contact with ``2 c`` (normal force, potential; friction is linear in ``N``), so A2 equals A1
    with H2 at ``2 c`` to round-off; with the real offset the forces differ, mildly."""
    a1, a2 = models
    q, v = state[:a2.n2], state[a2.n2:2 * a2.n2]
    tiny = replace(a2, contact=EndContact(replace(a2.contact.pair, h_pin=1e-12)))
    pair1 = a1.contact.pair
    a1x2 = replace(a1, contact=EndContact(replace(pair1, c=2 * pair1.c)), fixed_z=a2.fixed_z)   # A2's start
    Q2, P2 = _contact_forces(tiny, q, v)
    Q1, P1 = _contact_forces(a1x2, q, v)
    assert np.abs(Q2 - Q1).max() < 1e-6 * np.abs(Q1).max()
    assert P2 == pytest.approx(P1, rel=1e-6)
    Q, _ = _contact_forces(a2, q, v)
    assert 1e-4 < np.abs(Q - Q1).max() / np.abs(Q1).max() < 0.2       # the offset matters, mildly


def test_friction_power_is_the_work_rate_of_the_friction_forces(models, state):
    _, a2 = models
    q, v = state[:a2.n2], state[a2.n2:2 * a2.n2]
    Q, Pf = _contact_forces(a2, q, v)
    pair = a2.contact.pair
    frictionless = replace(a2, contact=EndContact(replace(pair, pair=replace(pair.pair, f0=0.0))))
    Q0, Pf0 = _contact_forces(frictionless, q, v)
    assert Pf0 == 0.0 and Pf < -1.0
    assert Pf == pytest.approx(float((Q - Q0) @ v), rel=1e-10)


def test_jacobian_against_differences_and_on_its_pattern(models, state):
    _, a2 = models
    J = a2.jac(0.0, state).toarray()
    assert not np.any(J[~a2.jac_sparsity.toarray()])
    rng = np.random.default_rng(5)
    n2, nc = a2.n2, a2.family.size
    slopes = rng.choice(a2.family.dof_index[:, 4:8].ravel(), 6, replace=False)
    cols = np.concatenate([rng.choice(nc, 10, replace=False), slopes, n2 + rng.choice(nc, 10, replace=False),
                           np.arange(nc, n2), n2 + np.arange(nc, n2)])
    assert_jacobian_columns(a2, state, J, cols)
