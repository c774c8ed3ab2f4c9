"""The one-pass right-hand side and the in-place Jacobian of the A5 chain on rigid shafts (H1 and H2) against
ChainCVT's general path (``evaluate``, ``ChainCVT.jac``), their twin (issue 13's benchmark)."""
from dataclasses import fields

import numpy as np
import pytest

from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import ChainCVT, from_scene
from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT
from cvtfem.scene.loader import load_scene

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])


@pytest.fixture(scope="module", params=["hertz", "hertz-refined"])
def model(request):
    scene = load_scene("band-6+2n")
    m = from_scene(scene, reference_geometry(), F_APPL, model="chain-A5", contact=request.param)
    return m, m.placed_state(RATIO, scene.cvt.regime.input_speed)


def _states(model, x0, count=3):
    """Running states off balance: chain offsets 0.2 um, velocities 0.05 m/s, shaft and sheave rates, loop states."""
    rng = np.random.default_rng(7)
    nc, n2 = model.family.size, model.n2
    for _ in range(count):
        x = x0.copy()
        x[:nc] += rng.normal(0.0, 2e-7, nc)
        x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
        x[n2 + nc:2 * n2] += rng.normal(0.0, 0.05, n2 - nc)
        x[2 * n2:] += rng.normal(0.0, 1e-3, x.size - 2 * n2)
        yield x


def test_rhs_equals_evaluate_and_returns_fresh_arrays(model):
    m, x0 = model
    assert m._one_pass
    kept = []
    for k, x in enumerate(_states(m, x0)):
        f = m.rhs(0.1 * k, x)
        ref = m.evaluate(0.1 * k, x, slip=False)[0]
        assert np.all(np.isfinite(f))
        assert np.abs(f - ref).max() <= 1e-12 * np.abs(ref).max()
        assert np.all(np.abs(f - ref) <= 1e-12 * np.abs(ref) + 1e-300), "not equal entry by entry"
        kept.append((f, f.copy()))
    assert all(np.array_equal(a, b) for a, b in kept)      # later calls wrote no returned array


def test_jac_equals_the_general_assembly_on_the_fixed_pattern(model):
    m, x0 = model
    assert m._jac_plan is not None
    pattern = m.jac_sparsity
    for x in _states(m, x0, 2):
        J = m.jac(0.0, x)
        ref = ChainCVT.jac(m, 0.0, x)
        assert J.shape == ref.shape and J.has_sorted_indices and np.all(J.data != 0)
        assert (abs(J) - abs(J).multiply(pattern)).count_nonzero() == 0
        outside = abs(ref) - abs(ref).multiply(pattern)
        assert outside.count_nonzero() == 0
        assert abs(J - ref).max() <= 1e-12 * abs(ref).max()
        assert J.indices is not m._jac_plan["P"].indices and J.indptr is not m._jac_plan["P"].indptr


def test_a_subclass_with_its_own_evaluate_keeps_the_general_path(model):
    m, x0 = model

    class Traced(type(m)):
        calls = 0

        def evaluate(self, t, x, slip=True):
            Traced.calls += 1
            return super().evaluate(t, x, slip)

    sub = Traced(*(getattr(m, f.name) for f in fields(m)))
    assert isinstance(sub, ChainHalvesCVT) and not sub._one_pass and sub._jac_plan is None
    x = next(_states(m, x0, 1))
    assert np.array_equal(sub.rhs(0.0, x), m.rhs(0.0, x)) and Traced.calls == 1
