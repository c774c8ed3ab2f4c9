"""Compiled gather of pin-axis points and scatter of point loads for the whole-pin chains (A1, A3, A4).

The contact pass of an RHS reads the pin-end positions from the state and turns the contact forces and
moments back into generalized forces.  :meth:`.asymmetric.ChainA1.axis_points` and
:meth:`.asymmetric.ChainA1.point_loads` (Hermite shape functions (1.132)-(1.133), virtual work of spec 2.7)
are the numpy twin of these kernels; they do the same per contact in one loop (no ``np.add.at``).
State layout of ``ChainA1``: ``q = [u (4, n, 2), w (2, n)]`` flattened.
"""
from __future__ import annotations

from cvtfem.elements.jit import njit


@njit(cache=True)
def _shape(xi, l):
    """``h_0..h_3`` and ``dh_i/dxi`` (1.132) at ``xi``."""
    l8 = l / 8.0
    return (1.0, xi, l8 * (1 - xi) ** 2 * (1 + xi), l8 * (xi - 1) * (1 + xi) ** 2,
            0.0, 1.0, l8 * (-1 - 2 * xi + 3 * xi * xi), l8 * (-1 + 2 * xi + 3 * xi * xi))


@njit(cache=True)
def axis_points_kernel(q, n, l, pins, xi, out):
    """Write ``U_p(xi) (m, 3)`` (m) of the axis points ``(pins, xi)`` into ``out``; ``q`` the state (10 n,)."""
    for k in range(pins.shape[0]):
        p = pins[k]
        h0, h1, h2, h3, _, _, _, _ = _shape(xi[k], l)
        for c in range(2):
            out[k, c] = (h0 * q[2 * p + c] + h1 * q[2 * n + 2 * p + c] + h2 * q[4 * n + 2 * p + c]
                         + h3 * q[6 * n + 2 * p + c])
        out[k, 2] = q[8 * n + p] + xi[k] * q[9 * n + p]


@njit(cache=True)
def point_loads_kernel(n, l, pins, xi, force, moment, Q):
    """Add the generalized forces of forces ``(m, 3)`` N at axis points ``(pins, xi)`` and in-plane moments
    ``(m, 2)`` N m into ``Q`` (10 n,): ``F . dU(xi) + M . d theta(xi)``, ``theta = k x t_perp``."""
    for k in range(pins.shape[0]):
        p = pins[k]
        h0, h1, h2, h3, _, d1, d2, d3 = _shape(xi[k], l)
        mk0, mk1 = moment[k, 1], -moment[k, 0]                       # M x k
        s = 2.0 / l
        for c in range(2):
            f = force[k, c]
            mk = mk0 if c == 0 else mk1
            Q[2 * p + c] += h0 * f
            Q[2 * n + 2 * p + c] += h1 * f + s * d1 * mk
            Q[4 * n + 2 * p + c] += h2 * f + s * d2 * mk
            Q[6 * n + 2 * p + c] += h3 * f + s * d3 * mk
        Q[8 * n + p] += force[k, 2]
        Q[9 * n + p] += xi[k] * force[k, 2]
