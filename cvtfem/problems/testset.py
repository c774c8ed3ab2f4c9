"""IVP test-set problems with published reference solutions: HIRES, Pleiades and Robertson.

References: Mazzia & Magherini, *Test Set for IVP Solvers* (release 2.4, Univ. Bari);
Hairer & Wanner, *Solving ODEs II*, §IV.10 (HIRES) and Hairer-Norsett-Wanner I, §II.10
(Pleiades). Reference values are the test set's.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.problems.base import Problem

__all__ = ["hires", "pleiades", "robertson"]

HIRES_REF = np.array([0.7371312573325668e-3, 0.1442485726316185e-3, 0.5888729740967575e-4,
                      0.1175651343283149e-2, 0.2386356198831331e-2, 0.6238968252742796e-2,
                      0.2849998395185769e-2, 0.2850001604814231e-2])
PLEIADES_REF = np.array([0.3706139143970502, 3.237284092057233, -3.222559032418324,
                         0.6597091455775310, 0.3425581707156584, 1.562172101400631,
                         -0.7003092922212495, -3.943437585517392, -3.271380973972550,
                         5.225081843456543])


def hires() -> Problem:
    """HIRES: 8 stiff chemical kinetics equations, ``t`` in [0, 321.8122]."""
    def fun(t, y):
        y1, y2, y3, y4, y5, y6, y7, y8 = y
        return np.array([
            -1.71 * y1 + 0.43 * y2 + 8.32 * y3 + 0.0007,
            1.71 * y1 - 8.75 * y2,
            -10.03 * y3 + 0.43 * y4 + 0.035 * y5,
            8.32 * y2 + 1.71 * y3 - 1.12 * y4,
            -1.745 * y5 + 0.43 * y6 + 0.43 * y7,
            -280.0 * y6 * y8 + 0.69 * y4 + 1.71 * y5 - 0.43 * y6 + 0.69 * y7,
            280.0 * y6 * y8 - 1.81 * y7,
            -280.0 * y6 * y8 + 1.81 * y7])

    def jac(t, y):
        J = np.zeros((8, 8))
        J[0, :3] = [-1.71, 0.43, 8.32]
        J[1, :2] = [1.71, -8.75]
        J[2, 2:5] = [-10.03, 0.43, 0.035]
        J[3, 1:4] = [8.32, 1.71, -1.12]
        J[4, 4:7] = [-1.745, 0.43, 0.43]
        J[5, 3:8] = [0.69, 1.71, -0.43 - 280 * y[7], 0.69, -280 * y[5]]
        J[6, 5:8] = [280 * y[7], -1.81, 280 * y[5]]
        J[7, 5:8] = [-280 * y[7], 1.81, -280 * y[5]]
        return J

    y0 = np.array([1.0, 0, 0, 0, 0, 0, 0, 0.0057])
    return Problem("hires", fun, y0, (0.0, 321.8122), jac=jac, y_ref=HIRES_REF,
                   ref_index=np.arange(8))


def pleiades() -> Problem:
    """Pleiades: 7 bodies in the plane, masses ``m_i = i``, ``t`` in [0, 3].

    State ``[x(7), y(7), x'(7), y'(7)]``: second-order structure with ``n2 = 14``; the reference
    covers ``y1..y10`` (all ``x`` and ``y_1..y_3``).
    """
    m = np.arange(1, 8, dtype=float)

    def fun(t, s):
        x, y, vx, vy = s[:7], s[7:14], s[14:21], s[21:]
        dx = x[None, :] - x[:, None]
        dy = y[None, :] - y[:, None]
        r3 = (dx * dx + dy * dy) ** 1.5
        np.fill_diagonal(r3, np.inf)
        ax = (m[None, :] * dx / r3).sum(axis=1)
        ay = (m[None, :] * dy / r3).sum(axis=1)
        return np.concatenate([vx, vy, ax, ay])

    y0 = np.concatenate([[3, 3, -1, -3, 2, -2, 2], [3, -3, 2, 0, 0, -4, 4],
                         [0, 0, 0, 0, 0, 1.75, -1.5], [0, 0, 0, -1.25, 1, 0, 0]]).astype(float)
    return Problem("pleiades", fun, y0, (0.0, 3.0), n2=14, y_ref=PLEIADES_REF,
                   ref_index=np.arange(10))


def robertson(t_end: float = 1e5) -> Problem:
    """Robertson's chemical kinetics (Hairer-Wanner II §IV.1), 3 equations, ``t`` in [0, t_end].

    ``y1' = -0.04 y1 + 1e4 y2 y3``, ``y2' = 0.04 y1 - 1e4 y2 y3 - 3e7 y2^2``, ``y3' = 3e7 y2^2``;
    ``y(0) = (1, 0, 0)``, ``y1 + y2 + y3 = 1`` for all ``t``. ``y2`` peaks at 3.65e-5 and decays
    like ``1/t``; stiffness grows with ``t`` (eigenvalue ~ -1e4 at the peak), so long spans
    (``t_end`` up to 1e11) test the step-size floor. No closed form: references come from a
    tight run (scipy Radau, rtol 1e-12).
    """
    if not (np.isfinite(t_end) and t_end > 0):
        raise InputError("t_end", t_end, "must be a positive finite time in s")

    def fun(t, y):
        y1, y2, y3 = y
        a, b, c = 0.04 * y1, 1e4 * y2 * y3, 3e7 * y2 * y2
        return np.array([-a + b, a - b - c, c])

    def jac(t, y):
        y1, y2, y3 = y
        return np.array([[-0.04, 1e4 * y3, 1e4 * y2],
                         [0.04, -1e4 * y3 - 6e7 * y2, -1e4 * y2],
                         [0.0, 6e7 * y2, 0.0]])

    return Problem(f"robertson(t_end={t_end:g})", fun, np.array([1.0, 0.0, 0.0]), (0.0, float(t_end)), jac=jac)
