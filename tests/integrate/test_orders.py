"""Measured orders match the nominal ones within 0.3 (issue 4 acceptance).

Local errors of one step from the closed-form limit-cycle problem; the effective order
``p~ = d ln e / d ln h - 1`` (spec (2.8)) between the two smallest steps.
"""
import numpy as np
import pytest

from cvtfem.integrate import solve

from cvtfem.integrate.study import effective_order, local_errors
from cvtfem.problems import limit_cycle, prothero_robinson

CASES = [  # method, options, nominal order, step sizes
    ("euler", {}, 1, [0.02, 0.01]),
    ("rk4", {}, 4, [0.1, 0.05]),
    ("dopri45", {}, 5, [0.1, 0.05]),
    ("dopri56", {}, 6, [0.2, 0.1]),
    ("dopri78", {}, 8, [0.4, 0.2]),
    ("dopri45", {"propagate": "low"}, 4, [0.1, 0.05]),
    ("gbs", {"stages": 2}, 4, [0.1, 0.05]),
    ("gbs", {"stages": 3}, 6, [0.2, 0.1]),
    ("gbs", {"stages": 4}, 8, [0.4, 0.2]),
    ("gbs-smooth", {"stages": 2}, 4, [0.1, 0.05]),
    ("gbs-smooth", {"stages": 3}, 6, [0.2, 0.1]),
    ("gbs", {"stages": 3, "sequence": "romberg"}, 6, [0.2, 0.1]),
    ("gbs", {"stages": 3, "sequence": "bulirsch"}, 6, [0.2, 0.1]),
    ("euler-extrapolation", {"stages": 2}, 2, [0.05, 0.025]),
    ("euler-extrapolation", {"stages": 4}, 4, [0.1, 0.05]),
    ("w1", {"d": 1.0}, 1, [0.02, 0.01]),
    ("w1-extrapolation", {"d": 1.0, "stages": 3}, 3, [0.05, 0.025]),
    ("sw24", {"d": 0.25}, 2, [0.05, 0.025]),
    ("sw24", {"d": 1.0}, 2, [0.05, 0.025]),
    ("ros34pw2", {}, 3, [0.1, 0.05]),
    ("trapezoidal", {}, 2, [0.05, 0.025]),
    ("trapezoidal", {"newton": "exact"}, 2, [0.05, 0.025]),
    ("implicit-euler", {}, 1, [0.02, 0.01]),
    ("theta", {"alpha": 0.3}, 1, [0.02, 0.01]),
    ("rkc", {"stages": 5}, 2, [0.05, 0.025]),
    ("rkc", {"stages": 20}, 2, [0.1, 0.05]),
    ("rock2", {"stages": 5}, 2, [0.1, 0.05]),
    ("rock2", {"stages": 50}, 2, [0.1, 0.05]),
    ("rock4", {"stages": 5}, 4, [0.1, 0.05]),
    ("rock4", {"stages": 30}, 4, [0.4, 0.2]),
]


@pytest.mark.parametrize("method,options,order,hs", CASES,
                         ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_effective_order(method, options, order, hs):
    problem = limit_cycle(r0=0.3)
    errs = local_errors(problem, method, hs, **options)
    assert np.all(errs > 1e-14), "errors at round-off level cannot show an order"
    p = effective_order(hs, errs)[-1]
    assert abs(p - order) <= 0.3, (p, errs)


@pytest.mark.parametrize("A", ["J", "zero", "stale"])
def test_sw24_order_two_for_any_matrix(A):
    """W-method property (spec §4.1, §12 case 5): order 2 whatever A; A = 0 is explicit."""
    problem = prothero_robinson(lam=-5.0, t_end=1.0)
    jac = {"J": None, "zero": lambda t, y: np.zeros((1, 1)), "stale": lambda t, y: np.array([[-1.0]])}[A]
    hs = [0.02, 0.01]
    kw = {} if jac is None else {"jac": jac}
    errs = []
    for h in hs:   # global error at t = 1
        res = solve(**{**problem.solve_kwargs(), **kw}, method="sw24", h=h)
        errs.append(abs(res.y[0, -1] - problem.exact(1.0)[0]))
    assert abs(np.log(errs[0] / errs[1]) / np.log(2) - 2) <= 0.3


def test_sw24_error_estimate_is_third_order():
    """The embedded estimate (2.13) is O(h^3) for an arbitrary A (its O(h) terms cancel)."""
    from cvtfem.integrate.base import Stats
    from cvtfem.integrate.system import as_system
    from cvtfem.integrate.wmethods import SW24
    problem = limit_cycle(r0=0.3)
    system = as_system(problem.fun, problem.y0, jac=lambda t, y: np.array([[0.3, -1.0], [0.5, -2.0]]))
    est = []
    hs = [0.02, 0.01]
    for h in hs:
        st = SW24(system, Stats())
        est.append(np.max(np.abs(st.attempt(0.0, problem.y0, h).err)))
    assert abs(np.log(est[0] / est[1]) / np.log(2) - 3) <= 0.3
