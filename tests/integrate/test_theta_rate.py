"""Adaptive theta-method with the contraction-rate Newton stop (``newton_stop="auto"``)."""
import numpy as np
import pytest

from cvtfem.integrate import solve


def test_exponential_growth_to_e60_finishes():
    """``y' = y`` to ``e^60``: the Newton test scales with ``|y|`` (the absolute 1e-10 floor of
    ``stop="source"`` stopped this run at t = 14.59 s, y = 2.2e6, below round-off of G)."""
    res = solve(lambda t, y: y, (0.0, 60.0), [1.0], method="trapezoidal", rtol=1e-6, atol=1e-9,
                jac=lambda t, y: np.eye(1))
    assert res.success, res.message
    # relative local errors add up on y' = y: the global one stays below nsteps * rtol
    assert abs(res.y[0, -1] / np.exp(60.0) - 1) < res.stats["nsteps"] * 1e-6


def stiff_oscillatory(k3: float = 2e3):
    """Three masses: a slow mode (~5 rad/s, cubic spring ``k3``) and two lightly damped stiff
    modes (3e4 and 8e4 rad/s, damping ratio ~5e-3), like the band's elastic modes; forced slowly
    (``100 sin 3t`` on the first mass)."""
    w = np.array([5.0, 3e4, 8e4])
    Q, _ = np.linalg.qr(np.array([[1.0, 0.3, 0.1], [0.2, 1.0, 0.4], [0.1, 0.5, 1.0]]))
    K = Q @ np.diag(w ** 2) @ Q.T
    C = Q @ np.diag(2 * np.array([0.05, 5e-3, 5e-3]) * w) @ Q.T

    def fun(t, x):
        u, v = x[:3], x[3:]
        a = -K @ u - C @ v
        a[0] += 100.0 * np.sin(3.0 * t) - k3 * u[0] ** 3
        return np.concatenate([v, a])

    def jac(t, x):
        J = np.zeros((6, 6))
        J[:3, 3:] = np.eye(3)
        J[3:, :3] = -K
        J[3:, 3:] = -C
        J[3, 0] -= 3 * k3 * x[0] ** 2
        return J

    return fun, jac, np.zeros(6)   # at rest: the stiff modes start on the slow manifold


def test_stiff_oscillatory_newton_statistics_and_accuracy():
    """Jacobian reused over many steps, <= 3 chord iterations per attempted step, and the global
    error proportional to the tolerance (``rtol^(2/3)`` for order 2: 100x tighter -> ~21x smaller)
    against Radau at rtol 1e-8 (which agrees with Radau at 1e-6 to 3e-8)."""
    fun, jac, x0 = stiff_oscillatory()
    ref = solve(fun, (0.0, 2.0), x0, method="Radau", rtol=1e-8, atol=1e-10, jac=jac)
    scale = np.max(np.abs(ref.y[0]))
    errs = []
    for rtol in (1e-3, 1e-5):
        res = solve(fun, (0.0, 2.0), x0, method="trapezoidal", rtol=rtol, atol=1e-2 * rtol, jac=jac, n2=3)
        assert res.success, res.message
        st = res.stats
        assert st["njev"] < 0.05 * st["nsteps"]
        assert st["nnewton"] <= 3 * (st["nsteps"] + st["nreject"])
        assert st["nreject"] < 0.3 * st["nsteps"]
        errs.append(abs(res.y[0, -1] - ref.y[0, -1]) / scale)
    assert errs[0] < 0.1
    assert errs[1] < errs[0] / 10


def test_source_stopping_rule_stays_available():
    """``newton_stop="source"``: line search and (2.23) also in adaptive runs; same solution."""
    fun, jac, x0 = stiff_oscillatory()
    a = solve(fun, (0.0, 0.5), x0, method="trapezoidal", rtol=1e-5, atol=1e-7, jac=jac, n2=3)
    b = solve(fun, (0.0, 0.5), x0, method="trapezoidal", rtol=1e-5, atol=1e-7, jac=jac, n2=3,
              newton_stop="source")
    assert a.success and b.success
    assert abs(a.y[0, -1] - b.y[0, -1]) < 1e-3


def test_linearised_predictor_avoids_newton_failures_on_band_4dof():
    """band-4dof closed loop at rtol 1e-2 (stiff real modes up to 4.9e5 1/s): the explicit-Euler
    predictor, off by ``h lambda ~ 1e3`` in the stiff components, makes most Newton solves fail
    (and each failure costs a Jacobian); the adaptive default (linearised predictor) does not,
    and the outputs stay within the tolerance of a Radau reference. Per-step control
    (``proportional=False``): the long steps of a loose tolerance are the case in point."""
    from cvtfem.analysis.study_problem import scene_problem

    p = scene_problem("band-4dof", 0.1, ref_rtol=1e-8)
    kw = dict(method="trapezoidal", rtol=1e-2, atol=1e-4, proportional=False)
    euler = solve(**p.solve_kwargs(), predictor="euler", **kw)
    auto = solve(**p.solve_kwargs(), **kw)
    assert euler.success and auto.success
    assert euler.stats["nnewton_fail"] > 0.3 * euler.stats["nsteps"]
    assert auto.stats["nnewton_fail"] <= 0.1 * auto.stats["nsteps"]
    assert auto.stats["njev"] <= 5
    assert p.error(auto) < 1e-3
