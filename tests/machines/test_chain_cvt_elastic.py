"""The symmetric chain on elastic shafts (issue 14: Table 1.1 (b)'s structure under chain-S2): the structure block
against the rotor code, the contact map in the sheave frames, the rigid limit, the Jacobian and the energy balance."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.assembly.model import Model
from cvtfem.control.clamping import Clamping
from cvtfem.elements.chain.sheave_contact import central_local_jacobian
from cvtfem.elements.contact.hertz import hertz_potential
from cvtfem.errors import InputError
from cvtfem.machines import layout
from cvtfem.machines.chain_cvt import from_scene as rigid_from_scene
from cvtfem.machines.chain_cvt_elastic import ElasticChainCVT, elastic, shaft_parameters
from cvtfem.machines.cvt import band_params, chain_geometry, chain_loop
from cvtfem.machines.rotor import build_model
from cvtfem.machines.shaft_structure import STEEL_DENSITY, STEEL_POISSON, build_structure, shaft_mesh
from cvtfem.modal import ModalProblem
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_energy_balance, assert_jacobian_columns

SCENE = "chain-S2,shafts-elastic"


@pytest.fixture(scope="module")
def scene():
    return load_scene(SCENE)


@pytest.fixture(scope="module")
def rigid(scene):
    rg = scene.cvt.regime
    F = Clamping(band_params(scene), rg.clamping_safety, rg.clamping_split, rg.min_clamping_force).forces(rg.torque,
                                                                                                          rg.ratio)
    return rigid_from_scene(scene, chain_geometry(scene), F, model="chain-S2", law="tanh")


@pytest.fixture(scope="module")
def rigid_start(rigid):
    w1, _, i = rigid.regime.targets(0.0)
    return (i, w1) + rigid.static_state(i, w1)


def _elastic(scene, rigid, rigid_start, stiffer: float = 1.0) -> ElasticChainCVT:
    """The chain on the scene's shafts with Young's modulus and bearing stiffness ``stiffer`` times the scene's."""
    params = tuple(replace(p, bearing_stiffness=stiffer * p.bearing_stiffness) for p in shaft_parameters(scene))
    structure = build_structure(params, stiffer * scene.cvt.young_modulus)
    return replace(elastic(rigid, structure), rigid_start=rigid_start)


@pytest.fixture(scope="module")
def static(scene, rigid, rigid_start):
    x0, rep = _elastic(scene, rigid, rigid_start).static_state(*rigid_start[:2])
    return rep["model"], x0, rep


def _rotor_scene(tmp_path, scene, k: int):
    """The rotor-code scene (``cvtfem modes``) of shaft ``k`` with its two sheaves as rigid disks and its bearings."""
    p = shaft_parameters(scene)[k]
    x = shaft_mesh(p)
    E = scene.cvt.young_modulus
    s = build_structure(shaft_parameters(scene), E)
    A = (p.inertia - STEEL_DENSITY * np.pi * p.diameter ** 4 / 32 * p.length) / 2
    lines = ["[[material]]", 'name = "steel"', f"E = {E!r}", f"G = {E / (2 * (1 + STEEL_POISSON))!r}",
             f"rho = {STEEL_DENSITY!r}"]
    for L in np.diff(x):
        lines += ["[[shaft]]", f"length = {float(L)!r}", f"outer_diameter = {p.diameter!r}", "inner_diameter = 0.0",
                  'material = "steel"']
    for node in (s.node_of_sheave[k] - s.offset[k]) // 6:
        lines += ["[[disk]]", f"node = {int(node)}", f"mass = {p.sheave_mass / 2!r}",
                  f"Id = {p.sheave_transverse_inertia / 2!r}", f"Ip = {float(A)!r}"]
    for node, axial in ((0, True), (len(x) - 1, False)):
        lines += ["[[bearing]]", f"node = {node}", f"kxx = {p.bearing_stiffness!r}", f"kyy = {p.bearing_stiffness!r}",
                  f"cxx = {p.bearing_damping!r}", f"cyy = {p.bearing_damping!r}"]
        if axial:
            lines += [f"kzz = {p.bearing_stiffness!r}", f"czz = {p.bearing_damping!r}"]
    lines += ["[rotor]", "gyroscopic = false"]
    path = tmp_path / f"shaft{k}.toml"
    path.write_text("\n".join(lines) + "\n")
    return load_scene(path)


