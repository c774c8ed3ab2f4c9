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


def assert_forces_are_minus_the_hertz_gradient(con, X, shafts):
    """A refined contact's frictionless generalized forces on every position input of the contacts ``X`` (more than
    100 of them touching, not all) equal minus the central-difference gradient of the Hertz potential of both ends,
    ``2 x 2/5 c Delta^{5/2}``, to 1e-6 relative; returns the forces."""
    from cvtfem.elements.contact.hertz import hertz_potential

    Y = con.local(X, shafts)
    c = con.c[shafts]

    def U(Xm):
        return 2 * hertz_potential(con.local(Xm, shafts, details=True)[1]["delta"], c)
    on = con.local(X, shafts, details=True)[1]["delta"] > 0
    assert 100 < on.sum() < len(X)
    for j in range(con.n_pos):
        h = 1e-9
        Xp, Xm = X.copy(), X.copy()
        Xp[:, j] += h
        Xm[:, j] -= h
        grad = (U(Xp) - U(Xm)) / (2 * h)
        np.testing.assert_allclose(Y[:, j], -grad, rtol=1e-6, atol=1e-6 * np.abs(Y[:, j]).max() + 1e-9)
    return Y


def assert_friction_power_is_the_work_rate(con, X, shafts) -> None:
    """A refined contact's friction power output equals the work rate of its friction forces (the forces less the
    frictionless ones) on the velocity inputs, 1e-10, and ``2 F_fr . slip`` (both ends), 1e-12; it dissipates."""
    from dataclasses import replace

    Y, d = con.local(X, shafts, details=True)
    Qfr = Y - replace(con, f0=0.0).local(X, shafts)
    n = con.n_pos
    power = (Qfr[:, :n] * X[:, n:2 * n]).sum(1) + Qfr[:, n] * X[:, -1]
    np.testing.assert_allclose(Y[:, -1], power, rtol=1e-10, atol=1e-10 * np.abs(power).max())
    np.testing.assert_allclose(Y[:, -1], 2 * (d["F_fr"] * d["slip"]).sum(1), rtol=1e-12, atol=1e-300)
    assert np.all(Y[:, -1] <= 0) and Y[:, -1].min() < -1.0


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


def perturbed(model, x0, seed: int = 0, scale=None):
    """A running state of a rigid-shaft chain CVT off balance: random chain offsets (2 um, times ``scale`` per chain
    coordinate) and velocities (0.05 m/s), and random shaft and sheave rates."""
    rng = np.random.default_rng(seed)
    x = x0.copy()
    nc, n2 = model.family.size, model.n2
    scale = np.ones(nc) if scale is None else scale
    x[:nc] += rng.normal(0.0, 2e-6, nc) * scale
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc) * scale
    x[n2 + nc:n2 + nc + 4] += rng.normal(0.0, 0.05, 4)
    return x


def band_reference(scene):
    """The 6+2n band model of ``scene`` run 1 s into its stationary regime: the clamping forces (2,) N it settles at,
    its tight and slack span tensions (2,) N (:func:`~cvtfem.machines.chain_cvt.band_span_tensions`) and its driven
    arc (:func:`~cvtfem.elements.band.creep.driven_arc`)."""
    from cvtfem.elements.band.creep import driven_arc
    from cvtfem.machines import build_model
    from cvtfem.machines.chain_cvt import band_span_tensions

    band = build_model(scene)
    rb = solve(band, (0.0, 1.0), band.initial_state(), method="Radau", rtol=1e-6, atol=1e-8, n2=band.n2,
               jac=band.jac, jac_sparsity=band.jac_sparsity)
    xb = rb.y[:, -1]
    ob = band.outputs(1.0, xb)
    q, v, _, _ = band.split(xb)
    return (np.array([ob["driving.clamping_force"], ob["driven.clamping_force"]]), band_span_tensions(band, xb),
            driven_arc(band.model, q, v))


