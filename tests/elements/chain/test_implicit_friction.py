"""The grouped backward-Euler friction step (``implicit_friction.friction_step``) against closed forms: a block on a
moving belt (scalar slip) and a puck sliding on a plate (a slip vector in a plane), each body free, the belt and the
plate also as the solver's low-rank border; the dissipated work equals the kinetic energy removed."""
import numpy as np
import pytest
import scipy.optimize as so
import scipy.sparse as sp

from cvtfem.elements.chain import implicit_friction as IF
from cvtfem.elements.chain.implicit_friction import FrictionSet, friction_step
from cvtfem.elements.contact.friction import friction_coefficient, friction_gain, friction_potential, friction_slope
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


@pytest.mark.parametrize("law", sorted(IF.LAW_CODES))
def test_the_compiled_laws_are_the_numpy_laws(law):
    """The compiled twin :func:`IF._law` against ``friction_gain``, ``friction_slope``, ``friction_potential`` from
    0 through the series' switch and the kink at ``v0`` to far past it, to round-off."""
    f0, v0 = 0.3, 0.02
    v = v0 * np.concatenate([[0.0, 1e-6, 9.9e-5, 1e-4, 1.01e-4], np.linspace(0.01, 3.0, 301), [0.999999, 1.0, 50.0]])
    got = np.array([IF._law(IF.LAW_CODES[law], x) for x in v / v0])
    ref = np.stack([friction_gain(v, f0, v0, law) * v0 / f0, friction_slope(v, f0, v0, law) * v0 / f0,
                    friction_potential(v, f0, v0, law) / (f0 * v0)], axis=1)
    assert np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max()


@pytest.mark.parametrize("law", ["linear-saturated", "tanh", "arctan", "smoothed"])
def test_the_contact_blocks_are_square_roots_of_the_force_jacobian(law):
    """:func:`IF._contacts`: the forces ``c psi(|s|) s``, the potential ``sum c Phi(|s|)``, and ``E E`` equal to the
    central-difference Jacobian of the forces (tangent) or ``c psi I`` (secant), for scalar slips and slip vectors
    of 2 and 3 rows (one at rest)."""
    rng = np.random.default_rng(4)
    f0, v0 = 0.25, 0.01
    sizes = np.array([1, 2, 3, 1, 3, 2])
    first = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    boff = np.concatenate([[0], np.cumsum(sizes ** 2)[:-1]])
    c = rng.uniform(5, 50, sizes.size)
    s = rng.normal(scale=2 * v0, size=sizes.sum())
    s[first[4]:first[4] + 3] = 0.0
    lawt = (first, sizes, boff, c, np.full(sizes.size, f0), np.full(sizes.size, v0),
            np.full(sizes.size, IF.LAW_CODES[law]))
    r, E, m = np.empty(s.size), np.empty(boff[-1] + 4), s.size

    def forces(x):
        out = np.empty(m)
        IF._contacts(x, lawt, True, out, np.empty(E.size))
        return out

    pot = IF._contacts(s, lawt, True, r, E)
    speeds = np.array([np.linalg.norm(s[f:f + d]) for f, d in zip(first, sizes)])
    assert pot == pytest.approx(c @ friction_potential(speeds, f0, v0, law), rel=1e-14)
    assert np.abs(r - np.repeat(c * friction_gain(speeds, f0, v0, law), sizes) * s).max() <= 1e-14 * np.abs(r).max()
    for d in (1, 2, 3):                                                 # FrictionSet.forces, the numpy twin
        rows = np.repeat(sizes == d, sizes)
        fs = FrictionSet(sp.csr_matrix((rows.sum(), 1)), c[sizes == d], d, f0, v0, law)
        assert np.abs(fs.forces(s[rows]) - r[rows]).max() <= 1e-14 * np.abs(r).max()
    eps = 1e-7 * v0
    for k, (f, d, o) in enumerate(zip(first, sizes, boff)):
        Ek = E[o:o + d * d].reshape(d, d)
        assert np.abs(Ek - Ek.T).max() == 0.0
        if abs(speeds[k] - v0) > 10 * eps:                                  # off linear-saturated's kink
            J = np.empty((d, d))
            for b in range(d):
                e = np.zeros(m)
                e[f + b] = eps
                J[:, b] = (forces(s + e) - forces(s - e))[f:f + d] / (2 * eps)
            assert np.abs(Ek @ Ek - J).max() <= 1e-6 * c[k] * f0 / v0            # the slope's scale
    IF._contacts(s, lawt, False, r, E)
    for k, (f, d, o) in enumerate(zip(first, sizes, boff)):
        Ek = E[o:o + d * d].reshape(d, d)
        assert np.abs(Ek @ Ek - c[k] * friction_gain(speeds[k], f0, v0, law) * np.eye(d)).max() <= 1e-12 * c[k] / v0


