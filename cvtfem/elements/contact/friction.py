"""Regularised friction laws ``f(v)`` of the band and chain models and their vector form.

One place for every contact with regularised friction: band–sheave (1.48), pin–sheave, pin–plate
and pin-half (contact-models digest §2.4, (1.298), Table 2.1). Laws, for slip speed ``v >= 0``:

* ``linear-saturated`` (alias ``nonsmooth``): ``f0 v / v0`` below ``v0``, ``f0`` above; C0.
* ``smooth`` (Table 2.1): linear below ``(1-eps) v0``, ``f0`` above ``(1+eps) v0``, between
  ``f0 [1 + eps phi(xi)]``, ``phi = -1 + 2 xi - xi^2``; C1, not C2 (digest §9 item 4).
* ``arctan`` (1.298): ``f0 (2/pi) arctan(pi v / (2 v0))``.
* ``smoothed``: ``f0 (3x - x^3)/2`` below ``x = v/v0 = 1``, ``f0`` above; ``tanh``: ``f0 tanh(v/v0)``.

The vector form (digest §2.5) uses ``psi(v) = f(v)/v``, finite at ``v = 0`` for every law, so
zero slip never divides 0 by 0.
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError

LAWS = ("linear-saturated", "nonsmooth", "smooth", "arctan", "smoothed", "tanh")
_SMALL = 1e-4  # below this x the series of arctan(x)/x, tanh(x)/x is exact to round-off


def _check(law: str, eps: float) -> None:
    if law not in LAWS:
        raise InputError("law", law, f"must be one of {', '.join(LAWS)}")
    if law == "smooth" and not 0.0 < eps < 1.0:
        raise InputError("eps", eps, "must lie in (0, 1)")


def friction_coefficient(v, f0: float, v0: float, law: str = "linear-saturated", eps: float = 0.1):
    """Friction coefficient ``f(v)`` (-) for slip speeds ``v >= 0`` (m/s); digest (1.298), Table 2.1."""
    _check(law, eps)
    x = np.asarray(v, dtype=float) / v0
    if law == "tanh":
        return f0 * np.tanh(x)
    if law == "arctan":
        return f0 * (2 / np.pi) * np.arctan(0.5 * np.pi * x)
    if law == "smoothed":
        return np.where(x < 1.0, f0 * (1.5 * x - 0.5 * x ** 3), f0)
    if law == "smooth":
        xi = (x - (1 - eps)) / (2 * eps)
        blend = f0 * (1 + eps * (-1 + 2 * xi - xi * xi))
        return np.where(x < 1 - eps, f0 * x, np.where(x > 1 + eps, f0, blend))
    return np.where(x < 1.0, f0 * x, f0)


#: Laws with a closed-form :func:`friction_potential`.
POTENTIAL_LAWS = ("linear-saturated", "nonsmooth", "tanh", "smoothed", "arctan")


def friction_potential(v, f0: float, v0: float, law: str = "linear-saturated"):
    """``Phi(v) = int_0^v f(u) du`` (m/s, times the coefficient) for ``v >= 0``: the convex potential whose
    derivative is :func:`friction_coefficient` (an implicit friction step minimises it); laws
    :data:`POTENTIAL_LAWS`."""
    if law not in POTENTIAL_LAWS:
        raise InputError("law", law, f"must be one of {', '.join(POTENTIAL_LAWS)} for the friction potential")
    y = np.asarray(v, dtype=float) / v0
    if law == "tanh":
        return f0 * v0 * (y + np.log1p(np.exp(-2 * y)) - np.log(2.0))
    if law == "arctan":
        a = 0.5 * np.pi * y
        return f0 * v0 * (2 / np.pi) ** 2 * (a * np.arctan(a) - 0.5 * np.log1p(a * a))
    if law == "smoothed":
        return f0 * v0 * np.where(y < 1, 0.75 * y * y - y ** 4 / 8, y - 0.375)
    return f0 * v0 * np.where(y < 1, 0.5 * y * y, y - 0.5)


def friction_slope(v, f0: float, v0: float, law: str = "linear-saturated", eps: float = 0.1):
    """``df/dv`` (s/m) for ``v >= 0``; at a kink of ``linear-saturated`` the right-hand slope."""
    _check(law, eps)
    x = np.asarray(v, dtype=float) / v0
    if law == "tanh":
        s = 1.0 - np.tanh(x) ** 2
    elif law == "arctan":
        s = 1.0 / (1.0 + (0.5 * np.pi * x) ** 2)
    elif law == "smoothed":
        s = np.where(x < 1.0, 1.5 * (1.0 - x * x), 0.0)
    elif law == "smooth":
        xi = (x - (1 - eps)) / (2 * eps)
        s = np.where(x < 1 - eps, 1.0, np.where(x > 1 + eps, 0.0, 1.0 - xi))
    else:
        s = np.where(x < 1.0, 1.0, 0.0)
    return (f0 / v0) * s


def friction_gain(v, f0: float, v0: float, law: str = "linear-saturated", eps: float = 0.1):
    """``psi(v) = f(v) / v`` (s/m) for ``v >= 0``, finite at ``v = 0`` (limit ``f'(0)``); digest §2.5."""
    _check(law, eps)
    x = np.asarray(v, dtype=float) / v0
    big = np.where(x > _SMALL, x, 1.0)  # x where dividing is safe
    if law == "tanh":
        g = np.where(x > _SMALL, np.tanh(big) / big, 1.0 - x * x / 3)
    elif law == "arctan":
        y = 0.5 * np.pi * x
        ybig = 0.5 * np.pi * big
        g = np.where(x > _SMALL, np.arctan(ybig) / ybig, 1.0 - y * y / 3)
    elif law == "smoothed":
        g = np.where(x < 1.0, 1.5 - 0.5 * x * x, 1.0 / np.maximum(x, 1.0))
    elif law == "smooth":
        g = np.where(x < 1 - eps, 1.0, friction_coefficient(x, 1.0, 1.0, law, eps) / np.maximum(x, 1 - eps))
    else:
        g = np.where(x < 1.0, 1.0, 1.0 / np.maximum(x, 1.0))
    return (f0 / v0) * g


def friction_vector(v_r, f0: float, v0: float, law: str = "linear-saturated", eps: float = 0.1,
                    axis: int = -1):
    """``f(|v_r|) v_r / |v_r|`` (-) for slip vectors ``v_r`` (m/s) with components along ``axis``."""
    v_r = np.asarray(v_r, dtype=float)
    speed = np.sqrt(np.sum(v_r * v_r, axis=axis, keepdims=True))
    return friction_gain(speed, f0, v0, law, eps) * v_r


def friction_force(v_r, N, f0: float, v0: float, law: str = "linear-saturated", eps: float = 0.1,
                   normal=None):
    """Friction force ``F = -N psi(|v_r|) v_r`` (N) and ``dF/dv_r`` (N s/m); digest §2.5.

    ``v_r``: slip vectors ``(n, 3)`` (m/s), ``N``: normal forces ``(n,)`` (N). With unit normals
    ``normal`` ``(n, 3)`` the slip is first projected, ``v_r -> E_t v_r`` with ``E_t = E - n n``,
    and the Jacobian is with respect to the unprojected relative velocity:
    ``-N [psi (E_t - tau tau) + f'(v) tau tau]``. Returns ``(F (n, 3), J (n, 3, 3))``.
    """
    v_r = np.asarray(v_r, dtype=float)
    N = np.asarray(N, dtype=float)
    eye = np.broadcast_to(np.eye(3), v_r.shape[:-1] + (3, 3))
    if normal is not None:
        proj = eye - normal[..., :, None] * normal[..., None, :]
        v_r = np.einsum("...ij,...j->...i", proj, v_r)
    else:
        proj = eye
    speed = np.sqrt(np.sum(v_r * v_r, axis=-1))
    psi = friction_gain(speed, f0, v0, law, eps)
    tau = v_r / np.where(speed > 0.0, speed, 1.0)[..., None]  # 0 at zero slip, where f' = psi
    tt = tau[..., :, None] * tau[..., None, :]
    slope = friction_slope(speed, f0, v0, law, eps)
    F = -(N * psi)[..., None] * v_r
    J = -N[..., None, None] * (psi[..., None, None] * (proj - tt) + slope[..., None, None] * tt)
    return F, J
