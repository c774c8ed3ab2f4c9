"""The one step loop's memory (issue 12): a checkpoint of a 3,500-state sparse model stays small
(Jacobians and iteration matrices stored compressed) and restores bit for bit."""
from __future__ import annotations

import h5py
import numpy as np
import pytest
import scipy.sparse as sp

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