def test_the_step_is_the_root_of_the_optimality_condition_and_keeps_its_plan():
    """Two sets, a sparse border: ``v`` solves ``M (v - v*) + h S^T r(Sv) = 0`` (scipy's root finder on the numpy
    laws, independent of the compiled path) to the tolerance; a second call on the same pattern reuses the pattern's
    plan, another pattern gets its own, and a call back on the first gives the first result to round-off."""
    rng = np.random.default_rng(8)
    n, h = 14, 1e-3
    M, Mi = masses(rng.uniform(0.5, 2.0, n))
    A = sp.csr_matrix(rng.normal(size=(4, n)) * (rng.uniform(size=(4, n)) < 0.4))
    G = sp.csr_matrix(rng.normal(size=(6, n)) * (rng.uniform(size=(6, n)) < 0.5))
    sets = [FrictionSet(A, rng.uniform(1, 10, 4), 1, 0.1, 1e-3, "arctan"),
            FrictionSet(G, rng.uniform(1, 10, 3), 2, 0.2, 1e-3, "linear-saturated")]
    S = sp.vstack([A, G], format="csr")
    v = rng.normal(size=n)

    def residual(w, v_star=v):
        s = S @ w
        speed = np.concatenate([np.abs(s[:4]), np.linalg.norm(s[4:].reshape(3, 2), axis=1)])
        psi = np.concatenate([sets[0].c * friction_gain(speed[:4], 0.1, 1e-3, "arctan"),
                              np.repeat(sets[1].c * friction_gain(speed[4:], 0.2, 1e-3, "linear-saturated"), 2)])
        return M @ (w - v_star) + h * (S.T @ (psi * s))

    v1, W, _ = friction_step(M, Mi, sets, v, h, border=[n - 3, n - 1], tol=1e-12)
    plan = IF._PLAN["last"]
    ref = so.root(residual, v1 + 1e-6, tol=1e-15).x
    assert np.abs(v1 - ref).max() <= 1e-10 * np.abs(v).max()
    assert W == pytest.approx(0.5 * (v - v1) @ (M @ (v + v1)), rel=1e-12)
    again = friction_step(M, Mi, sets, v * 1.1, h, border=[n - 3, n - 1], tol=1e-12)
    assert IF._PLAN["last"] is plan and np.abs(residual(again[0], 1.1 * v)).max() <= 1e-10
    other = [sets[0], FrictionSet(G[:4], sets[1].c[:2], 2, 0.2, 1e-3, "linear-saturated")]
    friction_step(M, Mi, other, v, h, border=[n - 3, n - 1], tol=1e-12)
    assert IF._PLAN["last"] is not plan
    back = friction_step(M, Mi, sets, v, h, border=[n - 3, n - 1], tol=1e-12)
    assert np.abs(back[0] - v1).max() <= 1e-14 * np.abs(v).max()


def test_a_small_newton_step_is_checked_by_a_chord_step_not_a_new_factorisation():
    """All slips in the linear part of the piecewise-linear law: the function is quadratic, one Newton step is exact.
    That step (between the tolerance and :data:`CHORD` times it) is checked by a chord step on the same LDL^T, which is
    zero: one factorisation in all (a second Newton step would need two), and ``v`` the linear solve's."""
    rng = np.random.default_rng(3)
    n, h, v0, f0 = 30, 1e-2, 1e-3, 0.2
    M, Mi = masses(rng.uniform(0.5, 2.0, n))
    G = sp.csr_matrix(rng.normal(size=(20, n)) * (rng.uniform(size=(20, n)) < 0.3))
    c = rng.uniform(1, 10, 10)
    v = rng.normal(size=n)
    v *= 0.5 * v0 / np.linalg.norm((G @ v).reshape(-1, 2), axis=1).max()          # every slip below v0
    v1, _, lus = friction_step(M, Mi, [FrictionSet(G, c, 2, f0, v0, "linear-saturated")], v, h, tol=0.1)
    exact = np.linalg.solve((M + h * G.T @ sp.diags(np.repeat(c * f0 / v0, 2)) @ G).toarray(), M @ v)
    assert np.linalg.norm((G @ exact).reshape(-1, 2), axis=1).max() < v0
    assert np.abs(G @ (v - exact)).max() > 0.1 * v0 * 1.0001                   # the Newton step is not small
    assert lus == 1
    assert np.abs(v1 - exact).max() <= 1e-12 * np.abs(v).max()


def test_no_contact_in_touch_leaves_the_velocities():
    M, Mi = masses([1.0, 2.0])
    fs = FrictionSet(sp.csr_matrix((0, 2)), np.zeros(0), 2, F0, V0, "tanh")
    v, W, lus = friction_step(M, Mi, [fs], np.array([0.3, -0.1]), 1e-3, border=[1])
    assert np.array_equal(v, [0.3, -0.1]) and W == 0.0 and lus == 0


def test_a_law_without_a_potential_is_refused():
    with pytest.raises(InputError, match="friction_law"):
        FrictionSet(sp.csr_matrix([[1.0]]), np.ones(1), 1, F0, V0, "smooth")
