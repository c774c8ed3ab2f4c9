"""RODAS4 and RODAS5P (issue 19): orders 4 and 5, dense outputs of orders 3 and 4, non-autonomous terms, second-order structure,
sparse Jacobians, and tolerance proportionality on HIRES."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.integrate.stepping import Stepping, make_engine
from cvtfem.integrate.system import as_system
from cvtfem.problems import heat1d, hires, limit_cycle, oscillator, prothero_robinson, van_der_pol_stiff


METHODS = [("rodas4", 4), ("rodas5p", 5)]


def orders(method, p, ns):
    t_end = p.t_span[1]
    errs = [np.max(np.abs(solve(**p.solve_kwargs(), method=method, h=t_end / n).y[:, -1] - p.exact(t_end)))
            for n in ns]
    return np.log2(np.array(errs[:-1]) / errs[1:])


@pytest.mark.parametrize("method,order", METHODS)
def test_order_autonomous(method, order):
    assert np.all(np.abs(orders(method, limit_cycle(), [20, 40, 80, 160])[-2:] - order) < 0.15)


@pytest.mark.parametrize("method,order", METHODS)
def test_order_non_autonomous(method, order):
    """Prothero-Robinson with g = sin t: the F_t terms (weights d_i) carry the time dependence."""
    assert np.all(np.abs(orders(method, prothero_robinson(lam=-1.0, t_end=2.0), [10, 20, 40, 80]) - order) < 0.15)


@pytest.mark.parametrize("method,order", METHODS)
def test_dense_output_local_error_order(method, order):
    """The continuous extension is of order p - 1: its error inside one step falls like h^p; evaluated at
    one time or at several at once, the same values."""
    p = limit_cycle()
    errs = []
    for h in (0.2, 0.1, 0.05, 0.025):
        x0 = p.exact(0.3)
        engine = make_engine(method, as_system(p.fun, x0, jac=p.jac), 0.3, x0, 10.0, 1e-6, 1e-9, h=h)
        run = Stepping(engine, 0.3, x0, 10.0)
        run.step()
        ts = 0.3 + h * np.array([0.25, 0.5, 0.8])
        assert np.allclose(run.last.dense(ts)[:, 1], run.dense(ts[1]), rtol=1e-14, atol=0)
        errs.append(max(np.max(np.abs(run.dense(tq) - p.exact(tq))) for tq in ts))
    assert np.all(np.abs(np.log2(np.array(errs[:-1]) / errs[1:]) - order) < 0.25)


@pytest.mark.parametrize("method", ["rodas4", "rodas5p"])
@pytest.mark.parametrize("rtol", [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8])
def test_hires_error_tracks_tolerance(method, rtol):
    """Against the published reference, the achieved relative error stays within 10x rtol."""
    p = hires()
    res = solve(**p.solve_kwargs(), method=method, rtol=rtol, atol=1e-3 * rtol)
    err = np.max(np.abs(res.y[:, -1] - p.reference()) / np.abs(p.reference()))
    assert res.success and err < 10 * rtol


@pytest.mark.parametrize("method", ["rodas4", "rodas5p"])
def test_second_order_structure_van_der_pol_stiff(method):
    """n2 = 1 (reduced linear systems) on Van der Pol, eps = 1e-3: agrees with scipy Radau to 10 rtol."""
    p = van_der_pol_stiff(eps=1e-3)
    ref = solve(**p.solve_kwargs(), method="Radau", rtol=1e-9, atol=1e-9).y[:, -1]
    res = solve(**p.solve_kwargs(), method=method, rtol=1e-6, atol=1e-6)
    assert res.success and np.max(np.abs(res.y[:, -1] - ref) / np.abs(ref)) < 1e-5


@pytest.mark.parametrize("method", ["rodas4", "rodas5p"])
def test_sparse_jacobian_heat_equation(method):
    """N = 1000 with a sparse tridiagonal Jacobian (SuperLU): the exact semi-discrete solution to
    within 10x rtol, one LU per step attempt."""
    p = heat1d(N=1000, t_end=0.1)
    res = solve(**p.solve_kwargs(), method=method, rtol=1e-6, atol=1e-9)
    ex = p.exact(0.1)
    assert res.success and np.max(np.abs(res.y[:, -1] - ex)) < 1e-5 * np.max(np.abs(ex))
    assert res.stats["nlu"] == res.stats["nsteps"] + res.stats["nreject"]


@pytest.mark.parametrize("method", ["rodas4", "rodas5p"])
@pytest.mark.parametrize("rtol", [1e-6, 1e-8])
def test_event_times_on_the_dense_output(method, rtol):
    """Zero crossings of u = cos t (oscillator, 20 s, six events at pi/2 + k pi), located on the method's own
    continuous extension: within 10 rtol of the closed form."""
    p = oscillator(t_end=20.0)
    res = solve(**p.solve_kwargs(), method=method, rtol=rtol, atol=rtol, events=lambda t, x: x[0])
    te = res.t_events[0]
    assert len(te) == 6 and np.max(np.abs(te - (np.pi / 2 + np.pi * np.arange(6)))) < 10 * rtol
