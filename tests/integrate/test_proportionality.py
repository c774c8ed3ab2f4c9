"""Tolerance proportionality (issue 19): the achieved error of the order-2 methods stays within 10x of rtol
because they control the local error against ``rtol_int = c rtol^(3/2)`` (``proportional_ratio``); with
the plain per-step control (``proportional=False``) the trapezoidal rule's error on HIRES grows like
``rtol^(2/3)`` and leaves the band. Error: max over components of ``|y - y_ref| / |y_ref|`` at the end time,
atol a fixed fraction of rtol per problem (as ``studies/integrators/bench_vs_radau.py``)."""
from functools import lru_cache

import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.integrate.base import proportional_ratio
from cvtfem.integrate.methods import METHODS
from cvtfem.integrate.system import as_system
from cvtfem.problems import hires, limit_cycle, robertson, van_der_pol_stiff

PROBLEMS = {"hires": (hires, 1e-3, 1e-15), "vdp": (lambda: van_der_pol_stiff(1e-6), 1.0, 1e-12),
            "robertson": (lambda: robertson(1e5), 1e-8, 1e-20)}


@lru_cache(maxsize=None)
def reference(name):
    """HIRES: the published values (all 8 components); the others scipy Radau at rtol 1e-12."""
    make, _, atol_ref = PROBLEMS[name]
    p = make()
    if p.y_ref is not None:
        return p.y_ref
    return solve(**p.solve_kwargs(), method="Radau", rtol=1e-12, atol=atol_ref).y[:, -1]


def error_over_rtol(name, method, rtol, **kw):
    make, atol_factor, _ = PROBLEMS[name]
    res = solve(**make().solve_kwargs(), method=method, rtol=rtol, atol=atol_factor * rtol, **kw)
    assert res.success, res.message
    ref = reference(name)
    return float(np.max(np.abs(res.y[:, -1] - ref) / np.abs(ref))) / rtol


def test_ratio_is_the_order_2_tolerance_map():
    assert proportional_ratio(1e-6, 2, 0.5) == pytest.approx(0.5e-3)
    assert proportional_ratio(1e-6, 4, 1.0) == pytest.approx(10 ** -1.5)
    assert proportional_ratio(0.5, 2, 10.0) == 1.0   # never looser than asked


@pytest.mark.parametrize("method", ["trapezoidal", "sw24", "rkc"])
def test_hires_error_tracks_rtol(method):
    ratios = [error_over_rtol("hires", method, r) for r in (1e-3, 1e-4)]
    assert all(0.01 < q < 10 for q in ratios), ratios


def test_without_the_map_the_trapezoidal_error_leaves_the_band():
    """The check above can fail: the per-step control of the same method gives 400-900x rtol."""
    assert error_over_rtol("hires", "trapezoidal", 1e-5, proportional=False) > 100


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PROBLEMS))
@pytest.mark.parametrize("method", ["trapezoidal", "sw24"])
def test_error_tracks_rtol_over_four_decades(method, name):
    ratios = [error_over_rtol(name, method, r) for r in (1e-3, 1e-4, 1e-5, 1e-6)]
    assert all(q < 10 for q in ratios), ratios


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PROBLEMS))
@pytest.mark.parametrize("method", ["rodas4", "rodas5p", "w1-extrapolation"])
def test_higher_order_methods_track_rtol_to_1e_8(method, name):
    ratios = [error_over_rtol(name, method, r) for r in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)]
    assert all(q < 10 for q in ratios), ratios


def adaptive_methods() -> dict[str, int]:
    """Every registered native method with an error estimate, with its order (theta at its default 1/2 is
    the trapezoidal rule, so left out)."""
    out = {}
    for name, cls in METHODS.items():
        if getattr(cls, "needs_split", False):           # splitting methods run only on a system with a StiffSplit
            continue
        stepper = cls(as_system(lambda t, y: -y, np.ones(2)))
        if stepper.error_order is not None and name != "theta":
            out[name] = stepper.order
    return out


#: order >= 2 methods that take over a second here (the tolerance map makes order 2 dear at rtol 1e-8)
SLOW_ON_LIMIT_CYCLE = {"sw24", "trapezoidal", "rkc", "rock2"}
CHEAP = [m for m, order in adaptive_methods().items() if order >= 2 and m not in SLOW_ON_LIMIT_CYCLE]


def limit_cycle_error_over_rtol(method: str) -> list[float]:
    """Max absolute error at t = 2 over rtol (atol = rtol), closed-form solution, rtol 1e-3 ... 1e-8."""
    p = limit_cycle(0.3, 2.0)
    out = []
    for rtol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        res = solve(**p.solve_kwargs(), method=method, rtol=rtol, atol=rtol)
        assert res.success, res.message
        out.append(float(np.max(np.abs(res.y[:, -1] - p.exact(2.0)))) / rtol)
    return out


def test_every_adaptive_method_is_listed():
    """The lists below cover every registered method with an estimate; order 1 is implicit Euler alone."""
    methods = adaptive_methods()
    assert set(CHEAP) | SLOW_ON_LIMIT_CYCLE | {"implicit-euler"} == set(methods)
    assert [m for m, order in methods.items() if order < 2] == ["implicit-euler"]


@pytest.mark.parametrize("method", CHEAP)
def test_error_within_10_rtol_on_the_limit_cycle(method):
    """Issue 19: the achieved error of every adaptive method of order >= 2 stays below 10 rtol over rtol
    1e-3 ... 1e-8 (measured 0.02-6; some are far more accurate than asked: docs/integrators.md)."""
    ratios = limit_cycle_error_over_rtol(method)
    assert max(ratios) < 10, ratios


@pytest.mark.slow
@pytest.mark.parametrize("method", sorted(SLOW_ON_LIMIT_CYCLE))
def test_error_within_10_rtol_on_the_limit_cycle_order_2(method):
    ratios = limit_cycle_error_over_rtol(method)
    assert max(ratios) < 10, ratios


@pytest.mark.slow
def test_implicit_euler_is_not_proportional():
    """Order 1 (the known exception): holding its local error O(h^2) at the tolerance gives a global error
    ~ rtol^(1/2), 44 x rtol at 1e-3 and 1.4e4 x rtol at 1e-8 on the limit cycle; a proportional map would need
    h ~ rtol, 1e8 steps per second at rtol 1e-8."""
    ratios = limit_cycle_error_over_rtol("implicit-euler")
    assert ratios[0] > 10 and np.log10(ratios[-1] / ratios[0]) / 5 == pytest.approx(0.5, abs=0.1)
