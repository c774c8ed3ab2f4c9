"""Block sweep (tree elimination) against dense and sparse frequency-domain solves."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.torsional import build_network
from cvtfem.errors import InputError
from cvtfem.assembly.numbering import through_numbering
from cvtfem.periodic import blocktri, hb


def dense_response(net, omega, N):
    """Per harmonic dense solve of (K + i n w C - n^2 w^2 M) a = p, assembled independently."""
    S = net.n_nodes
    K = np.zeros((S, S))
    C = np.diag(net.b).astype(float)
    for e in range(net.n_links):
        idx = [net.i[e]] + ([net.j[e]] if net.j[e] >= 0 else [])
        sign = np.array([1.0, -1.0][:len(idx)])
        K[np.ix_(idx, idx)] += net.k_out[e] * np.outer(sign, sign)
        C[np.ix_(idx, idx)] += net.d[e] * np.outer(sign, sign)
    p = hb.load_harmonics(net, N)
    a = np.empty_like(p)
    for k, n in enumerate(range(-N, N + 1)):
        Z = K + 1j * n * omega * C - (n * omega) ** 2 * np.diag(net.m)
        a[:, k] = np.linalg.solve(Z, p[:, k])
    return a


def random_network(rng, parents):
    S = len(parents)
    i = [s for s in range(S) if parents[s] >= 0] + [0]
    j = [parents[s] for s in range(S) if parents[s] >= 0] + [-1]
    E = len(i)
    Q = rng.normal(size=(S, 3)) + 1j * rng.normal(size=(S, 3))
    return build_network(rng.uniform(0.5, 2, S), rng.uniform(0.1, 1, S), i, j, rng.uniform(1e4, 1e5, E),
                         d=rng.uniform(1, 10, E), orders=(0, 1, 3), Q=Q)


def chain_parents(S):
    return [-1] + list(range(S - 1))


def branched_parents():
    # main chain 0..9, side branch 10..13 from node 4, branch 14..16 from node 7, twig 17 from 11
    parents = [-1] + list(range(9)) + [4, 10, 11, 12, 7, 14, 15, 11]
    return parents


@pytest.mark.parametrize("parents", [chain_parents(12), branched_parents()], ids=["chain", "branched"])
def test_sweep_equals_dense_solve(parents):
    rng = np.random.default_rng(3)
    net = random_network(rng, parents)
    for omega in (30.0, 170.0, 400.0):  # below, among and above the natural frequencies
        ref = dense_response(net, omega, 4)
        got = hb.solve_linear(net, omega, 4, method="sweep")
        assert got.method == "sweep"
        assert np.abs(got.a - ref).max() <= 1e-10 * np.abs(ref).max()


def test_nonlinear_blocks_sweep_equals_sparse_lu():
    """Full Toeplitz blocks (Newton step) on a branched tree: sweep == assembled sparse LU."""
    rng = np.random.default_rng(5)
    parents = branched_parents()
    net0 = random_network(rng, parents)
    E = net0.n_links
    net = build_network(net0.m, net0.b, net0.i, net0.j, net0.k_out, d=net0.d, law=[1] * (E - 1) + [0],
                        k_in=0.05 * net0.k_out, h=np.full(E, 1e-4), orders=net0.orders, Q=net0.Q * 10)
    N, omega = 6, 120.0
    M = hb.default_samples(N)
    topo = hb.prepare(net)
    a = hb.solve_linear(net, omega, N).a
    d_sweep, _, used = hb.newton_step(net, omega, a, hb.load_harmonics(net, N), M, topo, net.incidence(), "sweep")
    d_lu, _, used_lu = hb.newton_step(net, omega, a, hb.load_harmonics(net, N), M, topo, net.incidence(), "sparse")
    assert (used, used_lu) == ("sweep", "sparse")
    assert np.abs(d_sweep - d_lu).max() <= 1e-10 * np.abs(d_lu).max()


def test_loop_goes_to_sparse_lu():
    rng = np.random.default_rng(1)
    # ring of 6 nodes (a loop) + one ground link
    i, j = [0, 1, 2, 3, 4, 5, 0], [1, 2, 3, 4, 5, 0, -1]
    net = build_network(rng.uniform(1, 2, 6), np.full(6, 0.5), i, j, rng.uniform(1e4, 2e4, 7),
                        orders=(1,), Q=rng.normal(size=(6, 1)))
    assert through_numbering(6, net.i, net.j) is None
    got = hb.solve_linear(net, 80.0, 2)
    assert got.method == "sparse"
    ref = dense_response(net, 80.0, 2)
    assert np.abs(got.a - ref).max() <= 1e-10 * np.abs(ref).max()
    with pytest.raises(InputError, match="loop"):
        hb.solve_linear(net, 80.0, 2, method="sweep")


def test_ungrounded_network_is_rejected():
    net = build_network([1.0, 1.0], [0.1, 0.1], [0], [1], [1e4], orders=(1,), Q=[[1.0], [0.0]])
    with pytest.raises(InputError, match="ground"):
        hb.solve_linear(net, 10.0, 2)


def test_diagonal_fast_path_with_one_backlash_link():
    """One backlash link in a branched tree: the root sits at it, linear side trees stay diagonal."""
    rng = np.random.default_rng(8)
    parents = branched_parents()
    net0 = random_network(rng, parents)
    E = net0.n_links
    law = np.zeros(E, int)
    law[12] = 1  # a link on the first side branch
    net = build_network(net0.m, net0.b, net0.i, net0.j, net0.k_out, d=net0.d, law=law, k_in=0.05 * net0.k_out,
                        h=np.full(E, 1e-4), orders=net0.orders, Q=net0.Q * 10)
    topo = hb.prepare(net)
    assert topo.order[0] in (net.i[12], net.j[12])  # rooted at the nonlinear link
    N, omega = 6, 150.0
    M, D, p = hb.default_samples(N), net.incidence(), hb.load_harmonics(net, N)
    a = hb.solve_linear(net, omega, N).a
    d_sweep, _, _ = hb.newton_step(net, omega, a, p, M, topo, D, "sweep")
    d_lu, _, _ = hb.newton_step(net, omega, a, p, M, topo, D, "sparse")
    assert np.abs(d_sweep - d_lu).max() <= 1e-10 * np.abs(d_lu).max()


def test_mixed_real_basis_sweep_equals_full_complex_sweep():
    """Mixed storage + real cos/sin basis (Newton steps) == the full complex block sweep, also when the
    root is away from the backlash links (dense fill-in through linear links, diagonal children of dense nodes)."""
    rng = np.random.default_rng(11)
    parents = branched_parents()
    net0 = random_network(rng, parents)
    E = net0.n_links
    law = np.zeros(E, int)
    law[[3, 12, 15]] = 1
    net = build_network(net0.m, net0.b, net0.i, net0.j, net0.k_out, d=net0.d, law=law, k_in=0.05 * net0.k_out,
                        h=np.full(E, 1e-4), orders=net0.orders, Q=net0.Q * 10)
    N, omega = 7, 140.0
    M, D, p = hb.default_samples(N), net.incidence(), hb.load_harmonics(net, N)
    a = hb.solve_linear(net, omega, N).a
    r, Nb, L = hb.linearize(net, omega, a, p, M, D)
    _, Nd, Ld, dense, Ldense = hb.linearize_mixed(net, omega, a, p, M, D)
    g = -hb._symmetrize(r)
    for topo in (hb.prepare(net), through_numbering(net.n_nodes, net.i, net.j)):
        ref = blocktri.block_sweep(topo, Nb, L, net.i, net.j, g[:, None])[:, 0]
        got = blocktri.block_sweep_mixed(topo, Nd, Ld, dense, Ldense, net.i, net.j, g)
        assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max()
        res = blocktri.apply_mixed(Nd, Ld, dense, Ldense, net.i, net.j, got) - g
        assert np.linalg.norm(res) <= 1e-10 * np.linalg.norm(g)
