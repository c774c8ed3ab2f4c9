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


def test_taut_shortcut_agrees_with_the_full_state_selection():
    """``_taut`` (the taut state proven from a bound of the other nine margins, which ``_plate_law`` takes before the
    full ten-state selection ``_state``) never claims state 1 where ``_state`` finds another, also at the boundary of
    state 1 (strains scaled onto it, where the margins tie to round-off); and it decides most taut plates of a
    stretched chain (else it would save nothing)."""
    c, c1, c2, h = law()
    rng = np.random.default_rng(23)
    n = 20000
    psi = rng.normal(size=(n, 2)) * 10.0 ** rng.uniform(-7, -2, (n, 1))
    Delta = rng.normal(size=n) * 10.0 ** rng.uniform(-9, -5, n)
    A, m = np.zeros((3, 3)), np.zeros(10)
    # onto the boundary of state 1: the stretch at which M0 = max(|M01|, |M02|) (margin 0 ties margin 1..4)
    M01, M02 = c1 * psi[:, 0] + c2 * psi[:, 1], c2 * psi[:, 0] + c1 * psi[:, 1]
    edge = 2.0 / (h * c) * np.maximum(np.abs(M01), np.abs(M02)) * (1 + rng.choice([-1, 1], n) * 1e-15)
    taut_total, decided = 0, 0
    for case in range(2 * n):
        p1, p2 = psi[case % n]
        D = Delta[case] if case < n else edge[case - n]
        st = ker._state(p1, p2, D, c, c1, c2, h, A, m)[0]
        quick = ker._taut(p1, p2, D, c, c1, c2, h)
        assert not quick or st == 1, (p1, p2, D, st)
        taut_total += st == 1
        decided += quick
    assert taut_total > 1000 and decided > 0.5 * taut_total
    stretched = np.abs(Delta) + 1e-6                               # a chain under tension: strains small against it
    quick = [ker._taut(p1 * 1e-3, p2 * 1e-3, D, c, c1, c2, h) for (p1, p2), D in zip(psi[:2000], stretched)]
    assert np.mean(quick) > 0.99
