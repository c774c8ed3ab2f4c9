"""Secant-updated LU factors (Newton ``hart``): solves and the secant equation, dense and sparse."""
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.integrate.luupdate import UpdatedLU
from cvtfem.integrate.stats import Stats


@pytest.mark.parametrize("sparse", [False, True])
def test_updated_factors_solve_and_satisfy_secant(sparse):
    rng = np.random.default_rng(0)
    A = sp.random(60, 60, density=0.08, random_state=2) + 3 * sp.identity(60)
    B = A.tocsc() if sparse else A.toarray()
    st = Stats()
    f = UpdatedLU(st, B)
    b = rng.standard_normal(60)
    assert np.max(np.abs(B @ f.solve_y(b) - b)) < 1e-12
    U_nnz = (f.U != 0).sum()
    for _ in range(3):      # several updates: each new product maps s to y exactly
        s, y = rng.standard_normal(60), rng.standard_normal(60)
        f.update(s, y)
        assert np.max(np.abs(f.solve_y(y) - s)) < 1e-10
    assert (f.U != 0).sum() <= U_nnz        # pattern kept
    assert st.counts["nlu"] == 1            # no refactorisation
