"""Static stability of A5's rolling joint (the contact proposal of chain-models-2 section 5.3): under tension the
frictionless rolling faces of the two halves of a pin give the chain negative static stiffness, which is why the
quasi-static start of A5 on the sheaves stalls (docs/chain.md, "A5 on the sheaves", quasi-static start)."""
import numpy as np
import pytest

from tests.elements.chain.test_halves import chain, straight


def _tensioned_segment(T, n=4, **over):
    """Balance of an open straight segment pulled by ``-+T`` at its end pins (a quarter at each end of each half),
    as ``test_open_segment_under_end_tension_carries_it_in_every_link``; returns the chain, the balance and the
    static stiffness ``K = -dQ/dq`` there (dense)."""
    ch = chain(n=n, closed=False, stopper_play=0.0, **over)
    q = straight(ch)
    pins, half, xi = np.repeat([0, n - 1], 4), np.tile([0, 0, 1, 1], 2), np.tile([-1.0, 1.0], 4)
    F = np.zeros((8, 3))
    F[:4, 0], F[4:, 0] = -T / 4, T / 4
    Qext = ch.point_loads(pins, half, xi, F)
    v = np.zeros(ch.n2)
    for _ in range(40):
        R = ch.forces(q, v) + Qext
        if np.abs(R).max() < 1e-9 * T:
            break
        K, _ = ch.jacobian(q, v, damping=False)
        q = q + np.linalg.lstsq(-K.toarray(), R, rcond=1e-12)[0]
    assert np.abs(ch.forces(q, v) + Qext).max() < 1e-9 * T
    return ch, q, -ch.jacobian(q, v, damping=False)[0].toarray()


def _slide(ch, pin):
    """Unit vector of the relative in-plane slide of the two halves of ``pin`` across the chain (``x2``): half ``-``
    by ``+1``, half ``+`` by ``-1``."""
    e = np.zeros(ch.n2)
    e[ch.dof_index[pin, [1, 11]]] = [1.0, -1.0]
    return e / np.linalg.norm(e)


@pytest.fixture(scope="module")
def segments():
    return {T: _tensioned_segment(T) for T in (1000.0, 2000.0)}


def test_tension_gives_the_relative_slide_of_the_halves_negative_stiffness(segments):
    """At the balance the stiffness is symmetric (conservative forces) and has negative eigenvalues; the most
    negative one's mode is the relative slide of the two halves of an inner pin across the chain (both halves'
    ``u_0`` carry > 90 % of it, in opposite directions).  The stiffness of that slide is geometric: it is
    proportional to the tension (doubling ``T`` doubles it to 3 %) and its quotient ``e.K.e`` is negative."""
    lowest = {}
    for T, (ch, q, K) in segments.items():
        assert np.abs(K - K.T).max() < 1e-8 * np.abs(K).max()
        w, V = np.linalg.eigh(K)
        assert w[0] < 0
        A = V[:, 0][ch.dof_index]                                 # (pins, 21)
        pin = int(np.argmax((A ** 2).sum(1)))
        assert 0 < pin < ch.n_pins - 1
        assert (A[:, [0, 1, 10, 11]] ** 2).sum() > 0.9
        assert A[pin, 1] * A[pin, 11] < 0
        e = _slide(ch, pin)
        assert e @ K @ e < 0
        lowest[T] = w[0]
    assert lowest[2000.0] / lowest[1000.0] == pytest.approx(2.0, rel=0.03)


def test_a_rolling_tie_makes_those_directions_stiff(segments):
    """With the conservative no-slip tie on the rolling contacts (``roll_tie``, the static friction that holds the
    halves rolling), the relative slides that had negative stiffness without it (one per pin: the negative modes
    with more than half their weight on the halves' ``u_0``) have positive stiffness (their Rayleigh quotients), at
    the same tension.  (The other five negative modes are yaws ``u_1`` of the halves; the tie stiffens four of them,
    the fifth, -13 N/m, stays at -11 N/m.)"""
    ch, _, K = segments[1000.0]
    w, V = np.linalg.eigh(K)
    unstable = V[:, w < -1e-9 * np.abs(w).max()]
    weight = (unstable[ch.dof_index[:, [0, 1, 10, 11]].ravel()] ** 2).sum(0)
    slides = unstable[:, weight > 0.5]
    assert slides.shape[1] == ch.n_pins
    _, _, K_tied = _tensioned_segment(1000.0, roll_tie=1e9)
    assert np.all(np.einsum("ik,ij,jk->k", slides, K_tied, slides) > 0)
