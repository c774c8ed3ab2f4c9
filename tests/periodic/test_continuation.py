"""Arclength continuation through folds and Floquet stability."""
from __future__ import annotations

import numpy as np

from cvtfem.elements.torsional import BACKLASH, build_network
from cvtfem.periodic.continuation import continuation
from cvtfem.periodic.hb import solve_linear, solve_periodic
from cvtfem.periodic.stability import floquet


def oscillator():
    """1-DOF smoothed backlash oscillator, preloaded into contact (spec 12 #11), eps = 0.03."""
    return build_network([1.0], [0.05], [0], [-1], [1.0], law=[BACKLASH], k_in=[0.03], h=[1.0],
                         orders=(0, 1), Q=[[0.8, 0.1]])


def test_floquet_multipliers_of_linear_oscillator_are_exact():
    m, b, k, w = 2.0, 0.4, 50.0, 3.0
    net = build_network([m], [b], [0], [-1], [k], orders=(1,), Q=[[1.0]])
    fl = floquet(solve_linear(net, w, 3), rtol=1e-11)
    lam = np.roots([m, b, k])
    ref = np.exp(lam * 2 * np.pi / w)
    assert np.allclose(np.sort_complex(fl.multipliers), np.sort_complex(ref), rtol=1e-8, atol=1e-12)
    assert fl.stable


def test_continuation_passes_folds_and_stability_changes_there():
    net = oscillator()
    branch = continuation(net, 0.5, 1.5, 24, ds=0.05, max_steps=400)
    assert branch.message == "reached omega_stop"
    omega = branch.omega
    # softening backlash resonance: the branch turns back (omega decreases) between the folds
    assert len(branch.turning_points) >= 2
    t0, t1 = branch.turning_points[:2]
    assert omega[t0] > omega[t1] and np.all(np.diff(omega[t0 + 1:t1 + 1]) < 0)
    # every point solves the harmonic-balance equations: re-solving from it converges at once
    k = (t0 + t1) // 2
    again = solve_periodic(net, omega[k], 24, a0=branch.solutions[k].a)
    assert again.converged and again.iterations <= 1
    # saddle-node folds: Floquet stability flips exactly where omega turns (within one step)
    for t in (t0, t1):
        window = np.array([floquet(s).stable for s in branch.solutions[t - 3:t + 4]])
        flips = np.flatnonzero(window[1:] != window[:-1]) + t - 3
        assert len(flips) == 1 and abs(flips[0] - t) <= 1
    assert floquet(branch.solutions[0]).stable and not floquet(branch.solutions[k]).stable