def _frequencies(M, K, C, kind, speed=0.0, G=None, n=16):
    """Damped natural frequencies (Hz) and whirl labels of the lowest ``n`` modes."""
    modes = ModalProblem(M, K, C, G if G is not None else 0 * M, kind).solve(speed, n)
    return modes.wd / (2 * np.pi), np.array(modes.whirl)


def test_structure_block_at_standstill_equals_the_rotor_code(scene, tmp_path):
    """Each shaft with its sheaves and bearings: the structure block's natural frequencies at standstill equal
    those of the rotor code (``cvtfem modes``) built from a rotor scene of the same shaft to 1e-8 (acceptance
    0.5 %) for every bending and torsion mode below 5 kHz; axial modes differ by design (the movable sheave slides
    on the shaft) and are left out."""
    s = build_structure(shaft_parameters(scene), scene.cvt.young_modulus)
    for k in range(2):
        sl = slice(s.offset[k], s.offset[k] + 6 * len(s.x[k]) + 1)
        f, whirl = _frequencies(s.M[sl, sl], s.K[sl, sl], s.C[sl, sl], s.dof_kind[sl], n=24)
        rotor = build_model(_rotor_scene(tmp_path, scene, k))
        fr, whirl_r = _frequencies(rotor.M, rotor.K, rotor.C, rotor.dof_kind, n=24)
        mine, ref = f[(whirl != "axial") & (f < 5e3)], fr[(whirl_r != "axial") & (fr < 5e3)]
        assert len(mine) >= 8 and len(mine) == len(ref)
        np.testing.assert_allclose(mine, ref, rtol=1e-8)


@pytest.mark.parametrize("speeds", [(0.0, 0.0), (400.0, 900.0)])
def test_j11_without_chain_gives_the_structure_frequencies(static, speeds):
    """The source's J11 (1.358): the Jacobian of the coupled model over the shaft/sheave states with the chain
    frozen and its contact stiffness zero has the structure block's eigenvalues (frequencies to 1e-6) at
    standstill, i.e. the Campbell lines with the chain removed, and with the shafts spinning (rad/s; the
    sheaves' gyroscopic terms at each shaft's speed, forward and backward whirl split)."""
    model, x0, _ = static
    free = replace(model, contact=replace(model.contact, c=np.zeros(2)))
    s = model.structure
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    x[n2 + nc:2 * n2] = 0.0
    for k, w in enumerate(speeds):                                # every node of shaft k spins at w
        nodes = slice(n2 + nc + s.offset[k], n2 + nc + s.offset[k] + 6 * len(s.x[k]))
        x[nodes][5::6] = w
    rows = np.concatenate([np.arange(nc, n2), n2 + np.arange(nc, n2)])
    J11 = free.jac(0.0, x)[rows][:, rows].toarray()
    lam = np.linalg.eigvals(J11)
    lam = lam[lam.imag > 1.0]                                     # rad/s: drop the free spins and zeta
    G = speeds[0] * s.G[0] + speeds[1] * s.G[1]
    f_ref, _ = _frequencies(s.M, s.K, s.C, s.dof_kind, speed=1.0, G=G, n=40)
    f = np.sort(lam.imag / (2 * np.pi))[:len(f_ref)]
    np.testing.assert_allclose(f, np.sort(f_ref), rtol=1e-6)
    if speeds[0]:
        f_still, _ = _frequencies(s.M, s.K, s.C, s.dof_kind, n=40)
        assert np.abs(np.sort(f_ref) / np.sort(f_still) - 1).max() > 1e-3   # the gyroscopic split shows


