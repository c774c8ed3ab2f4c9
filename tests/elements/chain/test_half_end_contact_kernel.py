"""The compiled H2 contact path of variant (e) (half_end_contact_kernel: broad phase, gather, the refined kernel at
every half end, scatter, and the contacts' Jacobian entries) against ChainCVT's numpy path (broad phase, contact
map, HalfEndContact.local, bincount), on random states of the A5 chain near the sheaves."""
from functools import partialmethod

import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_halves_refined_cvt import ChainHalvesRefinedCVT
from cvtfem.scene.loader import load_scene
from tests.elements.chain.test_sheave_contact_kernel import F_APPL, placed

pytest.importorskip("numba")


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module")
def model(scene):
    return from_scene(scene, reference_geometry(), F_APPL, model="chain-A5", contact="hertz-refined")


@pytest.fixture(scope="module")
def states(model, scene):
    """Three states off balance: chain offsets of 1 um (contacts on and off near the arcs' ends), velocities of
    0.5 m/s on every chain coordinate and on the sheaves; ``(q, v)`` each."""
    x0 = placed(model, scene.cvt.regime.input_speed)
    nc, n2 = model.family.size, model.n2
    rng = np.random.default_rng(11)
    out = []
    for _ in range(3):
        x = x0.copy()
        x[:nc] += rng.normal(0.0, 1e-6, nc)
        x[n2:n2 + nc] += rng.normal(0.0, 0.5, nc)
        x[n2 + nc:2 * n2] += rng.normal(0.0, 0.5, n2 - nc)
        out.append((x[:n2], x[n2:2 * n2]))
    return out


def test_variant_e_takes_the_compiled_path(model):
    assert isinstance(model, ChainHalvesRefinedCVT) and model._compiled_contact is not None
    cols, coef, shafts, rows, w = model._pair_table
    assert cols.shape[0] == 2 * model.n_ends and cols.shape[1] == 17 and rows.shape[1] == 9


def test_compiled_contact_forces_equal_the_numpy_path(model, states):
    """Generalized forces (relative to the largest) and friction power to 1e-12, with candidates on and off
    contact."""
    for q, v in states:
        Qc, Qr = np.zeros(model.n2), np.zeros(model.n2)
        Pc, _ = model._contact_forces(q, v, Qc)
        Pr, _ = model._contact_forces(q, v, Qr, reference=True)
        _, _, _, (_, det) = model._contacts(q, v, details=True)
        assert (det["delta"] > 0).sum() > 20 and (det["delta"] <= 0).sum() > 0
        assert np.abs(Qc - Qr).max() <= 1e-12 * np.abs(Qr).max()
        assert Pr < 0 and Pc == pytest.approx(Pr, rel=1e-12)


def test_compiled_contact_jacobian_equals_the_numpy_path(model, states):
    """``dQ/dy`` entries of the contacts and the friction power's gradient: the same central differences of the
    local contact (steps of HalfEndContact.local_jacobian), so equal but for the round-off the steps magnify.  The
    compiled path differentiates the candidates in contact only (those with ``delta > 0``), the numpy path all."""
    n2 = model.n2
    K, table = model._contact_kernel, model._pair_table
    for q, v in states[:2]:
        pair, _ = K.local_jacobians(np.concatenate([q, v, model._constants]), *table, *model._compiled_contact,
                                    K.STEPS)
        _, _, _, (_, det) = model._contacts(q, v, details=True)
        assert len(pair) == (det["delta"] > 0).sum() < len(det["delta"])
        (rc, cc, dc), gc = model._contact_jacobian(q, v)
        (rr, cr, dr), gr = model._contact_jacobian(q, v, reference=True)
        A = sp.csr_matrix((dc, (rc, cc)), shape=(n2, 2 * n2))
        B = sp.csr_matrix((dr, (rr, cr)), shape=(n2, 2 * n2))
        assert abs(A - B).max() <= 1e-11 * abs(B).max()
        assert np.abs(gc - gr).max() <= 1e-11 * np.abs(gr).max()


def test_model_rhs_compiled_equals_numpy(model, states, monkeypatch):
    """The whole right-hand side with the compiled contacts against the numpy contacts, to 1e-12 of each block's
    largest entry."""
    q, v = states[0]
    x = np.concatenate([q, v, model.control.initial_state(*v[model._idx[1]]), np.zeros(4)])
    fast = model.rhs(0.0, x)
    monkeypatch.setattr(type(model), "_contact_forces",
                        partialmethod(ChainHalvesRefinedCVT._contact_forces, reference=True))
    slow = model.rhs(0.0, x)
    n2 = model.n2
    for block in (slice(n2, 2 * n2), slice(2 * n2, None)):
        assert np.abs(fast[block] - slow[block]).max() <= 1e-12 * np.abs(slow[block]).max()
