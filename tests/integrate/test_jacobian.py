"""Graph-coloured finite-difference Jacobians (spec §11.3, issue 4 acceptance)."""
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.integrate.base import Stepper
from cvtfem.assembly.colouring import color_columns
from cvtfem.integrate.jacobian import JacobianProvider
from cvtfem.integrate.linsolve import DENSE_MAX
from cvtfem.integrate.system import as_system
from cvtfem.problems import coupled_oscillators


def banded_problem(n, bw):
    """Nonlinear RHS with half-bandwidth ``bw``: ``F_i = sum_{|j-i|<=bw} sin(c_ij y_j) + y_i^3``."""
    rng = np.random.default_rng(1)
    C = sp.diags([rng.uniform(0.5, 1.5, n - abs(k)) for k in range(-bw, bw + 1)],
                 list(range(-bw, bw + 1)), format="csr")

    def fun(t, y):
        Cs = C.copy()
        Cs.data = np.sin(C.data * y[C.indices])
        return np.asarray(Cs.sum(axis=1)).ravel() + y ** 3

    def jac(t, y):
        J = C.copy()
        J.data = C.data * np.cos(C.data * y[C.indices])
        return J + sp.diags(3 * y ** 2)

    return fun, jac, C != 0


@pytest.mark.parametrize("bw", [1, 2, 5])
def test_banded_costs_bandwidth_plus_one(bw):
    n = 200
    fun, jac, pattern = banded_problem(n, bw)
    y = np.linspace(-1, 1, n)
    colored = Stepper(as_system(fun, y, jac_sparsity=pattern))
    prov = JacobianProvider(colored)
    assert prov.n_colors == 2 * bw + 1          # full bandwidth + 1 groups
    J = prov(0.0, y)
    assert colored.stats.counts["nfev_jac"] == 2 * bw + 1
    assert colored.stats.counts["nfev"] == 2 * bw + 2     # + F(x) itself
    dense = Stepper(as_system(fun, y))
    Jd = JacobianProvider(dense)(0.0, y)
    assert dense.stats.counts["nfev_jac"] == n
    assert np.max(np.abs(J.toarray() - Jd.toarray())) < 1e-7
    assert np.max(np.abs(J.toarray() - jac(0, y).toarray())) < 1e-6


def test_colouring_is_valid_on_random_pattern():
    S = sp.random(300, 300, density=0.01, random_state=3, format="csr") != 0
    colors = color_columns(S)
    Sc = sp.csc_matrix(S)
    for c in range(colors.max() + 1):
        cols = np.flatnonzero(colors == c)
        rows = Sc[:, cols].indices
        assert len(rows) == len(np.unique(rows)), "two columns of one colour share a row"


def test_second_order_rows_are_exact():
    """For x = [u, v] the u' = v rows are set analytically; only F_v rows are differenced."""
    p = coupled_oscillators(n=DENSE_MAX + 20)
    st = Stepper(as_system(p.fun, p.y0, n2=p.info.get("n2", len(p.y0) // 2), jac_sparsity=p.jac_sparsity))
    prov = JacobianProvider(st)
    assert prov.n_colors == 3          # tridiagonal stiffness block
    J = prov(0.0, p.y0 + 0.1).toarray()
    n = len(p.y0) // 2
    assert np.array_equal(J[:n, n:], np.eye(n)) and not J[:n, :n].any()
