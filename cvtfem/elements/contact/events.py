"""Event indicators and the discrete state of pin–sheave contacts (contact-models digest §7, §10.3).

Indicators are plain arrays over candidate contacts; a state changes where its indicator changes
sign. Hertz contacts (H1/H2) have two states (off/on), Coulomb contacts (C1/C2) three
(``FREE``, ``SLIDING``, ``STUCK`` of :mod:`cvtfem.elements.contact.impact`).
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.contact.impact import FREE, SLIDING, STUCK


def hertz_indicator(delta):
    """``e = Delta`` (m): up-crossing turns a Hertz contact on, down-crossing off; ``e = 0`` is off."""
    return np.asarray(delta, dtype=float)


def hertz_state(delta):
    """Contact flags of Hertz contacts: on where ``Delta > 0``."""
    return np.asarray(delta, dtype=float) > 0.0


def coulomb_indicators(state, delta, N, slip, reaction, v_star, f_star):
    """Indicator of the one transition each C1/C2 contact can take next (digest §7).

    ``FREE``: ``-Delta`` (m; negative once touching, impact follows). ``SLIDING``:
    ``min(N, |v_r| - v_r*)`` with ``N`` (N) and ``|v_r|`` ``slip`` (m/s): negative on release
    or on stick. ``STUCK``: ``min(N, f_* N - |R_*|)`` with ``reaction = |R_*|`` (N): negative on
    release or on slip. Mixed units per state; only the sign matters.
    """
    state = np.asarray(state)
    N = np.asarray(N, dtype=float)
    e_slide = np.minimum(N, np.asarray(slip, dtype=float) - v_star)
    e_stick = np.minimum(N, f_star * N - np.asarray(reaction, dtype=float))
    return np.where(state == FREE, -np.asarray(delta, dtype=float),
                    np.where(state == SLIDING, e_slide, e_stick))


def coulomb_switch(state, N, slip, reaction, v_star, f_star):
    """State after a C1/C2 event that did not start an impact: release (``N <= 0``) to ``FREE``,
    sliding to ``STUCK`` below ``v_r*``, stuck to ``SLIDING`` at ``|R_*| >= f_* N``."""
    state = np.asarray(state)
    N = np.asarray(N, dtype=float)
    slides = np.where(np.asarray(slip, dtype=float) < v_star, STUCK, SLIDING)
    sticks = np.where(np.asarray(reaction, dtype=float) >= f_star * N, SLIDING, STUCK)
    new = np.where(state == SLIDING, slides, np.where(state == STUCK, sticks, state))
    return np.where((state != FREE) & (N <= 0.0), FREE, new)


def crossing_fraction(e0, e1):
    """Fraction ``theta = e0/(e0 - e1)`` of a step where each indicator changes sign, ``inf`` where
    none does (digest §10.3); ``e = 0`` counts as negative ("off")."""
    e0, e1 = np.asarray(e0, dtype=float), np.asarray(e1, dtype=float)
    cross = (e0 > 0.0) != (e1 > 0.0)
    return np.where(cross, e0 / np.where(cross, e0 - e1, 1.0), np.inf)
