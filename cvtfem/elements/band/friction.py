"""Regularised friction law of the band models, eq. (1.48) and its smooth variants.

``friction_vector(v_r)`` returns ``f(|v_r|) t`` with ``t = v_r / |v_r|``, evaluated without 0/0
below ``v0`` (spec section 4.3 [C]).
"""
from __future__ import annotations

import numpy as np

LAWS = ("linear-saturated", "smoothed", "tanh")


def friction_coefficient(v, f0: float, v0: float, law: str = "linear-saturated"):
    """Friction coefficient ``f(v)`` for slip speed ``v >= 0`` (m/s).

    linear-saturated: ``f0 v / v0`` below ``v0``, ``f0`` above (1.48); smoothed: ``f0 (3x - x^3)/2``
    below ``x = v / v0 = 1`` (C1 at v0); tanh: ``f0 tanh(v / v0)``.
    """
    x = np.asarray(v) / v0
    if law == "tanh":
        return f0 * np.tanh(x)
    if law == "smoothed":
        return np.where(x < 1.0, f0 * (1.5 * x - 0.5 * x ** 3), f0)
    return np.where(x < 1.0, f0 * x, f0)


def friction_gain(v, f0: float, v0: float, law: str = "linear-saturated"):
    """``f(v) / v`` (s/m) for slip speeds ``v >= 0``, finite at ``v = 0`` (limit ``f'(0)``)."""
    x = v / v0
    if law == "tanh":
        safe = np.where(x > 1e-8, x, 1.0)
        g = np.where(x > 1e-8, np.tanh(safe) / safe, 1.0 - x * x / 3)
    elif law == "smoothed":
        g = np.where(x < 1.0, 1.5 - 0.5 * x * x, 1.0 / np.where(x < 1.0, 1.0, x))
    else:
        g = np.where(x < 1.0, 1.0, 1.0 / np.where(x < 1.0, 1.0, x))
    return (f0 / v0) * g


def friction_vector(v_r, f0: float, v0: float, law: str = "linear-saturated"):
    """``f(|v_r|) v_r / |v_r|`` for slip vectors ``v_r`` of shape ``(3, ...)`` (components first)."""
    return friction_gain(np.sqrt(np.sum(v_r * v_r, axis=0)), f0, v0, law) * v_r
