"""Variant (e) on rigid shafts: the chain with independent pin halves (A5) with the refined contact H2 at both ends of
every half (issues 13/14/16)."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.half_end_contact import HalfEndContact
from cvtfem.errors import InputError
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT
from cvtfem.machines.chain_halves_refined_cvt import ChainHalvesRefinedCVT
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_jacobian_columns

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])   # N per sheave, as the S2, A1 and A5 tests


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module")
def model(scene):
    """A5 with H2 and the presets' pin face (inclined at the flank angle)."""
    return from_scene(scene, reference_geometry(), F_APPL, model="chain-A5", contact="hertz-refined")


@pytest.fixture(scope="module")
def placed(model, scene):
    """The placed start (halves rolling on each other on the path of the ratio, sheaves at the wedge estimate)."""
    return model.placed_state(RATIO, scene.cvt.regime.input_speed)


@pytest.fixture(scope="module")
def flat(scene):
    """A5 with the flat pin face (theta = 0) and its placed start: a face symmetric about the pin axis, the same for
    a half turning with its own link as for a whole pin turning with the bisector of its two links."""
    m = from_scene(scene, reference_geometry(), F_APPL, model="chain-A5", contact="hertz-refined", face_inclination=0.0)
    return m, m.placed_state(RATIO, scene.cvt.regime.input_speed)


