"""The free discrete chain through the Model protocol (issue 13: the chain as a model family)."""
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from cvtfem.assembly.model import Model
from cvtfem.elements.chain.geometry import REFERENCE_SECTION, chain_geometry, ring_positions
from cvtfem.elements.chain.symmetric import ChainDamping, ChainS1, ChainS2, ChainS3
from cvtfem.integrate import solve
from cvtfem.machines.chain import FreeChain

C_LINK, PITCH = 1.4e9, 0.009


def _open_chain(Family, n=10):
    g = chain_geometry(n, 0.033, PITCH, 12, C_LINK, n * 0.0179, REFERENCE_SECTION, c_pin=2.0e8, closed=False)
    fam = Family(g)
    x = np.stack([np.arange(n) * PITCH, np.zeros(n)], axis=1)
    return fam, FreeChain(fam, fam.join(x, np.full(n, g.l / 2), np.zeros((n, 2))))


def _ring(Family, n=8, damping=ChainDamping()):
    g = chain_geometry(n, 0.033, PITCH, 12, C_LINK, n * 0.0179, REFERENCE_SECTION, c_pin=2.0e8)
    fam = Family(g, damping)
    x, _ = ring_positions(g.L)
    rng = np.random.default_rng(3)
    v0 = fam.join(rng.normal(0.0, 0.05, (n, 2)), rng.normal(0.0, 0.05, n), rng.normal(0.0, 0.5, (n, 2)))
    return fam, FreeChain(fam, fam.join(x, np.full(n, g.l / 2), np.zeros((n, 2))), v0)


@pytest.mark.parametrize("Family", [ChainS1, ChainS2])
def test_linearised_straight_chain_has_the_spring_mass_frequencies(Family):
    """About a straight, unstretched open chain the in-line stiffness is the link stiffness c between
    neighbours: the free-free spring-mass chain (masses m_eff, an independent tridiagonal model) gives
    the longitudinal frequencies, to 1e-9 relative."""
    fam, model = _open_chain(Family)
    lin = model.linearize(model.initial_state())
    w2 = sla.eigh(lin.K.toarray(), lin.M.toarray(), eigvals_only=True)
    n, m = fam.n, fam.geom.m_eff
    lap = np.diag(np.r_[1.0, np.full(n - 2, 2.0), 1.0]) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1)
    ref = sla.eigh(C_LINK * lap, np.diag(m), eigvals_only=True)
    for value in ref[1:]:
        assert np.min(np.abs(w2 - value)) <= 1e-9 * value
    assert np.allclose(lin.G.toarray(), 0.0) and abs(ref[0]) < 1e-6 * ref[-1]   # the rigid translation


@pytest.mark.parametrize("Family", [ChainS1, ChainS2, ChainS3])
def test_protocol_jacobian_and_its_pattern(Family):
    fam, model = _ring(Family, damping=ChainDamping(beta_link=1e-6, b_joint=1e-4))
    assert isinstance(model, Model)
    x = model.initial_state() + 1e-5 * np.random.default_rng(1).standard_normal(model.size)
    J = model.jac(0.0, x)
    outside = J.multiply(sp.csr_matrix(~model.jac_sparsity.toarray()))
    assert outside.nnz == 0 or np.abs(outside.data).max() == 0.0
    fd = model.fd_jac(0.0, x).toarray()
    scale = np.abs(J.toarray()).max()
    assert np.abs(fd - J.toarray()).max() <= 1e-5 * scale


@pytest.mark.parametrize("Family", [ChainS1, ChainS2, ChainS3])
def test_free_ring_conserves_energy_through_solve(Family):
    """A closed ring with random initial velocities, no dissipation: solve(model) (dopri78, rtol 1e-10)
    keeps the energy to 1e-8 relative and the linear momentum to round-off over 20 periods of the
    highest in-line link mode."""
    fam, model = _ring(Family)
    period = 2 * np.pi / (2 * np.sqrt(C_LINK / fam.geom.m_eff.min()))
    res = solve(model, (0.0, 20 * period), model.initial_state(), method="dopri78", rtol=1e-10, atol=1e-14)
    assert res.success
    E = np.array([model.energy(x) for x in res.y.T])
    assert np.abs(E - E[0]).max() <= 1e-8 * E[0]
    p = np.array([fam.linear_momentum(x[model.n2:]) for x in res.y.T])
    assert np.abs(p - p[0]).max() <= 1e-12 * np.abs(fam.geom.m_eff).sum() * 0.05


def test_damped_ring_loses_what_the_rayleigh_forces_take():
    """dE/dt = -2 Phi along a damped run: E(t) + int 2 Phi dt stays at E(0) to 1e-6 of the dissipated energy."""
    fam, model = _ring(ChainS2, damping=ChainDamping(beta_link=2e-7, b_joint=1e-4))
    period = 2 * np.pi / (2 * np.sqrt(C_LINK / fam.geom.m_eff.min()))
    t = np.linspace(0.0, 10 * period, 2001)
    res = solve(model, (0.0, t[-1]), model.initial_state(), method="dopri78", rtol=1e-11, atol=1e-15, t_eval=t)
    E = np.array([model.energy(x) for x in res.y.T])
    D = np.array([model.power(0.0, x)["dissipated"] for x in res.y.T])
    lost = np.concatenate([[0.0], np.cumsum(0.5 * (D[1:] + D[:-1]) * np.diff(t))])   # trapezoid
    assert lost[-1] > 1e-3 * E[0]
    assert np.abs(E + lost - E[0]).max() <= 1e-3 * lost[-1]
