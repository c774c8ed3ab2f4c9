"""The compiled mapped-contact path of the chains on elastic shafts (variant (b): A1 with H2; variant (e): A5 half ends
with H2; variant (zh): A5 half ends with H1; :mod:`cvtfem.elements.chain.mapped_contact_kernel`) against its numpy twin
(``ElasticChainCVT.mapped_local``, ``ElasticChainACVT._refined_frame``, ``reference=True``): the frame map and its
derivative, the generalized forces and friction power on random running states, the contacts' Jacobian entries; and
the structure's forces and accelerations from their precomputed operators against the matrices they stand for.  The
symmetric chains' H1 path on elastic shafts runs compiled in ``test_chain_cvt_elastic.py`` (energy, Jacobian)."""
from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.elements.chain import mapped_contact_kernel as MCK
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_cvt_elastic import elastic, shaft_parameters
from cvtfem.machines.cvt import chain_geometry
from cvtfem.machines.shaft_structure import build_structure
from cvtfem.scene.loader import load_scene

F_APPL = np.array([30000.0, 35000.0])   # N per sheave
SCENES = {"b": ("variant-b,regime-stationary,chain-uniform", "chain-A1", "hertz-refined"),
          "e": ("variant-e,regime-stationary,chain-uniform", "chain-A5", "hertz-refined"),
          "zh": ("variant-zh,regime-stationary,chain-uniform", "chain-A5", "hertz")}
KINDS = {"b": MCK.REFINED, "e": MCK.REFINED_HALF_END, "zh": MCK.POINT}
#: Central-difference steps of the mapped inputs (positions, rates, spin rate), as ``_mapped_jacobian``.
H_POS = 1e-9


@pytest.fixture(scope="module", params=sorted(SCENES))
def placed(request):
    """``(name, model, x0)``: the chain placed on the path at the start ratio (wedge estimate of the sheaves) on the
    undeformed elastic shafts, the faces' references there (no quasi-static solve)."""
    name, model_name, contact = SCENES[request.param]
    scene = load_scene(name)
    rigid = from_scene(scene, chain_geometry(scene), F_APPL, model=model_name, contact=contact, law="tanh")
    model = elastic(rigid, build_structure(shaft_parameters(scene), scene.cvt.young_modulus))
    w1, _, ratio = rigid.regime.targets(0.0)
    pl, u3, z = rigid.wedge_guess(ratio, F_APPL[1])
    nc = rigid.family.size
    x0r = np.zeros(rigid.size)
    x0r[:nc], x0r[rigid._idx[2]] = rigid._placed(pl, u3), z
    model = replace(model, z_ref=model._face_reference(x0r))
    x0 = np.zeros(model.size)
    x0[:nc] = x0r[:nc]
    return request.param, model, x0


