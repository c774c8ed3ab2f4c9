"""ROS34PW2, the Rosenbrock-W method of Rang & Angermann (2005): order 3 whatever the matrix A (exact, zero, a
constant wrong one, or a Jacobian reused over steps), also on a non-autonomous problem without a dF/dt term; an
embedded estimate of order 2 (local error O(h^3)); one Jacobian per ``jac_every`` steps and one LU per Jacobian
at a fixed step."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.integrate.base import Stats
from cvtfem.integrate.rosw import ALPHA, B, BHAT, GAMMAS, ROS34PW2
from cvtfem.integrate.system import as_system
from cvtfem.problems import limit_cycle, prothero_robinson


def _rate(errs):
    return np.log2(np.asarray(errs[:-1]) / np.asarray(errs[1:]))


@pytest.mark.parametrize("A", ["J", "zero", "stale"])
def test_order_three_for_any_matrix_on_a_non_autonomous_problem(A):
    """Prothero-Robinson ``y' = lambda (y - phi(t)) + phi'(t)`` depends on t; the method has no dF/dt term, which a
    W-method may leave out (it is part of A's error), so the global error at t = 1 still falls as h^3."""
    problem = prothero_robinson(lam=-5.0, t_end=1.0)
    jac = {"J": None, "zero": lambda t, y: np.zeros((1, 1)), "stale": lambda t, y: np.array([[-1.0]])}[A]
    kw = {} if jac is None else {"jac": jac}
    errs = [abs(solve(**{**problem.solve_kwargs(), **kw}, method="ros34pw2", h=h).y[0, -1] - problem.exact(1.0)[0])
            for h in (0.04, 0.02, 0.01)]
    assert np.all(np.abs(_rate(errs) - 3) <= 0.25), errs


@pytest.mark.parametrize("jac_every", [1, 3, 7])
def test_a_reused_jacobian_keeps_order_three(jac_every):
    """On the nonlinear limit cycle, the Jacobian of an earlier step reused for ``jac_every`` steps: global order
    3 against DOP853 at rtol 1e-13 (the rates approach 3 from above, 3.3-3.4 here for jac_every 7: at a fixed
    ``jac_every`` the age of A in time shrinks with h, so A's error shrinks too before the order-3 terms rule)."""
    problem = limit_cycle(r0=0.3)
    ref = solve(problem.fun, problem.t_span, problem.y0, method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
    errs = [np.abs(solve(**problem.solve_kwargs(), method="ros34pw2", h=h, jac_every=jac_every).y[:, -1] - ref).max()
            for h in (0.05, 0.025, 0.0125)]
    assert np.all(np.abs(_rate(errs) - 3) <= 0.45), errs


def test_the_embedded_estimate_is_second_order():
    """The estimate ``x1 - x1_hat`` (order 3 against order 2) is O(h^3) for an arbitrary A."""
    problem = limit_cycle(r0=0.3)
    system = as_system(problem.fun, problem.y0, jac=lambda t, y: np.array([[0.3, -1.0], [0.5, -2.0]]))
    est = [np.max(np.abs(ROS34PW2(system, Stats()).attempt(0.0, problem.y0, h).err)) for h in (0.02, 0.01)]
    assert abs(np.log2(est[0] / est[1]) - 3) <= 0.3


def test_published_tableau_is_consistent_and_stiffly_accurate():
    """sum b = sum bhat = 1 (order 1 of both solutions); b_i = alpha_4i + gamma_4i (the last stage value is the
    solution: stiffly accurate, so R(-inf) = 0, asserted in test_damping)."""
    assert B.sum() == pytest.approx(1.0, abs=1e-14) and BHAT.sum() == pytest.approx(1.0, abs=1e-14)
    assert np.allclose(B, ALPHA[3] + GAMMAS[3], atol=1e-14)


def test_one_jacobian_per_jac_every_steps_and_one_lu_each():
    """20 fixed steps with ``jac_every = 5``: 4 Jacobians, 4 LUs, 4 RHS calls and 4 solves per step."""
    problem = limit_cycle(r0=0.3)
    res = solve(problem.fun, (0.0, 2.0), problem.y0, method="ros34pw2", h=0.1, jac_every=5,
                jac=lambda t, y: np.array([[0.0, 1.0], [-1.0, 0.0]]))
    st = res.stats
    assert st["nsteps"] == 20 and st["njev"] == 4 and st["nlu"] == 4
    assert st["nsolve"] == 80 and st["nfev"] == 80


def test_bad_jac_every_is_refused():
    with pytest.raises(InputError, match="jac_every"):
        solve(lambda t, y: -y, (0.0, 1.0), [1.0], method="ros34pw2", h=0.1, jac_every=0)