def stationary_means(model, x0, t_end: float = 10e-3, window: float = 6e-3, method: str = "Radau", rtol: float = 1e-3):
    """Means over the last ``window`` s of a run (``method``, ``rtol``, atol ``1e-3 rtol``) to ``t_end`` sampled every
    25 us: span tensions (tight, slack), sheave axial forces and clamping forces (driving, driven), N."""
    res = solve(model, (0.0, t_end), x0, method=method, rtol=rtol, atol=1e-3 * rtol, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity, t_eval=np.linspace(t_end - window, t_end, int(window / 25e-6) + 1))
    assert res.status == 0
    outs = [model.outputs(t, y) for t, y in zip(res.t, res.y.T)]
    T = np.nanmean([o["chain.span_tension"] for o in outs], axis=0)
    axial = np.mean([o["contact.sheave_axial_force"] for o in outs], axis=0)
    clamp = np.mean([[o["driving.clamping_force"], o["driven.clamping_force"]] for o in outs], axis=0)
    return T, axial, clamp


def assert_jacobian_on_pattern(model, x, n_chain: int = 25) -> None:
    """``model.jac`` at ``x`` is zero off ``jac_sparsity`` and equals central differences on ``n_chain`` random chain
    position and velocity columns and on every shaft, sheave and loop column (:func:`assert_jacobian_columns`)."""
    J = model.jac(0.0, x).toarray()
    assert not np.any(J[~model.jac_sparsity.toarray()])
    rng = np.random.default_rng(5)
    n2, nc = model.n2, model.family.size
    cols = np.concatenate([rng.choice(nc, n_chain, replace=False), n2 + rng.choice(nc, n_chain, replace=False),
                           np.arange(nc, n2), n2 + np.arange(nc, n2), np.arange(2 * n2, 2 * n2 + 4)])
    assert_jacobian_columns(model, x, J, cols)


def friction_rate(m, x, halves_only: bool = False) -> np.ndarray:
    """``f_I`` of an A5 model's friction split at ``x`` from its friction sets: ``M^-1`` times the friction forces on
    the velocity rows, their power on the work row ``D - P_fr``; ``halves_only``: the halves' friction alone."""
    n2, out = m.n2, np.zeros(m.size)
    v = x[n2:2 * n2]
    sets = m.friction_sets(x)[:1] if halves_only else m.friction_sets(x)
    for fs in sets:
        r = fs.forces(fs.S @ v)
        out[n2:2 * n2] -= m._masses[1] @ (fs.S.T @ r)
        out[2 * n2 + m.control.size + 2] += r @ (fs.S @ v)
    return out


def assert_friction_solve_all_is_backward_euler(m, states) -> None:
    """``m.friction_solve_all`` over 0.1 and 2 us from each state: positions and loop states unchanged, the velocity
    change ``h f_I(x1)`` to the solve's tolerance (set 1e-6 v0 by the caller), and the booked work the kinetic energy
    removed to round-off, written ``T(v*) - T(v) = -dv^T M (v* + dv / 2)`` with ``dv = v - v*``: the difference of
    the two kinetic energies themselves cancels (the shafts' spin energy is ~1e6 times what one step removes), and
    that round-off changed with the BLAS kernel (OPENBLAS_CORETYPE=Sandybridge failed a 1e-12 comparison)."""
    n2, iw = m.n2, 2 * m.n2 + m.control.size + 2
    M = m._masses[0]
    for x in states:
        for h in (1e-7, 2e-6):
            x1, _ = m.friction_solve_all(0.0, x, h)
            assert np.array_equal(x1[:n2], x[:n2]) and np.array_equal(x1[2 * n2:iw], x[2 * n2:iw])
            dv = x1[n2:2 * n2] - x[n2:2 * n2]
            assert np.abs(dv - h * friction_rate(m, x1)[n2:2 * n2]).max() <= 1e-6 * np.abs(dv).max()
            removed = -dv @ (M @ (x[n2:2 * n2] + 0.5 * dv))
            assert removed > 0 and x1[iw] - x[iw] == pytest.approx(removed, rel=1e-12)
