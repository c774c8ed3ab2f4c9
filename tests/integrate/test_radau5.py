"""Radau IIA(5) (issue 19): order 5, a collocation dense output of local order 4, agreement with scipy's
Radau and the published HIRES values, RADAU5's Jacobian reuse (far fewer Jacobians than steps, at no loss of
accuracy), sparse Jacobians, and the error tracking rtol through RADAU5's tolerance map."""
from functools import lru_cache

import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.integrate import solve
from cvtfem.integrate.stepping import Stepping, make_engine
from cvtfem.integrate.system import as_system
from cvtfem.problems import heat1d, hires, limit_cycle, prothero_robinson, van_der_pol_stiff


def global_orders(p, ns):
    t_end = p.t_span[1]
    errs = [np.max(np.abs(solve(**p.solve_kwargs(), method="radau5", h=t_end / n).y[:, -1] - p.exact(t_end)))
            for n in ns]
    return np.log2(np.array(errs[:-1]) / errs[1:])


def test_order_5_autonomous():
    assert np.all(np.abs(global_orders(limit_cycle(), [10, 20, 40])[-1:] - 5) < 0.2)


def test_order_5_non_autonomous():
    """Prothero-Robinson with lambda = -1, g = sin t: the stage times c_i h enter the collocation."""
    assert np.all(np.abs(global_orders(prothero_robinson(lam=-1.0, t_end=2.0), [5, 10, 20]) - 5) < 0.2)


def test_dense_output_local_error_order_4():
    """The collocation polynomial (degree 3) is exact at the step's end and O(h^4) inside it."""
    p = limit_cycle()
    errs = []
    for h in (0.2, 0.1, 0.05, 0.025):
        x0 = p.exact(0.3)
        engine = make_engine("radau5", as_system(p.fun, x0, jac=p.jac), 0.3, x0, 10.0, 1e-6, 1e-9, h=h)
        run = Stepping(engine, 0.3, x0, 10.0)
        run.step()
        ts = 0.3 + h * np.array([0.25, 0.5, 0.8])
        assert np.allclose(run.last.dense(ts)[:, 1], run.dense(ts[1]), rtol=1e-14, atol=0)
        assert np.allclose(run.dense(0.3 + h), run.x, rtol=1e-14, atol=1e-16)
        errs.append(max(np.max(np.abs(run.dense(tq) - p.exact(tq))) for tq in ts))
    assert np.all(np.abs(np.log2(np.array(errs[:-1]) / errs[1:]) - 4) < 0.3)


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_hires_published_values(rtol):
    """Within 10 rtol of the published HIRES reference (all 8 components, relative)."""
    p = hires()
    res = solve(**p.solve_kwargs(), method="radau5", rtol=rtol, atol=1e-3 * rtol)
    err = np.max(np.abs(res.y[:, -1] - p.reference()) / np.abs(p.reference()))
    assert res.success and err < 10 * rtol


@lru_cache(maxsize=None)
def vdp_reference() -> np.ndarray:
    """Van der Pol eps = 1e-6 at t = 2 from scipy's Radau at rtol 1e-7 (error ~1e-9 relative)."""
    p = van_der_pol_stiff(1e-6)
    return solve(**p.solve_kwargs(), method="Radau", rtol=1e-7, atol=1e-7).y[:, -1]


def test_van_der_pol_stiff_matches_scipy_radau_and_reuses_jacobians():
    """eps = 1e-6: the end state agrees with scipy's Radau to 10 rtol; the Jacobian is recomputed only after
    slow Newton solves (fewer than one per three steps) and each LU pair serves more than one attempt."""
    p = van_der_pol_stiff(1e-6)
    res = solve(**p.solve_kwargs(), method="radau5", rtol=1e-5, atol=1e-5)
    s = res.stats
    assert res.success and np.max(np.abs(res.y[:, -1] - vdp_reference()) / np.abs(vdp_reference())) < 1e-4
    assert s["njev"] < s["nsteps"] / 3
    assert s["nlu"] < 2 * (s["nsteps"] + s["nreject"])