def _running(model, x0, seed: int):
    """A running state: random chain offsets (0.2 um) and velocities (0.05 m/s), sheave tilts (0.2 mrad) and shifts
    (2 um), structure rates, spin rates about 300 rad/s."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2, s = model.family.size, model.n2, model.structure
    x[:nc] += rng.normal(0.0, 2e-7, nc)
    tilts, shifts = nc + s.sheave_dofs[:, :, 3:5].ravel(), nc + s.sheave_dofs[:, :, 0:2].ravel()
    x[tilts] += rng.normal(0.0, 2e-4, tilts.size)
    x[shifts] += rng.normal(0.0, 2e-6, shifts.size)
    x[n2:2 * n2] += rng.normal(0.0, 0.05, n2)
    x[n2 + model._idx[1]] = rng.uniform(250.0, 350.0, 2)
    return x


def _qv(model, x):
    return x[:model.n2], x[model.n2:2 * model.n2]


def test_compiled_path_is_taken(placed):
    """(b), (e) and (zh) run the compiled path (numba is a dependency), each with its kernel."""
    name, model, _ = placed
    assert model._compiled_mapped is not None and model._compiled_mapped[4] == KINDS[name]


def test_frame_map_equals_numpy_twin(placed):
    """:func:`MCK.frame_a1` against ``ElasticChainACVT._refined_frame`` (A1's map, which (e) composes with constant
    maps) on random frame inputs on every (shaft, sheave): positions and derivative to round-off, and the derivative
    has no nonzero off :data:`MCK.PATTERN`."""
    from cvtfem.machines.chain_cvt_elastic import ElasticChainACVT

    name, model, _ = placed
    if KINDS[name] == MCK.POINT:
        pytest.skip("H1 maps the end point alone (no frame derivative)")
    rng = np.random.default_rng(5)
    m = 64
    k, j = rng.integers(0, 2, m), rng.integers(0, 2, m)
    c = model.contact.centres[k]
    P = np.zeros((m, MCK.N_FRAME))
    P[:, 0:6] = np.tile(c, 3) + rng.uniform(-0.06, 0.06, (m, 6))
    P[:, 6] = rng.uniform(-5e-3, 5e-3, m)
    P[:, 7:9] = rng.normal(0.0, 1e-3, (m, 2))
    P[:, 9:12] = rng.normal(0.0, 1e-5, (m, 3))
    P[:, 12:14] = rng.normal(0.0, 2e-3, (m, 2))
    P[:, 14] = rng.normal(0.0, 1e-5, m)
    K_ref, dK_ref = ElasticChainACVT._refined_frame(model, P, k, j)
    frame = model._compiled_mapped[2]
    K, dKc = np.empty(MCK.N_KERNEL), np.empty(MCK.N_PATTERN)
    for t in range(m):
        MCK.frame_a1(P[t], frame[0, k[t], j[t]], c[t, 0], c[t, 1], frame[1, k[t], j[t]], frame[2, k[t], j[t]], K, dKc)
        dK = np.zeros((MCK.N_KERNEL, MCK.N_FRAME))
        dK[MCK.PATTERN] = dKc
        np.testing.assert_allclose(K, K_ref[t], rtol=0, atol=1e-15)
        np.testing.assert_allclose(dK, dK_ref[t], rtol=0, atol=1e-14 * np.abs(dK_ref[t]).max())
    off = np.ones((MCK.N_KERNEL, MCK.N_FRAME), bool)
    off[MCK.PATTERN] = False
    assert np.all(dK_ref[:, off] == 0.0)


def test_compiled_forces_equal_numpy(placed):
    """On random running states the compiled forces on every coordinate and the friction power equal the numpy path's
    to 1e-12 of the largest (round-off: the two sum in different orders), with contacts on both shafts."""
    _, model, x0 = placed
    for seed in (1, 2, 3):
        q, v = _qv(model, _running(model, x0, seed))
        Q, Q_ref = np.zeros(model.n2), np.zeros(model.n2)
        Pf, _ = model._mapped_forces(q, v, Q)
        Pf_ref, _ = model._mapped_forces(q, v, Q_ref, reference=True)
        _, k, _, _, _, _, (_, det) = model._mapped_set(q, v, details=True)
        assert set(k[det["delta"] > 0]) == {0, 1}
        assert np.abs(Q - Q_ref).max() <= 1e-12 * np.abs(Q_ref).max()
        assert Pf < 0 and abs(Pf - Pf_ref) <= 1e-12 * abs(Pf_ref)


def test_compiled_jacobian_equals_numpy(placed):
    """The compiled contacts' Jacobian entries and friction-power gradient equal the numpy path's (both central
    differences of the mapped contact with the same steps): the outputs agree to round-off ``~1e-16 |Y|``, which the
    difference quotient amplifies by ``1 / h`` (h = 1e-9 m), so the bound is ``1e3 eps max|Y| / h``, far below the
    entries (about 1e-9 of the largest)."""
    _, model, x0 = placed
    n2 = model.n2
    q, v = _qv(model, _running(model, x0, 4))
    (r, c, d), dD = model._mapped_contact_jacobian(q, v)
    (r0, c0, d0), dD0 = model._mapped_contact_jacobian(q, v, reference=True)
    J = sp.csr_matrix((d, (r, c)), shape=(n2, 2 * n2))
    J0 = sp.csr_matrix((d0, (r0, c0)), shape=(n2, 2 * n2))
    _, _, _, _, _, _, Y = model._mapped_set(q, v)
    bound = 1e3 * np.finfo(float).eps * np.abs(Y).max() / H_POS
    assert abs(J - J0).max() <= bound <= 1e-8 * abs(J0).max()
    assert np.abs(dD - dD0).max() <= 1e3 * np.finfo(float).eps * np.abs(Y[:, -1]).max() / H_POS


def test_structure_operators_equal_their_matrices(placed):
    """The structure's forces from the stacked ``[K, C, G_0, G_1]`` equal ``K q + (C + Omega_0 G_0 + Omega_1 G_1) v``;
    its acceleration rows of the Jacobian equal ``M_s^-1 [-K, -(C + Omega G)]`` (dense), placed."""
    _, model, x0 = placed
    s, nc, n2 = model.structure, model.family.size, model.n2
    q, v = _qv(model, _running(model, x0, 6))
    w = v[model._idx[1]]
    qs, vs = q[nc:], v[nc:]
    ref = s.K @ qs + s.damping_matrix(w) @ vs
    got = model._structure_operator @ np.concatenate([qs, vs, w[0] * vs, w[1] * vs])
    assert np.abs(got - ref).max() <= 1e-13 * np.abs(ref).max()
    A = model._structure_accelerations(w).toarray()
    Mi = np.linalg.inv(s.M.toarray())
    expect = np.zeros((n2, model.size))
    expect[nc:, nc:n2] = -Mi @ s.K.toarray()
    expect[nc:, n2 + nc:2 * n2] = -Mi @ s.damping_matrix(w).toarray()
    assert np.abs(A - expect).max() <= 1e-10 * np.abs(expect).max()
