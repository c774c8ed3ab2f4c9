"""Variants (g) and (d) (issue 14, Table 1.1): the per-plate chains A3 and A4 with the refined contact H2 on elastic
shafts (:class:`~cvtfem.machines.chain_cvt_elastic.ElasticChainACVT` over the per-plate families)."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.machines.chain_cvt_elastic import ElasticChainACVT
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import assert_jacobian_columns

pytestmark = pytest.mark.slow          # the starts: A1, A3, A4 on rigid shafts, then on the elastic ones (~30-60 s)


def _variants(face: dict) -> dict:
    """``{"d": (model, x0, report), "g": (model, x0)}``: variant (d) from its start on elastic shafts; variant (g) with
    (d)'s face references (both from the wedge estimate and A1's balance) at (d)'s start state, which is no balance of
    (g) (some of A4's plates bear on a corner there) but a state to evaluate it at; ``face`` the `cvt.chain` keys
    written over the presets."""
    d = chain_loop(load_scene("variant-d,regime-stationary").replace({"cvt": {"chain": face}}))
    w1, _, i = d.regime.targets(0.0)
    x0, rep = d.static_state(i, w1)
    d = rep["model"]
    g = replace(chain_loop(load_scene("variant-g,regime-stationary").replace({"cvt": {"chain": face}})),
                z_ref=d.z_ref, rigid_start=d.rigid_start)
    return {"d": (d, x0, rep), "g": (g, x0)}


@pytest.fixture(scope="module")
def variants():
    """The variants with the presets' pin face (inclined at the flank angle)."""
    return _variants({})


@pytest.fixture(scope="module")
def flat_variants():
    """The variants with the flat pin face (theta = 0): the contact points 3-4 mm inside the pin ends."""
    return _variants({"face_inclination": 0.0})


def _running(model, x0, seed: int, pins=np.array([3, 30, 57]), angle: float = 4e-3):
    """A running state off balance: chain offsets (0.5 um) and velocities (0.05 m/s), sheave tilts (0.2 mrad), structure
    rates, and the pins ``pins`` tilted by ``angle`` (rad) in the chain plane against their plates (A4: corner contacts)."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    fam, nc, n2, s = model.family, model.family.size, model.n2, model.structure
    x[:nc] += rng.normal(0.0, 5e-7, nc)
    tilt = nc + s.sheave_dofs[:, :, 3:5].ravel()
    x[tilt] += rng.normal(0.0, 2e-4, tilt.size)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    u = fam.split(x[:nc])[0]
    tau = u[0, fam.ip1[pins]] - u[0, (pins - 1) % fam.n]
    u[1, pins] += angle * fam.geom.l / 2 * tau / np.linalg.norm(tau, axis=1)[:, None]
    return x


def test_start_balances_with_corner_contacts_in_the_outer_plates(flat_variants):
    """The start on elastic shafts (H2, residual 1e-8 of F2): the movable sheaves take the clamping forces along their
    tilted axes (1e-3). H2's contact points lie inside the pin ends, so the pins bend on the arcs (most on the small
    driving arc) and the outer plates tilt against them: there A4's plates bear on a corner (|m| = 1) or go slack,
    the inner half of the pin keeps line contact (the source, section 1.7: corner contacts occur in the outermost
    plates). At that state (g)'s clamped plates exceed the bound and the two right-hand sides differ.  The flat face
    (theta = 0): inclined at the flank angle, the contact points lie within 0.5 mm of the axis and no plate of (d)'s
    start bears on a corner (session 13)."""
    (d, x0, rep), (g, _) = flat_variants["d"], flat_variants["g"]
    assert isinstance(d, ElasticChainACVT) and d.contact.refined and d.family.chain.model == "A4"
    assert g.family.chain.model == "A3" and g.n2 == d.n2
    assert rep["residual"] < 1e-8
    o = d.outputs(0.0, x0)
    np.testing.assert_allclose(o["contact.sheave_axial_force"], [rep["F1"], rep["F2"]], rtol=1e-3)
    states, xi = o["chain.plate_state"], d.family.chain.xi
    assert 5 <= np.sum(states != 1) < 0.2 * len(states)
    assert np.all(np.abs(xi[states != 1]) > 0.25)
    assert np.nanmax(np.abs(o["chain.plate_reduced_moment"])) <= 1 + 1e-12
    assert np.nanmax(np.abs(g.outputs(0.0, x0)["chain.plate_reduced_moment"])) > 1
    fd, fg = d.rhs(0.0, x0), g.rhs(0.0, x0)
    assert np.abs(fd - fg).max() > 1e-3 * np.abs(fg).max()


@pytest.mark.parametrize("variant", ["g", "d"])
def test_jacobian_against_differences_and_on_its_pattern(variant, variants):
    """``jac`` zero off ``jac_sparsity`` and equal to central differences (1e-5 of each row's largest entry) on the
    tilted pins and their neighbours (A4's plates on corners), random chain columns, all sheave coordinates and
    rates and the loops."""
    model, x0 = variants[variant][:2]
    x = _running(model, x0, seed=2)
    J = model.jac(0.0, x).toarray()
    assert not np.any(J[~model.jac_sparsity.toarray()])
    rng = np.random.default_rng(5)
    n2, nc = model.n2, model.family.size
    pins = np.array([2, 3, 4, 29, 30, 31])
    near = model.family.dof_index[pins][:, [0, 2, 4, 6, 8, 9]].ravel()
    sheave = nc + model.structure.sheave_dofs.ravel()
    cols = np.concatenate([near, n2 + near, rng.choice(nc, 6, replace=False), n2 + rng.choice(nc, 6, replace=False),
                           sheave, n2 + sheave, np.arange(2 * n2, 2 * n2 + 4)])
    assert_jacobian_columns(model, x, J, np.unique(cols))


def test_energy_balance_over_a_short_run_of_variant_d(variants):
    """Radau (rtol 1e-6) over 10 us from the start (driving clamping force its reaction; plates on corners and slack on
    the small arc, switching as the pins move): chain, shaft, sheave and contact energy change by input - output +
    clamping - dissipated work to 1e-6 of the input work."""
    model, x0, rep = variants["d"]
    m = model.with_clamping([rep["F1"], rep["F2"]])
    res = solve(m, (0.0, 1e-5), x0, method="Radau", rtol=1e-6, atol=1e-9, n2=m.n2, jac=m.jac,
                jac_sparsity=m.jac_sparsity)
    assert res.status == 0
    W = m.split(res.y[:, -1])[3]
    assert W[0] > 0.5 and W[2] > 0.0
    assert m.energy(res.y[:, -1]) - m.energy(x0) == pytest.approx(W[0] - W[1] + W[3] - W[2], abs=1e-6 * W[0])


@pytest.mark.parametrize("variant", ["variant-g", "variant-d"])
def test_cvtfem_run_of_the_variant(cli, tmp_path, variant):
    """`cvtfem run` of the preset for 10 us (output every 2 us) from its start on elastic shafts: finished, every
    output finite, the work integrals close the energy balance to 1e-5 of the input work."""
    import json

    import h5py

    scene = tmp_path / "v.toml"
    scene.write_text(f'preset = "{variant}"\n[output]\nstep = 2e-6\n')
    h5, js = tmp_path / "v.h5", tmp_path / "s.json"
    r = cli("run", str(scene), "--until", "1e-5", "--results", str(h5), "--summary-json", str(js), timeout=900)
    assert r.returncode == 0, r.stderr
    summary = json.loads(js.read_text())
    assert summary["status"] == "finished" and summary["model"] == {"variant-g": "chain-A3", "variant-d": "chain-A4"}[variant]
    with h5py.File(h5) as f:
        s = f["series"]
        assert len(s["time"]) == 6
        for name in s:
            assert np.isfinite(s[name][:]).all(), name
        W, E = s["work"][-1], s["energy"][:]
    assert W[0] > 0.05 and abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-5 * W[0]
