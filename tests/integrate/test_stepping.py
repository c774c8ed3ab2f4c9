"""The one step loop's memory (issue 12): a checkpoint of a 3,500-state sparse model stays small
(Jacobians and iteration matrices stored compressed) and restores bit for bit."""
from __future__ import annotations

import h5py
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.errors import NumericalError
from cvtfem.integrate.stepping import Stepping, make_engine
from cvtfem.integrate.system import as_system
from cvtfem.io import checkpoint as ckpt

N_MASS = 1750          # 3,500 states
K, C = 1e4, 1.0        # spring stiffness (N/m), damping (N s/m), unit masses


def chain():
    """Free-fixed chain of unit masses and springs with dampers: ``x = [u, v]``, sparse analytic Jacobian."""
    n = N_MASS
    main = np.full(n, -2 * K)
    main[-1] = -K
    Kmat = sp.diags([np.full(n - 1, K), main, np.full(n - 1, K)], [-1, 0, 1], format="csr")
    J = sp.bmat([[None, sp.identity(n)], [Kmat, -C * sp.identity(n)]], format="csr")

    def rhs(t, x):
        return J @ x + np.concatenate([np.zeros(2 * n - 1), [np.sin(300 * t)]])

    x0 = np.concatenate([np.sin(np.linspace(0, np.pi, n)) * 1e-3, np.zeros(n)])
    return rhs, (lambda t, x: J), J != 0, x0


def _stepping(method, t0, x0, first_step=None):
    rhs, jac, pattern, _ = chain()
    system = as_system(rhs, x0, n2=N_MASS if method == "trapezoidal" else 0, jac=jac, jac_sparsity=pattern)
    engine = make_engine(method, system, t0, x0, 1.0, 1e-6, 1e-9, first_step=first_step)
    return Stepping(engine, t0, x0, 1.0)


@pytest.mark.parametrize("method", ["trapezoidal", "Radau", "BDF"])
def test_sparse_checkpoint_slot_is_small_and_restores_bitwise(tmp_path, method):
    run = _stepping(method, 0.0, chain()[3])
    for _ in range(6):
        assert run.step() and run.status == "running"
    state = run.state()
    layout = ckpt.Layout(run.fields())
    with h5py.File(tmp_path / "c.h5", "w") as f:
        ckpt.create(f, layout)
        ckpt.write(f, layout, 1, state)
        slot = f[ckpt.GROUP]["slots"][1].nbytes
    with h5py.File(tmp_path / "c.h5", "r") as f:
        _, back = ckpt.read_latest(f)
    assert slot < 5e6, slot                              # dense Jacobians alone: 3 x 98 MB
    again = _stepping(method, float(back["t"][0]), back["x"], first_step=float(back["h"][0]))
    again.restore(back)
    for _ in range(4):
        run.step(), again.step()
        assert run.t == again.t and np.array_equal(run.x, again.x)
    for c in ("nfev", "njev", "nlu"):
        assert run.counts[c] == again.counts[c], c


class _Unphysical:
    """``y' = -k (y - 0.9)`` from 0 whose right-hand side refuses a state above 1 with the model's NumericalError
    (as the H2 contact refuses a pin end on a shaft axis): an explicit stage of a too-long step lands there."""

    k = 50.0

    def __call__(self, t, y):
        if y[0] > 1.0:
            raise NumericalError("a state the model cannot evaluate", component="test model")
        return -self.k * (y - 0.9)


def test_a_models_numerical_error_rejects_the_step_of_an_adaptive_run():
    """The playground's adaptive steppers retry with a smaller step (scipy's solvers stop with the reason)."""
    fun = _Unphysical()
    system = as_system(fun, np.zeros(1))
    run = Stepping(make_engine("dopri45", system, 0.0, np.zeros(1), 1.0, 1e-8, 1e-10, first_step=0.1), 0.0,
                   np.zeros(1), 1.0)
    with pytest.raises(NumericalError):
        fun(0.0, np.array([0.0 + 0.1 * fun.k * 0.9]))        # the first trial's stage lies beyond the limit
    while run.status == "running":
        assert run.step(), run.failure
    assert run.x[0] == pytest.approx(0.9 - 0.9 * np.exp(-fun.k), abs=1e-8)


def test_a_models_numerical_error_stops_a_fixed_step_run_with_its_reason():
    from cvtfem.integrate import solve

    res = solve(_Unphysical(), (0.0, 1.0), [0.0], method="rk4", h=0.1)   # stage y = 4.5 at the first step
    assert not res.success and "cannot evaluate" in res.message and "h = 0.1" in res.message
    with pytest.raises(NumericalError, match="cannot evaluate"):
        solve(_Unphysical(), (0.0, 1.0), [0.0], method="rk4", h=0.1, raise_on_failure=True)
