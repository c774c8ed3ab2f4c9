"""Checks shared by the tests of the chain on the sheaves (S2/S3 with H1 or H2, A1)."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.integrate import solve


def assert_jacobian_columns(model, x, J, cols) -> None:
    """Columns ``cols`` of the dense Jacobian ``J`` at ``x`` equal central differences of ``model.rhs`` to 1e-5 of
    each row's largest entry (rows of the accelerations and beyond; ``u' = v`` is exact)."""
    n2 = model.n2
    rows = slice(n2, None)
    scale = np.abs(J[rows]).max(axis=1)
    for c in cols:
        h = 1e-9 if c < n2 else 1e-6 * max(1.0, abs(x[c]))
        xp, xm = x.copy(), x.copy()
        xp[c] += h
        xm[c] -= h
        fd = (model.rhs(0.0, xp) - model.rhs(0.0, xm))[rows] / (2 * h)
        err = np.abs(J[rows, c] - fd)
        assert np.all(err <= 1e-5 * scale + 1e-6), (c, err.max())


def assert_energy_balance(model, x0, t_end: float) -> None:
    """A Radau run (rtol 1e-6) over ``[0, t_end]`` s: ``E(t) - E(0)`` = input - output + clamping - dissipated
    work to 1e-6 of the input work, with power going in and friction dissipating some."""
    res = solve(model, (0.0, t_end), x0, method="Radau", rtol=1e-6, atol=1e-9, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity)
    assert res.status == 0
    x1 = res.y[:, -1]
    W = model.split(x1)[3]
    assert W[0] > 1.0 and W[2] > 0.0
    assert model.energy(x1) - model.energy(x0) == pytest.approx(W[0] - W[1] + W[3] - W[2], abs=1e-6 * W[0])
