"""The second-order RHS protocol (spec §1.1, §11.1): a model object with rhs/n2/jac_sparsity."""
import numpy as np
import scipy.sparse as sp

from cvtfem.integrate import solve


class SpringChain:
    """Model-like object: n2 masses on springs plus n1 = 1 first-order state z' = -z + u_0."""

    n2 = 30

    def __init__(self):
        n = self.n2
        self.K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format="csr") * 100.0
        band = self.K != 0
        z_row = sp.csr_matrix(([True, True], ([0, 0], [0, 2 * n])), shape=(1, 2 * n + 1))
        top = sp.hstack([sp.csr_matrix((n, n), dtype=bool), sp.identity(n, dtype=bool),
                         sp.csr_matrix((n, 1), dtype=bool)])
        mid = sp.hstack([band, sp.identity(n, dtype=bool), sp.csr_matrix((n, 1), dtype=bool)])
        self.jac_sparsity = sp.vstack([top, mid, z_row]).tocsr()
        self.calls = 0

    def rhs(self, t, x):
        self.calls += 1
        n = self.n2
        u, v, z = x[:n], x[n:2 * n], x[2 * n:]
        return np.concatenate([v, -self.K @ u - 0.5 * v - 10 * u ** 3, -z + u[:1]])


def test_model_object_runs_with_reduced_newton_system():
    model = SpringChain()
    x0 = np.zeros(2 * model.n2 + 1)
    x0[:model.n2] = np.sin(np.linspace(0, np.pi, model.n2))
    res = solve(model, (0, 1.0), x0, method="trapezoidal", h=1e-3, newton="const")
    ref = solve(SpringChain().rhs, (0, 1.0), x0, method="DOP853", rtol=1e-11, atol=1e-12)
    assert res.success and np.max(np.abs(res.y[:, -1] - ref.y[:, -1])) < 1e-4
    # FD Jacobian: only F_v, F_z rows are differenced, so u_j columns (3 colours, tridiagonal K)
    # and v_j columns (identity block, each meets u_{j-1..j+1}) need 4 colours, not n + 1 = 62
    assert res.stats["nfev_jac"] == 4 * res.stats["njev"]
    assert res.stats["nfev"] == model.calls
