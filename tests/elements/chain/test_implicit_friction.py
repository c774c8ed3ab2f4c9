"""The grouped backward-Euler friction step (``implicit_friction.friction_step``) against closed forms: a block on a
moving belt (scalar slip) and a puck sliding on a plate (a slip vector in a plane), each body free, the belt and the
plate also as the solver's low-rank border; the dissipated work equals the kinetic energy removed."""
import numpy as np
import pytest
import scipy.optimize as so
import scipy.sparse as sp

from cvtfem.elements.chain.implicit_friction import FrictionSet, friction_step
from cvtfem.elements.contact.friction import friction_coefficient
from cvtfem.errors import InputError

F0, V0, N = 0.3, 0.01, 50.0                       # -, m/s, N


def masses(m):
    m = np.asarray(m, float)
    return sp.diags(m).tocsr(), sp.diags(1 / m).tocsr()


@pytest.mark.parametrize("border", [None, [1]])
@pytest.mark.parametrize("law", ["linear-saturated", "tanh", "arctan", "smoothed"])
@pytest.mark.parametrize("h", [1e-6, 1e-4, 1e-2])
def test_block_on_a_belt(law, h, border):
    """Block ``m`` at 1 m/s on a belt of mass ``M`` at 0.3 m/s, slip ``s = v - u``: backward Euler gives
    ``s1 = s0 - h (1/m + 1/M) N f(s1)`` (a scalar equation), the momentum is kept."""
    m, Mb, v = 2.0, 5.0, np.array([1.0, 0.3])
    M, Mi = masses([m, Mb])
    fs = FrictionSet(sp.csr_matrix([[1.0, -1.0]]), np.array([N]), 1, F0, V0, law)
    v1, W, lus = friction_step(M, Mi, [fs], v, h, border=border, tol=1e-10)
    s0 = v[0] - v[1]
    s1 = so.brentq(lambda s: s - s0 + h * (1 / m + 1 / Mb) * N * friction_coefficient(s, F0, V0, law), 0.0, s0,
                   xtol=1e-15)
    assert v1[0] - v1[1] == pytest.approx(s1, rel=1e-9, abs=1e-12)
    assert m * v1[0] + Mb * v1[1] == pytest.approx(m * v[0] + Mb * v[1], rel=1e-13)
    dT = 0.5 * (v @ (M @ v) - v1 @ (M @ v1))
    assert W == pytest.approx(dT, rel=1e-12) and W > 0 and lus < 60


@pytest.mark.parametrize("border", [None, [3, 4, 5]])
@pytest.mark.parametrize("h", [1e-5, 1e-3, 1e-1])
def test_puck_on_a_plate(h, border):
    """A puck (velocities 0..2) on a plate (3..5) with the normal ``n``: the slip is the relative velocity projected
    on the plane, ``s = E_t (v_p - v_q)`` (3 rows).  Backward Euler keeps its direction: ``s1 = a s0`` with
    ``|s1| = |s0| - h (1/m + 1/M) N f(|s1|)``; the normal relative velocity is untouched, the momentum kept."""
    n = np.array([0.0, 0.6, 0.8])
    Et = np.eye(3) - np.outer(n, n)
    m, Mq = 1.5, 4.0
    M, Mi = masses([m] * 3 + [Mq] * 3)
    S = sp.csr_matrix(np.hstack([Et, -Et]))
    v = np.array([0.4, -0.2, 0.3, 0.0, 0.1, -0.1])
    fs = FrictionSet(S, np.array([N]), 3, F0, V0, "tanh")
    v1, W, lus = friction_step(M, Mi, [fs], v, h, border=border, tol=1e-10)
    s0, s1 = S @ v, S @ v1
    a0 = np.linalg.norm(s0)
    a1 = so.brentq(lambda a: a - a0 + h * (1 / m + 1 / Mq) * N * friction_coefficient(a, F0, V0, "tanh"), 0.0, a0,
                   xtol=1e-15)
    assert np.abs(s1 - a1 / a0 * s0).max() <= 1e-9 * a0 + 1e-13
    rel = lambda y: y[:3] - y[3:]  # noqa: E731
    assert n @ rel(v1) == pytest.approx(n @ rel(v), abs=1e-14)
    assert np.abs(m * v1[:3] + Mq * v1[3:] - m * v[:3] - Mq * v[3:]).max() <= 1e-13
    assert W == pytest.approx(0.5 * (v @ (M @ v) - v1 @ (M @ v1)), rel=1e-12) and W > 0 and lus < 60


def test_two_sets_with_a_shared_border_equal_the_dense_solve():
    """Scalar and vector slips together, the border carrying both: the same ``v`` as the Newton step on the full
    velocity matrix (no Woodbury), to the tolerance."""
    rng = np.random.default_rng(3)
    n = 12
    M, Mi = masses(rng.uniform(0.5, 2.0, n))
    A = sp.csr_matrix(rng.normal(size=(4, n)) * (rng.uniform(size=(4, n)) < 0.4))
    G = sp.csr_matrix(rng.normal(size=(6, n)) * (rng.uniform(size=(6, n)) < 0.5))
    sets = [FrictionSet(A, rng.uniform(1, 10, 4), 1, 0.1, 1e-3, "tanh"),
            FrictionSet(G, rng.uniform(1, 10, 2), 3, 0.2, 1e-3, "linear-saturated")]
    v = rng.normal(size=n)
    a = friction_step(M, Mi, sets, v, 1e-3, tol=1e-12)
    b = friction_step(M, Mi, sets, v, 1e-3, border=[n - 2, n - 1], tol=1e-12)
    assert np.abs(a[0] - b[0]).max() <= 1e-12 * np.abs(v).max()
    assert a[1] == pytest.approx(b[1], rel=1e-12)


def test_a_law_without_a_potential_is_refused():
    with pytest.raises(InputError, match="friction_law"):
        FrictionSet(sp.csr_matrix([[1.0]]), np.ones(1), 1, F0, V0, "smooth")
