"""Events: bouncing-ball impact times against the closed form (issue 4 acceptance: 1e-10)."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.problems import bouncing_ball


@pytest.mark.parametrize("method,kw", [("rk4", {"h": 0.01}), ("dopri45", {"rtol": 1e-8}),
                                       ("trapezoidal", {"h": 0.01}), ("gbs", {"h": 0.05})])
def test_bouncing_ball_impacts_to_1e_10(method, kw):
    p = bouncing_ball(x0=1.0, v0=0.5, e=0.8, t_end=3.5)
    res = solve(**p.solve_kwargs(), method=method, **kw)
    assert res.success
    t_ev = res.t_events[0]
    exact = p.info["impacts"](len(t_ev))
    assert exact[-1] < 3.5 and p.info["impacts"](len(t_ev) + 1)[-1] > 3.5   # none missed
    assert np.max(np.abs(t_ev - exact)) < 1e-10
    assert res.stats["nevents"] == len(t_ev) == res.stats["ntruncated"]
    # after each impact the velocity is reversed and scaled by e
    v_after = res.y_events[0][:, 1]
    assert np.all(v_after < 0)


@pytest.mark.parametrize("h", [0.02, 0.01, 0.005])
def test_linear_location_error_bound(h):
    """The source's linear interpolation of a parabola: ``|dt| <= (g h^2 / 8) / |v*|``."""
    g, x0 = 9.81, 1.0
    p = bouncing_ball(x0=x0, g=g, t_end=0.5)
    res = solve(**p.solve_kwargs(), method="rk4", h=h, event_location="linear")
    err = abs(res.t_events[0][0] - p.info["impacts"](1)[0])
    bound = g * h * h / 8 / np.sqrt(2 * g * x0)
    assert 0 < err <= 1.01 * bound


def test_terminal_event_stops():
    p = bouncing_ball()
    ind, direction, _ = p.events
    res = solve(p.fun, p.t_span, p.y0, method="rk4", h=0.01, n2=1,
                events=(ind, direction, np.array([True])))
    assert res.status == 1 and abs(res.t[-1] - p.info["impacts"](1)[0]) < 1e-12


def test_simultaneous_events_switch_together():
    """Two identical balls hit the floor at the same time: one switch call with both fired."""
    calls = []

    def fun(t, x):
        return np.array([x[2], x[3], -9.81, -9.81])

    def switch(t, x, fired):
        calls.append(fired.copy())
        x[2:][fired] *= -0.5
        return x

    res = solve(fun, (0, 0.6), [1.0, 1.0, 0.0, 0.0], method="rk4", h=0.01, n2=2,
                events=(lambda t, x: x[:2], np.array([-1, -1]), np.array([False, False])),
                switch=switch)
    assert res.success and len(calls) == 1 and calls[0].all()
    assert np.allclose(res.t_events[0], res.t_events[1])


def test_zeno_accumulation_is_reported():
    p = bouncing_ball(e=0.5, t_end=5.0)
    res = solve(**p.solve_kwargs(), method="rk4", h=0.01)
    assert res.status == -1 and "Zeno" in res.message
    assert abs(res.t[-1] - p.info["t_zeno"]) < 1e-6


def test_scipy_method_with_events_matches():
    p = bouncing_ball(t_end=0.5)
    ind, direction, _ = p.events
    res = solve(p.fun, p.t_span, p.y0, method="RK45", rtol=1e-10, atol=1e-12,
                events=(ind, direction, np.array([True])))
    assert res.status == 1 and abs(res.t_events[0][0] - p.info["impacts"](1)[0]) < 1e-8


@pytest.mark.parametrize("bad", [-1, 2.5, True, "4"])
def test_event_samples_must_be_a_non_negative_integer(bad):
    with pytest.raises(InputError, match="`event_samples` must be an integer >= 0"):
        solve(lambda t, y: -y, (0.0, 1.0), [1.0], method="rk4", h=0.1, events=lambda t, y: y[0] - 0.5,
              event_samples=bad)
