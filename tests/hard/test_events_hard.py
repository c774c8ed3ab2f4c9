"""Event hard cases (issue 7): simultaneous events, chattering (Zeno accumulation), an event in
the very first and in the very last step.

References are closed forms of falling and bouncing balls (``x'' = -g``, impact ``v -> -e v``):
first impact at ``sqrt(2 x0 / g)`` from rest, impacts accumulating at
``t1 + 2 e V1 / (g (1 - e))``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.problems import bouncing_ball

pytestmark = pytest.mark.hard

G = 9.81


def _balls(n: int, e: float, calls: list):
    """n balls (n2 = n) falling to the floor; every call of the automaton is recorded."""
    def fun(t, x):
        return np.concatenate([x[n:], np.full(n, -G)])

    def indicators(t, x):
        return x[:n].copy()

    def switch(t, x, fired):
        calls.append((t, fired.copy()))
        x[n:][fired] *= -e
        return x

    return dict(fun=fun, n2=n, events=(indicators, -np.ones(n, int), np.zeros(n, bool)), switch=switch)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method, kw", [("dopri45", {"rtol": 1e-8}), ("rk4", {"h": 0.01}),
                                        ("trapezoidal", {"h": 0.01})])
def test_simultaneous_events_fire_together_once(method, kw):
    """Two identical balls and one dropped from 4x the height: the pair hits at sqrt(2/g) in one
    automaton call with both indicators, the third alone at sqrt(8/g)."""
    calls: list = []
    x0 = np.array([1.0, 1.0, 4.0, 0.0, 0.0, 0.0])
    res = solve(**_balls(3, 0.8, calls), t_span=(0.0, 1.0), y0=x0, method=method, **kw)
    assert res.status == 0 and np.all(np.isfinite(res.y))
    t1, t3 = math.sqrt(2 / G), math.sqrt(8 / G)
    assert len(calls) == 2
    assert calls[0][1].tolist() == [True, True, False] and calls[1][1].tolist() == [False, False, True]
    assert calls[0][0] == pytest.approx(t1, abs=1e-12) and calls[1][0] == pytest.approx(t3, abs=1e-12)
    assert res.t_events[0].tolist() == res.t_events[1].tolist() == [calls[0][0]]
    # after the switch both balls rebound with e V1 (same state up to round-off)
    assert np.allclose(res.y[0], res.y[1], rtol=0, atol=1e-12) and np.allclose(res.y[3], res.y[4], rtol=0, atol=1e-12)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method, kw", [("dopri45", {"rtol": 1e-9, "atol": 1e-12}), ("rk4", {"h": 1e-3})])
def test_chattering_impacts_stop_at_the_zeno_point_with_a_clear_status(method, kw):
    """A bouncing ball with e = 0.5 chatters ever faster: the run must neither hang nor return
    NaN; it stops with status -1 and a Zeno message at the closed-form accumulation time."""
    ball = bouncing_ball(x0=1.0, e=0.5, t_end=3.0)
    res = solve(**ball.solve_kwargs(), method=method, **kw)
    t_zeno = ball.info["t_zeno"]
    assert res.status == -1 and "(Zeno behaviour)" in res.message
    t_stop = float(res.message.split("accumulate at t = ")[1].split()[0])
    assert t_stop == pytest.approx(t_zeno, abs=1e-6)
    assert np.all(np.isfinite(res.y)) and res.t[-1] <= t_zeno + 1e-6
    n = len(res.t_events[0])
    assert np.allclose(res.t_events[0][:10], ball.info["impacts"](n)[:10], atol=1e-9)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method, kw", [("dopri45", {"rtol": 1e-8}), ("rk4", {"h": 0.01}),
                                        ("implicit-euler", {"h": 0.01})])
def test_event_inside_the_very_first_step(method, kw):
    """A ball 1e-9 m above the floor moving down at 1 m/s hits it at t = 1e-9 s (to O(g t^2)):
    the crossing inside the first step is located and the rebound happens there."""
    calls: list = []
    res = solve(**_balls(1, 0.8, calls), t_span=(0.0, 0.1), y0=[1e-9, -1.0], method=method, **kw)
    assert res.status == 0 and len(calls) == 1
    assert calls[0][0] == pytest.approx(1e-9, rel=1e-6)
    # after the rebound (v = +0.8 m/s) the ball flies: x(0.1) = 0.8 (0.1 - 1e-9) - g (0.1 - 1e-9)^2 / 2
    tf = 0.1 - 1e-9
    if method != "implicit-euler":     # first order: only the exact methods are checked in value
        assert res.y[0, -1] == pytest.approx(0.8 * tf - G * tf * tf / 2, rel=1e-6)
    assert res.y[0, -1] > 0


@pytest.mark.timeout(60)
@pytest.mark.parametrize("method, n_steps", [("rk4", 10), ("rk4", 7), ("trapezoidal", 10)])
def test_event_at_the_very_last_step(method, n_steps):
    """The first impact sqrt(2/g) lies 1e-9 s before t_end, inside the last step: the event is
    found once, the tiny rest of the step is completed, and the run ends normally.
    (With t_end exactly at the impact, whether x(t_end) rounds to +1e-17 or -1e-17 decides if
    the event fires: a tie that no locator can break.)"""
    t1 = math.sqrt(2 / G)
    t_end = t1 + 1e-9
    calls: list = []
    res = solve(**_balls(1, 0.8, calls), t_span=(0.0, t_end), y0=[1.0, 0.0], method=method, h=t_end / n_steps)
    assert res.status == 0 and res.t[-1] == pytest.approx(t_end, abs=1e-14)
    assert len(calls) == 1 and calls[0][0] == pytest.approx(t1, abs=1e-12)
    assert len(res.t_events[0]) == 1 and np.all(np.isfinite(res.y))
    assert res.y[1, -1] == pytest.approx(0.8 * math.sqrt(2 * G) - G * 1e-9, rel=1e-9)   # rebounded
