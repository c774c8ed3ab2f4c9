"""The compiled H1 contact path of the chain transmissions (sheave_contact_kernel: gather, broad phase, contact,
scatter) against the numpy path (broad phase, contact map, SheaveContact.local, bincount), for the mirrored pin
ends of S2, the single pin ends of A1 and the half ends of A5, on random states near the sheaves."""
from functools import partialmethod

import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import ChainCVT, from_scene
from cvtfem.scene.loader import load_scene

pytest.importorskip("numba")

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])
MODELS = ("chain-S2", "chain-A1", "chain-A5")


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module", params=MODELS)
def model(request, scene):
    return from_scene(scene, reference_geometry(), F_APPL, model=request.param)


def placed(model, w1):
    """The chain placed on the sheaves at the wedge estimate (A5: its rolling placement), shafts turning."""
    if hasattr(model, "placed_state"):
        return model.placed_state(RATIO, w1)
    pl, u3, z = model.wedge_guess(RATIO, float(model.F_appl[1]))
    nc, iphi, iz, _ = model._idx
    x = np.zeros(model.size)
    x[:nc], x[iz] = model._placed(pl, u3), z
    x[model.n2 + iphi] = w1 * pl.r[0] / pl.r
    return x


@pytest.fixture(scope="module")
def states(model, scene):
    """Three states off balance: chain offsets of 1 um (contacts on and off near the arcs' ends), velocities of
    0.5 m/s on every chain coordinate and on the sheaves; ``(q, v)`` each."""
    x0 = placed(model, scene.cvt.regime.input_speed)
    nc, n2 = model.family.size, model.n2
    rng = np.random.default_rng(7)
    out = []
    for _ in range(3):
        x = x0.copy()
        x[:nc] += rng.normal(0.0, 1e-6, nc)
        x[n2:n2 + nc] += rng.normal(0.0, 0.5, nc)
        x[n2 + nc:2 * n2] += rng.normal(0.0, 0.5, n2 - nc)
        out.append((x[:n2], x[n2:2 * n2]))
    return out


def test_the_h1_models_take_the_compiled_path(model):
    assert model._compiled_contact is not None
    cols, coef, shafts, rows, w = model._pair_table
    assert cols.shape[0] == 2 * model.n_ends and rows.shape[1] == 5


def test_compiled_contact_forces_equal_the_numpy_path(model, states):
    """Generalized forces (relative to the largest), friction power and mean slip speed per shaft to 1e-12, on
    states with candidates on and off contact."""
    for q, v in states:
        Qc, Qr = np.zeros(model.n2), np.zeros(model.n2)
        Pc, sc = model._contact_forces(q, v, Qc, slip=True)
        Pr, sr = model._contact_forces(q, v, Qr, slip=True, reference=True)
        _, _, _, (_, det) = model._contacts(q, v, details=True)
        assert (det["delta"] > 0).sum() > 20 and (det["delta"] <= 0).sum() > 0
        assert np.abs(Qc - Qr).max() <= 1e-12 * np.abs(Qr).max()
        assert Pr < 0 and Pc == pytest.approx(Pr, rel=1e-12)
        np.testing.assert_allclose(sc, sr, rtol=1e-12)


def test_compiled_contact_jacobian_equals_the_numpy_path(model, states):
    """``dQ/dy`` entries of the contacts and the friction power's gradient: the same central differences of the
    local kernel (steps of SheaveContact.local_jacobian), so equal but for the round-off the steps magnify
    (found 3e-14 of the largest entry)."""
    n2 = model.n2
    for q, v in states[:2]:
        (rc, cc, dc), gc = model._contact_jacobian(q, v)
        (rr, cr, dr), gr = model._contact_jacobian(q, v, reference=True)
        A = sp.csr_matrix((dc, (rc, cc)), shape=(n2, 2 * n2))
        B = sp.csr_matrix((dr, (rr, cr)), shape=(n2, 2 * n2))
        assert abs(A - B).max() <= 1e-11 * abs(B).max()
        assert np.abs(gc - gr).max() <= 1e-11 * np.abs(gr).max()


def test_model_rhs_compiled_equals_numpy(model, states, monkeypatch):
    """The whole right-hand side with the compiled contacts against the numpy contacts (the chain pass, loops
    and work rates shared), to 1e-12 of each block's largest entry."""
    q, v = states[0]
    x = np.concatenate([q, v, model.control.initial_state(*v[model._idx[1]]), np.zeros(4)])
    fast = model.rhs(0.0, x)
    monkeypatch.setattr(type(model), "_contact_forces", partialmethod(ChainCVT._contact_forces, reference=True))
    slow = model.rhs(0.0, x)
    n2 = model.n2
    for block in (slice(n2, 2 * n2), slice(2 * n2, None)):
        assert np.abs(fast[block] - slow[block]).max() <= 1e-12 * np.abs(slow[block]).max()