def test_sparse_jacobian_heat_equation():
    """N = 1000, tridiagonal Jacobian (SuperLU, real and complex): the exact semi-discrete solution to 10 rtol."""
    p = heat1d(N=1000, t_end=0.1)
    res = solve(**p.solve_kwargs(), method="radau5", rtol=1e-6, atol=1e-9)
    ex = p.exact(0.1)
    assert res.success and np.max(np.abs(res.y[:, -1] - ex)) < 1e-5 * np.max(np.abs(ex))
    assert res.stats["njev"] <= 3   # a linear problem: Newton converges at once, J is never stale


def test_without_the_tolerance_map_far_more_accurate_than_asked():
    """The map is what brings the error to rtol: without it radau5 is 100x+ more accurate than asked at
    rtol 1e-8 on the limit cycle (and pays for it)."""
    p = limit_cycle()
    ex = p.exact(p.t_span[1])
    err = {prop: np.max(np.abs(solve(**p.solve_kwargs(), method="radau5", rtol=1e-8, atol=1e-8,
                                     proportional=prop).y[:, -1] - ex)) for prop in (True, False)}
    assert err[False] < 1e-2 * 1e-8 < err[True] < 10 * 1e-8


@pytest.mark.parametrize("method", ["radau5", "rodas4"])
def test_memory_restores_bit_for_bit(method):
    """A run rebuilt from :meth:`Stepping.state` after 40 steps continues bit for bit: radau5's kept Jacobian,
    LU step size, flags and collocation polynomial, and the predictive controller's memory, are in the state."""
    p = van_der_pol_stiff(1e-6)
    x0 = p.y0

    def stepping(t0, x, first_step=None):
        engine = make_engine(method, as_system(p.fun, x, jac=p.jac), t0, x, 2.0, 1e-6, 1e-6, first_step=first_step)
        return Stepping(engine, t0, x, 2.0)

    run = stepping(0.0, x0)
    for _ in range(40):
        assert run.step()
    state = run.state()
    assert {name for name, _ in run.fields()} == set(state)
    again = stepping(run.t, run.x.copy(), first_step=float(state["h"][0]))
    again.restore(state)
    for _ in range(30):
        run.step(), again.step()
        assert run.t == again.t and np.array_equal(run.x, again.x)
    for c in ("nfev", "njev", "nlu", "nreject"):
        assert run.counts[c] == again.counts[c], c


def spring_chain(n_mass: int = 40, k: float = 1e4, c: float = 1.0):
    """Fixed-free chain of unit masses (springs ``k`` N/m, dampers ``c`` N s/m), the last one forced:
    ``x = [u, v]`` with a sparse analytic Jacobian; 80 states, above ``DENSE_MAX``."""
    n = n_mass
    main = np.full(n, -2 * k)
    main[-1] = -k
    K = sp.diags([np.full(n - 1, k), main, np.full(n - 1, k)], [-1, 0, 1], format="csr")
    J = sp.bmat([[None, sp.identity(n)], [K, -c * sp.identity(n)]], format="csr")

    def rhs(t, x):
        return J @ x + np.concatenate([np.zeros(2 * n - 1), [np.sin(30 * t)]])

    x0 = np.concatenate([np.sin(np.linspace(0, np.pi, n)) * 1e-3, np.zeros(n)])
    return rhs, J, x0


def test_second_order_structure_reduced_systems():
    """80 states with n2 = 40 (real and complex LUs of the 40 x 40 ``v`` block, sparse) and without (n2 = 0,
    80 x 80): both agree with scipy's Radau (rtol 1e-9) to 10 rtol at t = 0.2 s."""
    rhs, J, x0 = spring_chain()
    kw = dict(jac=lambda t, x: J, jac_sparsity=J != 0)
    ref = solve(rhs, (0.0, 0.2), x0, method="Radau", rtol=1e-9, atol=1e-12, **kw).y[:, -1]
    for n2 in (40, 0):
        res = solve(rhs, (0.0, 0.2), x0, method="radau5", rtol=1e-6, atol=1e-9, n2=n2, **kw)
        err = np.max(np.abs(res.y[:, -1] - ref)) / np.max(np.abs(ref))
        assert res.success and err < 1e-5, (n2, err)
