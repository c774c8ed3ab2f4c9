"""Periodic-solver hard cases (issue 7): a non-convergent Newton-Kantorovich run reported with its
residual history, a very small backlash clearance, a very weak gap stiffness.

Network: the geared drivetrain of spec 12 #12 (motor - shaft - gear | backlash | gear - shaft -
load - soft clamp) at its resonance, 107 rad/s, where the mesh rattles through the clearance.
References are limits, approached at first order: clearance h -> 0 gives the linear network
with contact stiffness; gap stiffness k_in -> 0 gives the pure dead-zone law.
"""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.torsional import BACKLASH, build_network
from cvtfem.errors import NumericalError
from cvtfem.periodic.hb import load_harmonics, residual, solve_linear, solve_periodic

pytestmark = pytest.mark.hard

OMEGA, N_H = 107.0, 32
K_MESH = 1e6


def gear_pair(h: float = 2e-4, k_in: float = 3e4):
    Q = np.zeros((4, 2), complex)
    Q[0] = [40.0, 60.0]  # mean and first harmonic of the drive force, N
    return build_network([1.0, 0.5, 0.5, 2.0], [2.0, 1.0, 1.0, 20.0], [0, 1, 2, 3], [1, 2, 3, -1],
                         [2e5, K_MESH, 2e5, 5e4], d=[20, 30, 20, 60], law=[0, BACKLASH, 0, 0],
                         k_in=[0, k_in, 0, 0], h=[0, h, 0, 0], orders=(0, 1), Q=Q)


def _forces(net):
    sol = solve_periodic(net, OMEGA, N_H)
    assert sol.converged and sol.residuals[-1] <= 1e-10
    f = sol.link_forces()
    assert np.all(np.isfinite(f))
    return f


@pytest.mark.timeout(60)
def test_tiny_backlash_clearance_tends_to_the_linear_mesh():
    """h = 1e-8 .. 1e-12 m: Newton converges and the link forces approach the linear mesh
    (contact stiffness) at first order in h, down to 1e-8 of the force amplitude."""
    f_lin = solve_linear(gear_pair(h=0.0), OMEGA, N_H).link_forces()
    hs = np.array([1e-8, 1e-10, 1e-12])
    err = np.array([np.abs(_forces(gear_pair(h=h)) - f_lin).max() for h in hs])
    order = np.log(err[:-1] / err[1:]) / np.log(hs[:-1] / hs[1:])
    assert np.allclose(order, 1.0, atol=0.02), order
    assert err[-1] < 1e-8 * np.abs(f_lin).max()
    # the clearance really matters at 2e-4 m: the rattling mesh force peaks > 20 % higher
    assert _forces(gear_pair())[1].max() > 1.2 * f_lin[1].max()


@pytest.mark.timeout(60)
def test_very_weak_gap_stiffness_converges_to_the_dead_zone_limit():
    """k_in = 3 .. 1e-3 N/m (1e-5 .. 1e-9 of the contact stiffness) and 0 (a pure dead zone, no
    stiffness inside the gap): Newton with load continuation converges every time, and the forces
    approach the k_in = 0 limit at first order in k_in."""
    ref = _forces(gear_pair(k_in=0.0))
    ks = np.array([3.0, 3e-2, 3e-4])
    err = np.array([np.abs(_forces(gear_pair(k_in=k)) - ref).max() for k in ks])
    order = np.log(err[:-1] / err[1:]) / np.log(ks[:-1] / ks[1:])
    assert np.allclose(order, 1.0, atol=0.05), order
    assert err[-1] < 1e-6 * np.abs(ref).max()


@pytest.mark.timeout(60)
def test_non_convergent_newton_kantorovich_reports_its_residual_history():
    """A tolerance below the round-off floor (~1e-14) cannot be met: the run ends (no hang) with
    converged = False, a finite residual history, and a message that quotes the last residual."""
    net = gear_pair()
    sol = solve_periodic(net, OMEGA, N_H, tol=1e-17, max_iter=10)
    assert not sol.converged
    hist = np.array(sol.residuals)
    assert len(hist) >= 2 and np.all(np.isfinite(hist)) and np.all(hist > 1e-17)
    assert sol.message.startswith("Newton-Kantorovich did not converge at omega = 107 rad/s (")
    assert f"relative residual {hist[-1]:.3e} > tol 1.0e-17" in sol.message
    assert np.all(np.isfinite(sol.a))
    with pytest.raises(NumericalError, match="did not converge at omega = 107 rad/s"):
        solve_periodic(net, OMEGA, N_H, tol=1e-17, max_iter=10, raise_on_failure=True)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("kw", [{"max_iter": 2}, {"tol": 1e-17, "max_iter": 10}])
def test_failed_solution_is_the_iterate_its_message_describes(kw):
    """A failed run returns the iterate its message and ``residuals`` describe: the full-load
    residual of ``a`` equals the last reported one (it once returned a partial-load continuation
    iterate with relative residual 0.98 while quoting 4.952e-11)."""
    net = gear_pair()
    sol = solve_periodic(net, OMEGA, N_H, **kw)
    assert not sol.converged
    p = load_harmonics(net, N_H)
    r, _ = residual(net, OMEGA, sol.a, p, sol.samples, net.incidence())
    rel = np.linalg.norm(r) / np.linalg.norm(p)
    assert rel == pytest.approx(sol.residuals[-1], rel=1e-6)
