"""Sparse assembly of element families against a dense scatter reference; random-geometry properties."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cvtfem.assembly import assemble, dof_map_nodes
from cvtfem.elements.beam import BeamFamily, BeamOptions


def beam(L, Do, ratio, n=3, **opts):
    return BeamFamily(nodes=np.stack([np.arange(n), np.arange(1, n + 1)], 1), L=np.asarray(L, float),
                      Do=np.asarray(Do, float), Di=np.asarray(Do, float) * ratio, E=np.full(n, 2e11),
                      G=np.full(n, 8e10), rho=np.full(n, 7800.0), options=BeamOptions(**opts))


def test_sparse_assembly_equals_dense_scatter():
    b = beam([0.1, 0.3, 0.2], [0.05, 0.08, 0.04], 0.3)
    N = 6 * 4
    K = b.stiffness()
    ref = np.zeros((N, N))
    for e in range(3):
        ref[np.ix_(b.dofs[e], b.dofs[e])] += K[e]
    got = assemble(N, [(K, b.dofs)])
    np.testing.assert_array_equal(got.toarray(), ref)
    assert (b.dofs == dof_map_nodes(b.nodes, 6)).all()


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(0.05, 0.5), min_size=3, max_size=3), st.lists(st.floats(0.02, 0.1), min_size=3,
                                                                         max_size=3), st.floats(0.0, 0.9))
def test_free_stepped_shaft_properties(L, Do, ratio):
    """Any stepped hollow shaft: K symmetric PSD with 6 rigid modes, M SPD with the exact mass, G skew."""
    b = beam(L, Do, ratio)
    N = 24
    K = assemble(N, [(b.stiffness(), b.dofs)]).toarray()
    M = assemble(N, [(b.mass(), b.dofs)]).toarray()
    G = assemble(N, [(b.gyroscopic(), b.dofs)]).toarray()
    scale = np.abs(K).max()
    assert np.allclose(K, K.T, atol=1e-12 * scale)
    assert np.allclose(G, -G.T, atol=1e-12 * np.abs(G).max())
    ev = np.linalg.eigvalsh(K / scale)
    assert np.sum(ev < 1e-10) == 6 and ev.min() > -1e-10
    assert np.linalg.eigvalsh(M).min() > 0
    u1 = np.zeros(N)
    u1[0::6] = 1.0
    np.testing.assert_allclose(u1 @ M @ u1, np.sum(7800.0 * b.area * b.L), rtol=1e-12)
    np.testing.assert_allclose(K @ u1, 0.0, atol=1e-9 * scale)        # rigid translation: no force
