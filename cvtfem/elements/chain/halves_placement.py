"""In-plane geometry of a chain with independent pin halves (A5) placed around rolling points, for links of any
lengths, unstretched or at a given tension: :func:`rolling_link_directions`, :func:`rolling_spacing`,
:func:`half_centres`.

The halves of pin ``p`` roll on each other at the rolling point ``U_p`` (n, 2) m; their faces (radii ``R-``, ``R+``)
touch on the bisector ``b_p`` of the two link directions ``tau_{p-1}``, ``tau_p`` (no rolling slip from the straight
chain), pressed together by ``delta`` (m), so the face centres are ``U_p -+ (R-+ - delta/2) b_p`` and the half axes
``u-_p = U_p - (R- - delta/2) b_p - (h - R-) tau_p``, ``u+_p = U_p + (R+ - delta/2) b_p - (R+ - h) tau_{p-1}``
(chain-models-2 §5.3, the digest's rolling faces; ``h`` = ``h_pin``).  The link direction the model reads is that of
the half axes it joins, ``x_p = u+_{p+1} - u-_p``; it differs from the chord ``U_{p+1} - U_p`` where the joint angles
at the link's two ends differ (links of unequal lengths on an arc), and by ``(h - R) |tau - chord|`` (microns: the
faces are stiff to 1e11 N/m^2) the faces would press or open and the links stretch.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import NumericalError


def _unit(a: np.ndarray) -> np.ndarray:
    return a / np.linalg.norm(a, axis=1, keepdims=True)


def _bisectors(tau: np.ndarray) -> np.ndarray:
    """Unit bisectors ``b_p`` of ``tau_{p-1}`` and ``tau_p`` (n, 2) of a closed chain."""
    return _unit(tau + np.roll(tau, 1, 0))


def half_centres(U: np.ndarray, tau: np.ndarray, R, h: float, delta=0.0) -> np.ndarray:
    """In-plane centres ``(u-, u+)`` (2, n, 2) m of the halves rolling at ``U`` (n, 2) m for link directions ``tau``
    (n, 2), face radii ``R = (R-, R+)`` m, half offset ``h`` m and face pressing ``delta`` (scalar or (n,)) m."""
    b = _bisectors(tau)
    a = np.asarray(delta, float)[..., None] / 2
    return np.stack([U - (R[0] - a) * b - (h - R[0]) * tau, U + (R[1] - a) * b - (R[1] - h) * np.roll(tau, 1, 0)])


def rolling_link_directions(U: np.ndarray, R, h: float, delta=0.0, tol: float = 1e-15,
                            iterations: int = 50) -> np.ndarray:
    """Link directions ``tau`` (n, 2) of the halves of :func:`half_centres` at ``U`` (n, 2) m that are the directions
    of the links they make: the fixed point of ``tau_p <- unit(x_p)``, ``x_p = U_{p+1} - U_p + a-_p b_p + a+_{p+1}
    b_{p+1} + (2 h - R- - R+) tau_p`` (``a = R - delta/2``; a contraction by about ``R / L``), from the chords of
    ``U``."""
    dU = np.roll(U, -1, 0) - U
    a = np.asarray(delta, float)[..., None] / 2
    am, ap = R[0] - a, np.roll(R[1] - a * np.ones((len(U), 1)), -1, 0)
    tau = _unit(dU)
    for _ in range(iterations):
        b = _bisectors(tau)
        new = _unit(dU + am * b + ap * np.roll(b, -1, 0) + (2 * h - R[0] - R[1]) * tau)
        step = np.abs(new - tau).max()
        tau = new
        if step < tol:
            return tau
    raise NumericalError(f"the link directions of the rolling halves did not settle (last change {step:.3g})",
                         component="halves placement")


def rolling_spacing(tau: np.ndarray, L: np.ndarray, R, delta=0.0, stretch=0.0) -> np.ndarray:
    """Distances ``|U_{p+1} - U_p|`` (n,) m of the rolling points that make every link ``L + stretch`` long between
    its pin centres (half-axis distance ``L + stretch + 2 h``) for link directions ``tau`` (n, 2), unstretched pin
    pitches ``L`` (n,) m, faces pressed by ``delta`` m: ``U_{p+1} - U_p = (L_p + stretch_p + R- + R+) tau_p - a-_p
    b_p - a+_{p+1} b_{p+1}``, ``a = R - delta/2``."""
    b = _bisectors(tau)
    a = np.asarray(delta, float)[..., None] / 2 * np.ones((len(L), 1))
    d = (L + stretch + R[0] + R[1])[:, None] * tau - (R[0] - a) * b - np.roll(R[1] - a, -1, 0) * np.roll(b, -1, 0)
    return np.linalg.norm(d, axis=1)
