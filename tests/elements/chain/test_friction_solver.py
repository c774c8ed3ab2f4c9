"""The compiled slip-space solver of the implicit friction (``cvtfem.elements.chain.friction_solver``): the LDL^T of
``C = I + h E K E`` against scipy's sparse solve on random block systems and on a closed chain (the cyclic corner),
and the Newton direction with a border against the dense velocity-space system ``M + h S^T E E S``."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.elements.chain.friction_solver import SlipCholesky, fill_reducing_order
from cvtfem.errors import NumericalError


def _blocks(rng, sizes, singular=False):
    """Random symmetric PSD blocks flattened (the square roots of friction slopes), some singular."""
    out = []
    for k, d in enumerate(sizes):
        A = rng.standard_normal((d, d))
        if singular and k % 3 == 0:
            A[:, 0] = 0.0
        out.append((A @ A.T).ravel())
    return np.concatenate(out)


def _dense_blocks(E, sizes):
    off = np.concatenate([[0], np.cumsum(sizes ** 2)[:-1]])
    return sp.block_diag([E[o:o + d * d].reshape(d, d) for o, d in zip(off, sizes)]).toarray()


def _random_system(rng, n_contacts=60, n_vel=150):
    sizes = rng.choice([1, 2, 3], n_contacts)
    S = sp.random(sizes.sum(), n_vel, density=0.03, random_state=rng, format="csr")
    Mi = sp.diags(rng.uniform(0.5, 2.0, n_vel), format="csr")
    return sizes, S, Mi


def _chain_system(rng, n_pins=40, dofs=4):
    """Contacts of a closed chain: the slips of a pin read its dofs and the next pin's (the last pin: the first's)."""
    sizes = np.tile([1, 2], n_pins)
    rows, cols = [], []
    r = 0
    for p in range(n_pins):
        for d in (1, 2):
            for _ in range(d):
                for q in (p, (p + 1) % n_pins):
                    rows += [r] * dofs
                    cols += list(q * dofs + np.arange(dofs))
                r += 1
    S = sp.csr_matrix((rng.standard_normal(len(rows)), (rows, cols)), shape=(r, n_pins * dofs))
    blocks = [rng.standard_normal((dofs, dofs)) for _ in range(n_pins)]
    Mi = sp.block_diag([b @ b.T + dofs * np.eye(dofs) for b in blocks], format="csr")
    return sizes, S, Mi


@pytest.mark.parametrize("make", [_random_system, _chain_system])
@pytest.mark.parametrize("singular", [False, True])
def test_ldl_solves_the_slip_matrix_like_scipy(make, singular):
    rng = np.random.default_rng(7)
    sizes, S, Mi = make(rng)
    K = (S @ Mi @ S.T).tocsr()
    K.sort_indices()
    system = SlipCholesky(K, sizes)
    for h in (1e-3, 0.4):                                   # one pattern, two factorisations
        E = _blocks(rng, sizes, singular)
        Ed = _dense_blocks(E, sizes)
        C = sp.csc_matrix(np.eye(K.shape[0]) + h * Ed @ K.toarray() @ Ed)
        b = rng.standard_normal((K.shape[0], 3))
        system.factor(K.data, h, E)
        x = system.solve(b)
        ref = spla.spsolve(C, b)
        assert np.abs(x - ref).max() <= 1e-12 * np.abs(ref).max()
        assert np.abs(system.solve(b[:, 0]) - ref[:, 0]).max() <= 1e-12 * np.abs(ref).max()
        upper = system.matrix(K.data, h, E).toarray()         # C's upper triangle in the solver's order
        P = np.argsort(system.perm)
        assert np.abs(upper - np.triu(C.toarray()[P][:, P])).max() <= 1e-13 * np.abs(C).max()


def test_the_closed_chain_couples_its_ends():
    """The cyclic corner: the last pin's slips read the first pin's dofs, so ``C`` couples them, and the solve is
    still exact."""
    rng = np.random.default_rng(1)
    sizes, S, Mi = _chain_system(rng)
    K = (S @ Mi @ S.T).tocsr()
    assert abs(K[0, K.shape[0] - 1]) > 0
    K.sort_indices()
    E = _blocks(rng, sizes)
    system = SlipCholesky(K, sizes)
    system.factor(K.data, 1.0, E)
    Ed = _dense_blocks(E, sizes)
    C = np.eye(K.shape[0]) + Ed @ K.toarray() @ Ed
    b = rng.standard_normal(K.shape[0])
    assert np.abs(C @ system.solve(b) - b).max() <= 1e-12 * np.abs(b).max() * np.linalg.cond(C)


@pytest.mark.parametrize("border, density", [(0, 1.0), (3, 1.0), (6, 0.3)])
def test_direction_is_the_velocity_space_newton_step(border, density):
    """``dv = -(M + h S^T E E S)^-1 g`` with ``r`` border velocities that many slips read (the shafts: a dense or, for
    a sheave's coordinates, a sparse column block of ``S``, whose zeros the forward solve skips), taken out of ``K``
    and put back by Woodbury, against scipy's sparse solve of the velocity-space matrix to 1e-12."""
    rng = np.random.default_rng(5)
    sizes, S, Mi = _chain_system(rng)
    n = S.shape[1]
    if border:
        B = rng.standard_normal((S.shape[0], border)) * (rng.uniform(size=(S.shape[0], border)) < density)
        S = sp.hstack([S, sp.csr_matrix(B)], format="csr")
        Mi = sp.block_diag([Mi, sp.diags(rng.uniform(0.5, 2.0, border))], format="csr")
    inner = np.arange(S.shape[1]) < n
    Mi_in = (Mi.multiply(inner[:, None]).multiply(inner[None, :])).tocsr()
    Mi_in.eliminate_zeros()
    St = S.T.tocsr()
    K = (S @ Mi_in @ St).tocsr()
    K.sort_indices()
    U = np.ascontiguousarray(St[~inner].toarray().T)
    Mb = Mi[~inner][:, ~inner].toarray()
    E, h = _blocks(rng, sizes, singular=True), 0.3
    g = rng.standard_normal(S.shape[1])
    dv, ds = SlipCholesky(K, sizes).direction(K.data, h, E, g, Mi, S, St, U, Mb)
    Ed = sp.csr_matrix(_dense_blocks(E, sizes))
    H = sp.csc_matrix(sp.csr_matrix(np.linalg.inv(Mi.toarray())) + h * St @ Ed @ Ed @ S)
    ref = -spla.spsolve(H, g)
    assert np.abs(dv - ref).max() <= 1e-12 * np.abs(ref).max()
    assert np.abs(ds - S @ dv).max() <= 1e-14 * np.abs(ds).max()


def test_an_indefinite_matrix_is_refused():
    rng = np.random.default_rng(2)
    sizes, S, Mi = _random_system(rng)
    K = (S @ Mi @ S.T).tocsr()
    K.sort_indices()
    system = SlipCholesky(K, sizes)
    with pytest.raises(NumericalError, match="not positive definite"):
        system.factor(K.data, -1e3, _blocks(rng, sizes))


def test_the_fill_reducing_order_needs_the_pattern_only():
    """The order of a pattern whose entries, counted with their repeats, make an exactly singular matrix (it stopped
    an imex run of (e) elastic, session 14: 725 slip rows with entries 1, 2, 4, 5): a permutation, equal to SuperLU's
    order of the same pattern with random SPD values."""
    r, c = np.array([0, 1, 0, 1, 0, 1]), np.array([0, 1, 1, 0, 1, 0])
    ones = sp.csc_matrix((np.ones(r.size), (r, c)), shape=(2, 2)) + sp.identity(2, format="csc")
    with pytest.raises(RuntimeError, match="singular"):
        spla.splu(ones.tocsc(), permc_spec="MMD_AT_PLUS_A")     # [[2, 2], [2, 2]]: the construction this replaces
    assert sorted(fill_reducing_order(r, c, 2)) == [0, 1]
    rng = np.random.default_rng(3)
    m = 120
    r, c = rng.integers(0, m, 600), rng.integers(0, m, 600)
    r, c = np.concatenate([r, c, r]), np.concatenate([c, r, c])              # symmetric, with repeats
    A = sp.csc_matrix((rng.random(r.size), (r, c)), shape=(m, m))
    A = A + A.T + m * sp.identity(m)
    assert np.array_equal(fill_reducing_order(r, c, m), spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A").perm_c)
