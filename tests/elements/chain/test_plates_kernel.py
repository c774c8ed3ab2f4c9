"""Compiled per-plate forces against their numpy twin (plate_strains -> plate_state -> plate_forces)."""
import numpy as np
import pytest

from cvtfem.elements.chain import plates as P
from cvtfem.elements.chain import plates_kernel as ker
from tests.elements.chain.test_plates import H_PLATE, L_PIN, L_PITCH, law, random_plates, strains

pytest.importorskip("numba")


@pytest.mark.parametrize("model", [ker.A4, ker.A3_DROP, ker.A3_KEEP])
def test_kernel_equals_the_numpy_twin(model):
    n = 5000
    q, xi = random_plates(n, np.random.default_rng(17))
    qdot = np.random.default_rng(2).normal(size=q.shape) * 1e-1
    c, c1, c2, h = law()
    be, bs = 3e-6, 7e-6
    eps, J = strains(q, xi)
    if model == ker.A4:
        st = P.plate_state(eps, c, c1, c2, h)
        assert np.all(np.bincount(st.state, minlength=11)[1:] > 0)
    else:
        st = P.clamped_plate_state(eps, c, c1, c2, drop_compressed=model == ker.A3_DROP)
    Q_np = P.plate_forces(st, J, qdot, c, c1, c2, be, bs)
    full = [np.full(n, v) for v in (L_PIN, L_PITCH, c, c1, c2, H_PLATE)]
    Q, T, M, state = np.zeros((n, 20)), np.zeros(n), np.zeros((n, 2)), np.zeros(n, np.int64)
    ker.plate_forces_kernel(q, qdot, xi, *full, be, bs, model, Q, T, M, state)
    np.testing.assert_array_equal(state, st.state)
    # Round-off scale of each plate, N m: its strains carry absolute round-off ~eps (psi = tau . t with
    # |t|, |tau| ~ 1) and ~eps L (Delta = |V| - L), which the moment terms carry through the cancellations
    # of a corner state (Delta~ = Delta + h/2 (|delta_1| + |delta_2|), zeta = psi - delta) and J into Q.
    c0 = H_PLATE ** 2 * c / 4
    S = (c1 + c0) * (np.abs(eps[:, :2]).sum(1) + 1) + H_PLATE / 2 * c * (np.abs(eps[:, 2]) + L_PITCH)
    fscale = S * (np.abs(J[:, :2]).max((1, 2)) + 2 / H_PLATE * np.abs(J[:, 2]).max(1))
    assert np.all(np.abs(Q - Q_np) <= 1e-13 * fscale[:, None])
    assert np.all(np.abs(T - st.tension) <= 1e-13 * 2 / H_PLATE * S)
    assert np.all(np.abs(M - st.moment) <= 1e-13 * S[:, None])
