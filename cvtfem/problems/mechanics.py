"""Mechanical models with discrete state and friction (the ``ode_num_int`` test models).

Bouncing ball (events, impacts, closed-form impact times) and a sliding point on a moving
belt with the regularised friction laws of spec §2.1 (Table 2.1, ``nonsmooth``/``smooth``).
"""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError
from cvtfem.problems.base import Problem

__all__ = ["bouncing_ball", "bouncing_ball_impacts", "sliding_point", "friction_coefficient"]


def bouncing_ball_impacts(x0: float, v0: float, g: float, e: float, n: int) -> np.ndarray:
    """Closed-form impact times: ``t1 = (v0 + sqrt(v0^2 + 2 g x0))/g``,
    ``t_{k+1} = t_k + 2 e^k V1 / g`` with ``V1 = sqrt(v0^2 + 2 g x0)`` the first impact speed."""
    V1 = np.sqrt(v0 * v0 + 2 * g * x0)
    t1 = (v0 + V1) / g
    gaps = 2 * e ** np.arange(1, n) * V1 / g
    return t1 + np.concatenate([[0.0], np.cumsum(gaps)])


def bouncing_ball(x0: float = 1.0, v0: float = 0.0, g: float = 9.81, e: float = 0.8,
                  t_end: float = 3.0) -> Problem:
    """Ball ``x'' = -g`` above the floor ``x = 0``; at impact ``v -> -e v`` (n2 = 1).

    The indicator ``e(t, x) = x`` fires downwards; the switch reverses the velocity. The
    impacts accumulate (Zeno) at ``t1 + 2 e V1 / (g (1 - e))``.
    """
    if not (0 < e <= 1 and g > 0 and x0 > 0):
        raise InputError("bouncing_ball", (x0, g, e), "needs x0 > 0, g > 0 and 0 < e <= 1")

    def fun(t, x):
        return np.array([x[1], -g])

    def indicators(t, x):
        return np.array([x[0]])

    def switch(t, x, fired):
        x[1] = -e * x[1]
        return x

    V1 = np.sqrt(v0 * v0 + 2 * g * x0)
    t_zeno = (v0 + V1) / g + 2 * e * V1 / (g * (1 - e)) if e < 1 else np.inf
    return Problem("bouncing_ball", fun, np.array([x0, v0]), (0.0, t_end), n2=1,
                   events=(indicators, np.array([-1]), np.array([False])), switch=switch,
                   info={"impacts": lambda n: bouncing_ball_impacts(x0, v0, g, e, n),
                         "t_zeno": t_zeno})


def friction_coefficient(v_r, f0: float, v0: float, law: str = "nonsmooth", eps: float = 0.1):
    """Regularised friction coefficient ``f(|v_r|)`` of spec Table 2.1 (``sign`` applied by caller).

    ``nonsmooth``: ``f0 v/v0`` below ``v0``, ``f0`` above (C0). ``smooth``: the C1 blend
    ``f0 [1 + eps phi((v - (1-eps) v0)/(2 eps v0))]``, ``phi(xi) = -1 + 2 xi - xi^2``, on
    ``[(1-eps) v0, (1+eps) v0]``.
    """
    v = np.abs(v_r)
    if law == "nonsmooth":
        return np.where(v < v0, f0 * v / v0, f0)
    if law == "smooth":
        xi = (v - (1 - eps) * v0) / (2 * eps * v0)
        blend = f0 * (1 + eps * (-1 + 2 * xi - xi * xi))
        return np.where(v < (1 - eps) * v0, f0 * v / v0, np.where(v > (1 + eps) * v0, f0, blend))
    raise InputError("law", law, "must be 'nonsmooth' or 'smooth'")


def sliding_point(law: str = "smooth", m: float = 1.0, k: float = 100.0, N: float = 10.0,
                  f0: float = 0.3, v0: float = 1e-3, V: float = 0.1, t_end: float = 2.0) -> Problem:
    """Mass ``m`` on a spring ``k`` resting on a belt moving at ``V`` with friction ``f N``.

    ``m u'' = -k u + N f(v_r) sign(v_r)``, ``v_r = V - u'`` (n2 = 1). Stick phases make it
    stiff: ``dF_v/dv = -N f0 / (m v0)`` there (-3000 1/s with the defaults).
    """
    friction_coefficient(0.0, f0, v0, law)  # validates `law`

    def fun(t, x):
        vr = V - x[1]
        return np.array([x[1], (-k * x[0] + N * friction_coefficient(vr, f0, v0, law) * np.sign(vr)) / m])

    return Problem(f"sliding_point({law})", fun, np.array([0.0, 0.0]), (0.0, t_end), n2=1)
