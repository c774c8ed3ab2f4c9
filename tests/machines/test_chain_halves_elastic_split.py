"""All friction of variant (e) split off on elastic shafts (``ElasticChainHalvesRefinedCVT.stiff_split``): the slip
map through the sheaves' frames reproduces the mapped H2 kernel's friction forces (on chain and structure) and power,
``f_E + f_I = f`` to round-off for both variants of the split, the friction solve is backward Euler on all velocities
with the structure's consistent mass and books the kinetic energy it removes, the friction rate at frozen positions
and its stiffness bound, and ``imex-rk4`` and ``multirate-rk4`` run it."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from tests.machines.chain_checks import assert_friction_solve_all_is_backward_euler, friction_rate
from tests.machines.test_chain_halves_elastic import _rigid, _running


@pytest.fixture(scope="module")
def model():
    """Variant (e) (uniform chain, stationary regime, tanh law) placed on its undeformed elastic shafts."""
    _, m = _rigid("e")
    w1, _, i = m.regime.targets(0.0)
    return m.placed(i, w1)


def _states(m, x0):
    return [_running(m, x0, seed) for seed in (3, 4)]


def test_slip_map_gives_the_mapped_kernels_friction(model):
    """``-G^T (N psi(|Gv|) Gv)`` = the mapped contact forces less those at ``f0 = 0`` on every velocity (chain and
    structure: the sheaves' translation, tilt and spin feel the friction), and ``N psi |s|^2`` is the friction power."""
    m, x0 = model
    free = m._frictionless["all"]
    n2 = m.n2
    for x in _states(m, x0):
        q, v = x[:n2], x[n2:2 * n2]
        Q, Q0 = np.zeros(n2), np.zeros(n2)
        Pf = m._compiled_mapped_forces(q, v, Q)
        free._compiled_mapped_forces(q, v, Q0)
        G, N = m.sheave_slips(x)
        fs = m.friction_sets(x)[1]
        s = G @ v
        r = fs.forces(s)
        nc = m.family.size
        assert len(N) > 50 and np.all(N > 0) and G.shape == (2 * len(N), n2)
        assert np.abs(G[:, nc:]).max() > 0.0
        assert np.abs(-(G.T @ r) - (Q - Q0)).max() <= 1e-12 * np.abs(Q).max()
        assert -r @ s == pytest.approx(Pf, rel=1e-12)


@pytest.mark.parametrize("variant", [None, "all"])
def test_explicit_plus_friction_equals_the_rhs(model, variant):
    m, x0 = model
    split = m.stiff_split
    explicit = split[0] if variant is None else split[3][variant][0]
    for x in _states(m, x0):
        f, fE, fI = m.rhs(0.0, x), explicit(0.0, x), friction_rate(m, x, halves_only=variant is None)
        assert np.abs(fI).max() > 1e-3 * np.abs(f).max()
        assert np.abs(f - fE - fI).max() <= 1e-12 * np.abs(f).max()


def test_friction_solve_all_is_backward_euler_and_books_the_kinetic_energy(model, monkeypatch):
    """To the solve's tolerance (1e-6 v0 on the slips here; the default is 0.1 v0), with the structure's consistent
    mass (its inverse dense over the structure), and the booked work is the kinetic energy removed to round-off."""
    m, x0 = model
    monkeypatch.setattr(type(m), "FRICTION_TOL", 1e-6)
    assert_friction_solve_all_is_backward_euler(m, _states(m, x0))


@pytest.mark.parametrize("scheme", [pytest.param("imex-rk4", marks=pytest.mark.slow), "multirate-rk4"])
def test_split_schemes_with_all_friction_converge_to_a_fine_explicit_run(model, scheme):
    """From a running state off balance (its stiff modes ringing), the split schemes with all friction at h = 1e-6,
    5e-7, 2.5e-7 s against DUMKA3 at 5e-8 s over 4 us: the errors of the velocities and of the dissipated work fall with
    the step at order 0.8 or more at each halving (order one at best: imex-rk4's is reduced in this stiff transient,
    multirate-rk4's mean over ``eta`` is first-order), the velocities' to within 1 % of their change at 2.5e-7 s.
    Found: imex-rk4 23, 11, 4 m/s and 5.5e-3, 2.7e-3, 1.0e-3 of the work; multirate-rk4 9.8, 3.1, 1.6 m/s of a change
    of 368 m/s and 2.4e-2, 1.4e-3, 3.8e-4 of the work."""
    m, x0 = model
    x = _running(m, x0, 5)
    t, n2 = (0.0, 4e-6), m.n2
    iw = 2 * n2 + m.control.size + 2
    ref = solve(m, t, x, method="dumka3", h=5e-8, adaptive=False).y[:, -1]
    change = np.abs(ref[n2:2 * n2] - x[n2:2 * n2]).max()
    errors, work = [], []
    for h in (1e-6, 5e-7, 2.5e-7):
        y = solve(m, t, x, method="strang-friction", h=h, scheme=scheme, friction="all").y[:, -1]
        errors.append(np.abs(y[n2:2 * n2] - ref[n2:2 * n2]).max())
        work.append(abs((y[iw] - ref[iw]) / (ref[iw] - x[iw])))
    assert errors[2] <= 1e-2 * change
    for e in (errors, work):
        assert np.all(np.log2(np.array(e[:-1]) / np.array(e[1:])) >= 0.8)


def test_friction_rate_is_the_split_friction_and_its_bound_holds(model):
    """``friction_rate`` (multirate-rk4's stiff part, positions frozen): its accelerations equal the compiled force
    passes' friction (``f - f_E`` of the variant ``"all"``) to round-off, and its bound, the power iteration with every
    slip at its law's steepest slope, is not below the spectral radius of its own velocity Jacobian (ARPACK on central
    differences), nor far above it at the placed state where the slips stick; its compiled Chebyshev stages are the
    same recurrence on the rate written in Python."""
    from scipy.sparse.linalg import LinearOperator, eigs

    from cvtfem.integrate.stabilized import rkc1_coefficients

    m, x0 = model
    n2 = m.n2
    explicit = m.stiff_split[3]["all"][0]
    for x in _states(m, x0):
        rate = m.friction_rate(x)
        f, fE, fI = m.rhs(0.0, x), explicit(0.0, x), np.empty(n2)
        rate(x[n2:2 * n2], fI)
        assert np.abs(fI - (f - fE)[n2:2 * n2]).max() <= 1e-12 * np.abs(f).max()
        radius, _ = rate.bound(None, 300)
        eps = 1e-7 * np.abs(x[n2:2 * n2]).max()

        def jv(w):
            r1, r2 = np.empty(n2), np.empty(n2)
            rate(x[n2:2 * n2] + eps * w, r1)
            rate(x[n2:2 * n2] - eps * w, r2)
            return (r1 - r2) / (2 * eps)

        lam = eigs(LinearOperator((n2, n2), matvec=jv), k=1, which="LM", v0=np.ones(n2),
                   return_eigenvectors=False)[0]
        assert abs(lam) <= radius * (1 + 1e-6) and abs(lam) >= 0.2 * radius, (lam, radius)
        # the compiled Chebyshev stages = the same recurrence on the rate in Python
        eta, mu, nu, mu_t = 1.5e-6, *rkc1_coefficients(12)
        a, v, g = fE[n2:2 * n2], x[n2:2 * n2], np.empty(n2)
        rate(v, g)
        u_prev, u = v, v + mu_t[1] * eta * (a + g)
        for j in range(2, 13):
            rate(u, g)
            u, u_prev = mu[j] * u + nu[j] * u_prev + mu_t[j] * eta * (a + g), u
        assert np.abs(rate.advance(v, a, eta, (mu, nu, mu_t)) - u).max() <= 1e-12 * np.abs(u).max()