def _perturbed(model, x0, seed=0):
    """A running state off balance: random chain offsets (0.2 um; slopes 2e-7), velocities, sheave and shaft rates."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    x[n2 + nc:n2 + nc + 4] += rng.normal(0.0, 0.05, 4)
    return x


def _contact_forces(model, q, v):
    """Generalized contact forces (all but the chain's own) and the friction power."""
    Q, Pf = model._forces(q, v, np.zeros(2), np.zeros(2))
    nc = model.family.size
    Q[:nc] -= model.family.forces(q[:nc], v[:nc])
    return Q, Pf


def _frictionless(model):
    """The model with friction coefficient 0 in its H2 kernel (A5: wrapped in HalfEndContact; A1: bare)."""
    pair = model.contact.pair
    if isinstance(pair, HalfEndContact):
        return replace(model, contact=EndContact(replace(pair, pair=replace(pair.pair, f0=0.0))))
    return replace(model, contact=EndContact(replace(pair, f0=0.0)))


def test_construction_and_contact_inputs(model, placed):
    """H2 at four half ends per pin; the contact map reads each half end ``u_0 + s u_1``, the chord of the half's link
    (``p-`` with ``(p+1)+``, ``(p-1)-`` with ``p+``), ``x3 = s w_0 + w_1`` and the half's end slope, mirrored."""
    from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR

    assert isinstance(model, ChainHalvesRefinedCVT) and isinstance(model.contact.pair, HalfEndContact)
    assert model.contact.refined and model.n_ends == 4 * model.family.n
    x = _perturbed(model, placed)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    ends = np.arange(model.n_ends)
    shafts = np.ones(model.n_ends, int)
    cols, coef = model._contact_map(ends, shafts)
    X = (coef * np.concatenate([q, v, model._constants])[cols]).sum(axis=2)
    u, _, _ = model.family.split(q[:model.family.size])
    n, chain = model.family.n, model.family.chain
    p, h, s = ends // 4, (ends // 2) % 2, ends % 2
    sign = np.where(s == 1, 1.0, -1.0)
    # the half ends and slopes against the element family's own axis (ChainA5.axis_points, cubic in xi)
    end = chain.axis_points(q[:model.family.size], p, h, sign)
    np.testing.assert_allclose(X[:, :2], end[:, :2], rtol=0, atol=1e-15)
    np.testing.assert_allclose(X[:, 4], sign * end[:, 2], rtol=0, atol=1e-15)      # x3 mirrored for x3 < 0
    def diff(d):                        # central difference in xi of the cubic axis: U' + d^2 U''' / 6
        qc = q[:model.family.size]
        return (chain.axis_points(qc, p, h, sign + d) - chain.axis_points(qc, p, h, sign - d))[:, :2] / (2 * d)
    slope = (4 * diff(5e-3) - diff(1e-2)) / 3 * 2 / model.family.geom.l          # Richardson: exact for a cubic
    np.testing.assert_allclose(END_SLOPE_FACTOR * X[:, 5:7], sign[:, None] * slope, rtol=0, atol=1e-12)
    chord = np.where(h[:, None] == 0, u[1, 0, (p + 1) % n] - u[0, 0, p], u[1, 0, p] - u[0, 0, (p - 1) % n])
    np.testing.assert_allclose(X[:, 2:4], chord, rtol=0, atol=1e-15)
    with pytest.raises(InputError, match=r"cvt\.effects\.contact"):
        ChainHalvesRefinedCVT.from_parameters(reference_geometry(), contact="hertz", model="chain-A5")


def test_compiled_contact_pass_equals_its_numpy_twin(model, placed):
    """HalfEndContact's compiled map and kernel equal the numpy formulas (``reference=True``) to round-off, and the
    ``details`` pass gives the same outputs."""
    x = _perturbed(model, placed, seed=8)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    _, shafts, _, _, X, Y = model._contact_set(q, v)
    Yr = model.contact.pair.local(X, shafts, reference=True)
    Yd = model.contact.pair.local(X, shafts, details=True)[0]
    scale = np.abs(Yr).max(axis=0)
    np.testing.assert_allclose(2 * Y, Yr, rtol=0, atol=1e-11 * scale.max())     # EndContact takes one end: 1/2
    np.testing.assert_array_equal(Yd, Yr)
    assert np.abs(Yr[:, 2:4]).max() > 0                                          # the twist is in the comparison


def test_contact_forces_are_minus_the_gradient_of_the_hertz_potential(model, placed):
    """Through the contact map (half end, its slope, the link chord, movable or fixed sheave): the frictionless
    generalized forces on every coordinate of a half (both halves of six pins), the neighbours' halves and the
    sheaves equal minus the gradient of the Hertz potentials (central differences, 1e-6)."""
    fm = _frictionless(model)
    q, v = _perturbed(model, placed, seed=1)[:model.n2], np.zeros(model.n2)
    Q, Pf = _contact_forces(fm, q, v)
    assert Pf == 0.0

    def U(qq):
        return fm._contacts(qq, v, details=True)[3][1]["potential"].sum()
    ends, _, _, (_, c) = fm._contacts(q, v, details=True)
    touching = np.unique(fm.pin_of(ends[c["delta"] > 0]))
    assert len(touching) > 40
    pins = np.random.default_rng(3).choice(touching, 6, replace=False)
    idx, n = fm.family.dof_index, fm.family.n
    cols = np.concatenate([idx[pins, :20].ravel(), idx[(pins + 1) % n, 10:12].ravel(),
                           idx[(pins - 1) % n, 0:2].ravel(), fm._idx[2]])
    scale = np.abs(Q).max()
    for j in cols:
        h = 1e-10
        qp, qm = q.copy(), q.copy()
        qp[j] += h
        qm[j] -= h
        assert Q[j] == pytest.approx(-(U(qp) - U(qm)) / (2 * h), rel=1e-6, abs=1e-6 * scale), j


def test_friction_power_is_the_work_rate_of_the_friction_forces(model, placed):
    """The kernel's friction power (slip of the material points of the half's face at ``R_*``, the half turning with
    its link) equals the power of the generalized friction forces, ``(Q - Q_frictionless) . v``, to 1e-10."""
    x = _perturbed(model, placed, seed=2)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    Q, Pf = _contact_forces(model, q, v)
    Q0, Pf0 = _contact_forces(_frictionless(model), q, v)
    assert Pf0 == 0.0 and Pf < -1.0
    assert Pf == pytest.approx(float((Q - Q0) @ v), rel=1e-10)

def test_twist_acts_on_the_halves_of_one_link_as_1_352(flat):
    """The force on the link chord of a half end is (1.352): the twist moment ``F . ((k + gamma) x rho)`` of the
    friction force at ``R_*`` (``rho = R_* - R_pin``, ``gamma`` the end slope) over ``|c|`` along ``n = k x c/|c|``,
    +on the front half, -on the rear one (spec §5.5, independent halves), per end (EndContact's half of the pair).
    The flat face: an inclined one turning with the half adds the normal force's twist (``dDelta/dphi``)."""
    from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR

    model, placed = flat
    x = _perturbed(model, placed, seed=2)
    q, v = x[:model.n2], x[model.n2:2 * model.n2]
    _, shafts, _, _, X, (Y, d) = model._contact_set(q, v, details=True)
    c = X[:, 2:4]
    n = np.column_stack([-c[:, 1], c[:, 0]]) / np.linalg.norm(c, axis=1)[:, None]
    rho = d["point"] - np.column_stack([X[:, 0:2], X[:, 4]])
    g = np.column_stack([END_SLOPE_FACTOR * X[:, 5:7], np.zeros(len(X))])
    moment = np.sum(d["F_fr"] * np.cross(np.array([0.0, 0.0, 1.0]) + g, rho), axis=1)
    expected = (moment / np.linalg.norm(c, axis=1))[:, None] * n
    assert np.abs(expected).max() > 1.0                                  # N: the twist is not negligible
    np.testing.assert_allclose(Y[:, 2:4], expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def _a1_state_in_halves(a1, a5, x1):
    """The A5 state with both halves of every pin at A1's pin (its ten coordinates), packs at the pins' axial
    centres, shafts and sheaves as A1's."""
    n1, n5 = a1.family.size, a5.family.size
    m1, m5 = a1.n2 - n1, a5.n2 - n5
    assert m1 == m5
    x5 = np.zeros(a5.size)
    for off1, off5 in ((0, 0), (a1.n2, a5.n2)):
        u1, w1 = a1.family.split(x1[off1:off1 + n1])
        q5 = np.zeros(n5)
        u5, w5, qp = a5.family.split(q5)
        u5[:], w5[:], qp[:] = u1[None], w1[None], w1[0]
        x5[off5:off5 + n5] = q5
        x5[off5 + n5:off5 + a5.n2] = x1[off1 + n1:off1 + a1.n2]
    x5[2 * a5.n2:] = x1[2 * a1.n2:]
    return x5


def test_halves_at_the_whole_pin_are_a1_with_twice_the_contact(flat, scene):
    """With both halves of every pin at the same place as A1's pin (zero offset, rigidly tied), each half end is one
    H2 contact at A1's end: frictionless, the half forces summed over the two halves equal A1 + H2 with ``2 c`` on all
    ten pin coordinates and the sheaves, to round-off.  With friction and the chain turning rigidly with one shaft
    (every link chord turns at the shaft's rate, so each half's spin equals A1's bisector spin) all forces and the
    friction power agree too: A1's twist map (1.349) with unit chords, ``(E - e e) n / |e_- + e_+| / L = n_e / (2 L)``
    per chord, is exactly half the twist moment through each chord, the sum of the two halves' (1.352).
    The flat face: an inclined face turns with its body, a half's with its link chord and A1's with the bisector of
    the pin's two chords (half a pitch angle apart on an arc), so the two contacts differ there (24 and 11 % on the
    sheaves' axial forces at this state, 10 deg)."""
    model, placed = flat
    a1 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A1", contact="hertz-refined",
                    face_inclination=0.0)
    pair1 = a1.contact.pair
    a1x2 = replace(a1, contact=EndContact(replace(pair1, c=2 * pair1.c)), fixed_z=model.fixed_z)
    fam5 = model.family
    q5 = placed[:fam5.size]
    u5, w5, _ = fam5.split(q5)
    x1 = np.zeros(a1.size)
    u1, w1 = a1.family.split(x1[:a1.family.size])
    u1[:], w1[:] = 0.5 * (u5[0] + u5[1]), 0.5 * (w5[0] + w5[1])
    rng = np.random.default_rng(7)
    nc1 = a1.family.size
    x1[:nc1] += rng.normal(0.0, 2e-7, nc1)
    x1[nc1:a1.n2] = placed[fam5.size:model.n2]
    # rigid turn with the driven shaft about its centre (positions), the vectors turning with it
    w = 40.0
    centre = model.contact.centres[1]
    u1v, _ = a1.family.split(x1[a1.n2:a1.n2 + nc1])
    u1v[0] = w * (u1[0] - centre) @ np.array([[0.0, 1.0], [-1.0, 0.0]])
    u1v[1:] = w * u1[1:] @ np.array([[0.0, 1.0], [-1.0, 0.0]])
    x1[a1.n2 + nc1:2 * a1.n2] = rng.normal(0.0, 0.05, a1.n2 - nc1)
    x5 = _a1_state_in_halves(a1, model, x1)

    def halves_summed(Q5):
        """The forces on both halves summed (A1's layout), and those on the shafts and sheaves."""
        u, w_, _ = fam5.split(Q5[:fam5.size])
        return a1.family.join(u[0] + u[1], w_[0] + w_[1]), Q5[fam5.size:model.n2]

    for m5, m1, friction in ((_frictionless(model), _frictionless(a1x2), False), (model, a1x2, True)):
        Q5, P5 = _contact_forces(m5, x5[:model.n2], x5[model.n2:2 * model.n2])
        Q1, P1 = _contact_forces(m1, x1[:a1.n2], x1[a1.n2:2 * a1.n2])
        chain5, rest5 = halves_summed(Q5)
        scale = np.abs(Q1).max()
        np.testing.assert_allclose(rest5, Q1[nc1:], rtol=1e-9, atol=1e-9 * scale)        # sheaves z, phi
        u5s, w5s = a1.family.split(chain5)
        u1s, w1s = a1.family.split(Q1[:nc1])
        np.testing.assert_allclose(w5s, w1s, rtol=1e-9, atol=1e-9 * scale)
        np.testing.assert_allclose(u5s, u1s, rtol=1e-9, atol=1e-9 * scale)
        if friction:
            assert P1 < -1.0 and P5 == pytest.approx(P1, rel=1e-9)
            assert np.abs(Q1[:nc1] - _contact_forces(_frictionless(m1), x1[:a1.n2], x1[a1.n2:2 * a1.n2])[0][:nc1]
                          ).max() > 1e-3 * scale                    # friction (and its twist) are in the check
        else:
            assert P5 == P1 == 0.0


def test_jacobian_against_differences_and_on_its_pattern(model, placed):
    """``jac`` against central differences of ``rhs`` (chain coordinates of both kinds, every shaft, sheave and loop
    column), zero off ``jac_sparsity``.  With the smooth clamped plates of A3-keep (A4's plates switch states within a
    difference step near zero tension: test_chain_halves_cvt)."""
    from cvtfem.elements.chain.symmetric import damping_from_ratio
    from cvtfem.machines.chain_halves_cvt import halves_family

    geom = reference_geometry()
    m = replace(model, family=halves_family(geom, damping_from_ratio(geom, 0.05), 2.1e11, plate_model="A3-keep"))
    x = _perturbed(m, placed, seed=5)
    J = m.jac(0.0, x).toarray()
    assert not np.any(J[~m.jac_sparsity.toarray()])
    rng = np.random.default_rng(5)
    n2, nc = m.n2, m.family.size
    slopes = rng.choice(m.family.dof_index[:, [4, 5, 6, 7, 14, 15, 16, 17]].ravel(), 6, replace=False)
    cols = np.concatenate([rng.choice(nc, 12, replace=False), slopes, n2 + rng.choice(nc, 12, replace=False),
                           np.arange(nc, n2), n2 + np.arange(nc, n2), np.arange(2 * n2, 2 * n2 + 4)])
    assert_jacobian_columns(m, x, J, cols)


def test_scene_path_and_refusals():
    """`chain-A5` with `hertz-refined` on rigid shafts builds variant (e) on rigid shafts (the preset's elastic shafts
    are admitted too); `chain-A5-point` (the point contact by name) refuses it, naming the key; the H1 path is
    unchanged."""
    from cvtfem.machines import layout
    from cvtfem.machines.cvt import chain_loop, chain_refusal

    e = load_scene("variant-e")
    assert chain_refusal(e) is None                     # on elastic shafts: test_chain_halves_elastic
    rigid = e.replace({"cvt": {"effects": {"shaft_elasticity": False}}})
    assert chain_refusal(rigid) is None
    m = chain_loop(rigid)
    assert isinstance(m, ChainHalvesRefinedCVT) and m.n2 == 21 * rigid.cvt.chain.n_pins + 4
    listed = [o.name for part in layout(rigid) for o in part.outputs]
    assert sorted(listed) == sorted(o.name for o in m.output_specs)
    with pytest.raises(InputError, match=r"cvt\.effects\.contact"):
        chain_loop(rigid.replace({"cvt": {"model": "chain-A5-point"}}))
    h1 = chain_loop(rigid.replace({"cvt": {"effects": {"contact": "hertz"}}}))
    assert type(h1) is ChainHalvesCVT


@pytest.mark.slow
def test_energy_balance_over_a_short_run(model, placed):
    """From the placed state (off balance), 1 us of Radau (rtol 1e-6, about 320 steps, 50 s CPU): the work integrals,
    with the chain's internal friction and damping and the H2 friction in the dissipated work, close the energy
    balance to 1e-6 of the input work (about 0.07 J; found 2e-9)."""
    from cvtfem.integrate import solve

    res = solve(model, (0.0, 1e-6), placed, method="Radau", rtol=1e-6, atol=1e-9, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity)
    assert res.status == 0
    x1 = res.y[:, -1]
    W = model.split(x1)[3]
    assert W[0] > 0.03 and W[2] > 0.05 * W[0]
    assert model.energy(x1) - model.energy(placed) == pytest.approx(W[0] - W[1] + W[3] - W[2], abs=1e-6 * W[0])


@pytest.mark.slow
def test_cvtfem_run_variant_e_on_rigid_shafts(cli, tmp_path):
    """`cvtfem run` of variant (e) with `shaft_elasticity = false` (chain-A5's solver settings) for 3 us through the
    CLI (after the quasi-static attempt, from the placement): it runs, every output is finite and the work
    integrals close the energy balance to 1e-5 of the input work."""
    import json

    import h5py

    scene = tmp_path / "variant-e-rigid.toml"
    scene.write_text('preset = ["variant-e", "regime-stationary", "chain-uniform"]\n[solver]\nmethod = "Radau"\n'
                     'rtol = 1e-3\natol = 1e-6\n[output]\nstep = 1e-6\n[cvt.effects]\nshaft_elasticity = false\n'
                     '[cvt.friction]\nlaw = "tanh"\n')
    h5, js = tmp_path / "e.h5", tmp_path / "s.json"
    r = cli("run", str(scene), "--until", "3e-6", "--results", str(h5), "--summary-json", str(js), timeout=1500)
    assert r.returncode == 0, r.stderr
    assert json.loads(js.read_text())["n_coordinates"] == 21 * 84 + 4
    with h5py.File(h5) as f:
        s = f["series"]
        for name in s:
            assert np.isfinite(s[name][:]).all(), name
        assert len(s["time"]) >= 3
        W, E = s["work"][-1], s["energy"][:]
    assert W[0] > 0.0 and abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-5 * W[0]