def test_contact_map_forces_are_the_hertz_gradient_and_friction_has_the_kernel_power(static):
    """Per mapped contact (pin end on one tilted, shifted sheave): the position forces are minus the gradient of the
    Hertz potential of the mapped penetration (central differences of the potential, friction off); with friction
    the power of all generalized forces on the input rates is minus the potential's rate plus the kernel's
    friction power (the velocity map is the time derivative of the position map)."""
    model, x0, _ = static
    rng = np.random.default_rng(3)
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    s = model.structure
    tilt = nc + s.sheave_dofs[:, :, 3:5].ravel()
    x[tilt] += rng.normal(0.0, 2e-4, tilt.size)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    q, v = x[:n2], x[n2:2 * n2]
    e, k, j, _, _, Z, (Y, det) = model._mapped_set(q, v, details=True)
    on = det["delta"] > 0
    assert on.sum() > 40 and np.unique(j[on]).size == 2

    def potential(Zp):
        return hertz_potential(model.mapped_local(Zp, k, j, details=True)[1]["delta"], model.contact.c[k])
    grad = central_local_jacobian(lambda Zp, kk: potential(Zp)[:, None], Z, k, np.full(19, 1e-8), 1)[:, 0, :9]
    frictionless = replace(model, contact=replace(model.contact, f0=0.0))
    Y0 = frictionless.mapped_local(Z, k, j)
    scale = np.abs(Y0[:, :9]).max()
    np.testing.assert_allclose(Y0[on, :9], -grad[on], atol=2e-6 * scale)
    rates = np.column_stack([Z[:, 9:18], Z[:, 18]])
    terms = Y[:, :10] * rates                                     # large and cancelling: pins run at ~10 m/s
    np.testing.assert_array_less(np.abs(terms.sum(axis=1) + np.sum(grad * Z[:, 9:18], axis=1) - Y[:, 10]),
                                 1e-5 * np.abs(terms).sum(axis=1) + 1e-9)
    assert Y[:, 10].min() < -1.0


def test_static_state_on_elastic_shafts(static, rigid_start):
    """The quasi-static start balances (residual 1e-8 of F2); the bearings carry the resultant of the pins' forces
    on the sheaves (the support force is minus it, as on rigid shafts) and no axial force; the pins' axial forces
    tilt the two sheaves of a pulley opposite ways."""
    model, x0, rep = static
    assert rep["residual"] < 1e-8
    o = model.outputs(0.0, x0)
    for name in ("driving", "driven"):
        b = o[f"{name}.bearing_force"].reshape(2, 3)
        assert abs(b[:, 2]).max() < 1e-6 * abs(b).max()
        tilt = o[f"{name}.sheave_tilt"].reshape(2, 2)
        np.testing.assert_allclose(tilt[0], -tilt[1], rtol=1e-6)
        assert 1e-5 < abs(tilt).max() < 1e-2
    assert o["contact.slip_speed"].max() < 5e-3 * model.contact.v0   # pins turn with the tilted sheaves (1st order)
    n2 = model.n2
    e, k, j, _, _, _, Y = model._mapped_set(x0[:n2], np.zeros(n2))                # friction unloaded
    for i, name in enumerate(("driving", "driven")):
        on_sheaves = Y[k == i, 3:5].sum(axis=0)
        assert np.linalg.norm(on_sheaves) > 1e3
        np.testing.assert_allclose(o[f"{name}.support_force"], -on_sheaves, rtol=1e-6)
    # the pins' forces along the tilted sheave axis (mean of the pair) hold the clamping force to first order in tilt
    np.testing.assert_allclose(o["contact.sheave_axial_force"][1], rep["F2"], rtol=1e-3)


@pytest.mark.slow
def test_stiff_shafts_converge_to_the_rigid_transmission(scene, rigid, rigid_start):
    """Shafts and bearings 10, 100 and 1000 times stiffer: the quasi-static state's driving clamping force, mean
    link tension and bearing reaction approach the rigid ChainCVT's, the distance falling about tenfold per step."""
    _, _, x0r, rep_r = rigid_start
    o_r = rigid.outputs(0.0, x0r)
    errs = []
    for stiffer in (10.0, 100.0, 1000.0):
        model = _elastic(scene, rigid, rigid_start, stiffer)
        x0, rep = model.static_state(*rigid_start[:2])
        o = rep["model"].outputs(0.0, x0)
        errs.append([abs(rep["F1"] / rep_r["F1"] - 1), abs(rep["tension"] / rep_r["tension"] - 1),
                     np.linalg.norm(o["driving.support_force"] - o_r["driving.support_force"])
                     / np.linalg.norm(o_r["driving.support_force"])])
    errs = np.array(errs)
    assert np.all(errs[-1] < 2e-3), errs
    assert np.all(errs[1:] < 0.3 * errs[:-1] + 1e-6), errs


