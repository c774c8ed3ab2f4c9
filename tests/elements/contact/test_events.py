"""Event indicators and discrete contact states (contact-models digest §7, §10.3)."""
from __future__ import annotations

import numpy as np

from cvtfem.elements.contact.events import (coulomb_indicators, coulomb_switch, crossing_fraction,
                                            hertz_indicator, hertz_state)
from cvtfem.elements.contact.impact import FREE, SLIDING, STUCK


def test_hertz_onset_and_release_located_by_linear_interpolation():
    """A pin end approaching at 10 m/s and leaving: Delta(t) linear in each step, so the crossing
    fraction is exact; Delta = 0 is 'off' (grazing without penetration does not switch on)."""
    t0, h = 0.0, 1e-6
    delta = lambda t: 10.0 * (t - 0.37e-6)        # noqa: E731
    e0, e1 = hertz_indicator(delta(t0)), hertz_indicator(delta(t0 + h))
    theta = crossing_fraction(e0, e1)
    assert abs(t0 + h * theta - 0.37e-6) < 1e-21
    assert not hertz_state(0.0) and hertz_state(1e-300)
    e0 = np.array([-1e-9, 0.0, 1e-9, 2e-9, -1e-9])
    e1 = np.array([1e-9, 1e-9, 0.0, 3e-9, -2e-9])
    th = crossing_fraction(e0, e1)
    assert np.allclose(th[:3], [0.5, 0.0, 1.0]) and np.all(np.isinf(th[3:]))


def test_coulomb_automaton():
    """F -> (touch) ; S -> F on N < 0, S -> K below v_r*; K -> F on N < 0, K -> S at |R_*| = f_* N."""
    state = np.array([FREE, SLIDING, SLIDING, SLIDING, STUCK, STUCK, STUCK])
    delta = np.array([1e-9, 0, 0, 0, 0, 0, 0.0])
    N = np.array([0.0, -1.0, 10.0, 10.0, -1.0, 10.0, 10.0])
    slip = np.array([0.0, 1.0, 1e-6, 1.0, 0.0, 0.0, 0.0])
    reaction = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 5.0, 1.0])
    e = coulomb_indicators(state, delta, N, slip, reaction, v_star=1e-4, f_star=0.2)
    assert np.array_equal(e < 0, [True, True, True, False, True, True, False])
    new = coulomb_switch(state, N, slip, reaction, v_star=1e-4, f_star=0.2)
    assert np.array_equal(new, [FREE, FREE, STUCK, SLIDING, FREE, SLIDING, STUCK])