def _perturbed(model, x0, seed=0):
    """A running state off balance: random velocities, small position offsets of pins and structure."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    n2 = model.n2
    x[:n2] += rng.normal(0.0, 1e-6, n2)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    return x


def test_jacobian_against_differences_and_on_its_pattern(static):
    model, x0, _ = static
    x = _perturbed(model, x0, seed=2)
    J = model.jac(0.0, x).toarray()
    assert not np.any(J[~model.jac_sparsity.toarray()])
    rng = np.random.default_rng(5)
    n2, nc = model.n2, model.family.size
    s = model.structure
    sheave = nc + s.sheave_dofs.ravel()
    cols = np.concatenate([rng.choice(nc, 15, replace=False), n2 + rng.choice(nc, 15, replace=False), sheave,
                           n2 + sheave, nc + rng.choice(s.n, 10, replace=False), np.arange(2 * n2, 2 * n2 + 4)])
    assert_jacobian_columns(model, x, J, np.unique(cols))


def test_energy_balance_over_a_short_run(static):
    """Radau over 50 us from the quasi-static start (driving clamping force its reaction): kinetic + elastic
    energy of chain, shafts and contacts changes by input - output + clamping - dissipated work to 1e-6."""
    model, x0, rep = static
    m = model.with_clamping([rep["F1"], rep["F2"]])
    assert_energy_balance(m, x0, 5e-5)


def test_elastic_shafts_with_the_refined_contact_are_refused_by_name():
    with pytest.raises(InputError, match=r"cvt\.effects\.shaft_elasticity"):
        chain_loop(load_scene("chain-S3-refined,shafts-elastic"))


@pytest.mark.slow
def test_scene_builds_the_elastic_model_with_its_layout(scene):
    model = chain_loop(scene)
    assert isinstance(model, ElasticChainCVT) and isinstance(model, Model)
    parts = layout(scene)
    assert sum(p.n2 for p in parts) == model.n2
    assert sorted(o.name for p in parts for o in p.outputs) == sorted(o.name for o in model.output_specs)


@pytest.mark.slow
def test_whole_pin_chain_on_elastic_shafts():
    """chain-A1 on the elastic shafts (ElasticChainACVT, variant (b) less the refined contact): the quasi-static
    start balances, each sheave tilts under its own pins, the bearings carry the resultant of the pins' forces on
    the sheaves, the Jacobian matches central differences on the structure and sampled chain columns, and a 50 us
    Radau run closes the energy balance to 1e-6 of the input work."""
    from cvtfem.machines.chain_cvt_elastic import ElasticChainACVT

    model = chain_loop(load_scene("chain-A1,regime-chapter2,shafts-elastic"))
    assert isinstance(model, ElasticChainACVT)
    x0, info = model.start()
    assert "residual" in info["kind"]
    n2, nc = model.n2, model.family.size
    o = model.outputs(0.0, x0)
    _, k, j, _, _, _, Y = model._mapped_set(x0[:n2], np.zeros(n2))
    for i, name in enumerate(("driving", "driven")):
        assert np.abs(o[f"{name}.sheave_tilt"]).max() > 1e-5
        np.testing.assert_allclose(o[f"{name}.support_force"], -Y[k == i, 3:5].sum(axis=0), rtol=1e-6)
        assert (j[k == i] == 0).any() and (j[k == i] == 1).any()
    x = _perturbed(model, x0, seed=4)
    J = model.jac(0.0, x).toarray()
    assert not np.any(J[~model.jac_sparsity.toarray()])
    rng = np.random.default_rng(6)
    sheave = nc + model.structure.sheave_dofs.ravel()
    cols = np.concatenate([rng.choice(nc, 10, replace=False), n2 + rng.choice(nc, 10, replace=False), sheave,
                           n2 + sheave])
    assert_jacobian_columns(model, x, J, np.unique(cols))
    F1 = model.outputs(0.0, x0)["contact.sheave_axial_force"][0]
    assert_energy_balance(model.with_clamping([F1, model.F_appl[1]]), x0, 5e-5)


def test_mean_slip_of_a_running_state(static):
    """The loops' mean slip per shaft: the contact-force-weighted mean of the slip speeds the outputs report."""
    model, x0, _ = static
    x = _perturbed(model, x0, seed=7)
    slip = model.evaluate(0.0, x)[1]["slip"]
    e, k, j, _, _, _, (_, det) = model._mapped_set(x[:model.n2], x[model.n2:2 * model.n2], details=True)
    speeds = np.linalg.norm(det["slip"], axis=1)
    for i in range(2):
        w = det["N"][k == i]
        assert slip[i] == pytest.approx((w * speeds[k == i]).sum() / w.sum(), rel=1e-12) and slip[i] > 1e-3
