"""Sheave meridians ``z - z_c = f(r)`` as data: callable on arrays (numpy) and as four numbers (compiled kernels).

Conical face ``f = f_0 - tan(gamma) r``; toroidal face, the arc (1.37) ``(r + y)^2 + (z - w)^2 = R^2``
on its working side, ``f = f_0 + sqrt(R^2 - (r + y)^2)`` (contact digest §4.1).  Both have ``f' < 0`` on
the working radii.  The numpy contact functions take a :class:`Meridian` wherever they take a
``profile(r) -> (f, f', f'')``; the kernels of :mod:`.kernels` take :attr:`Meridian.params`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.jit import njit
from cvtfem.errors import InputError

CONE, TORUS = 0.0, 1.0


@dataclass(frozen=True)
class Meridian:
    """A conical (``kind="cone"``: ``tan_gamma``) or toroidal (``kind="torus"``: ``R``, ``y``) meridian, m.

    ``f0`` (m) is the height at ``r = 0`` (cone) or of the arc centre (torus).
    """

    kind: str
    tan_gamma: float = 0.0
    R: float = 0.0
    y: float = 0.0
    f0: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("cone", "torus"):
            raise InputError("kind", self.kind, '"cone" or "torus"')
        if self.kind == "torus" and not self.R > 0:
            raise InputError("R", self.R, "> 0 for a torus")

    @property
    def params(self) -> np.ndarray:
        """``(kind, a, b, f0)``: ``(CONE, tan_gamma, 0, f0)`` or ``(TORUS, R, y, f0)`` for :func:`evaluate`."""
        if self.kind == "cone":
            return np.array([CONE, self.tan_gamma, 0.0, self.f0])
        return np.array([TORUS, self.R, self.y, self.f0])

    def __call__(self, r):
        """``(f, f', f'')`` (m, -, 1/m) at radii ``r`` (m)."""
        r = np.asarray(r, dtype=float)
        if self.kind == "cone":
            return self.f0 - self.tan_gamma * r, np.full(r.shape, -self.tan_gamma), np.zeros(r.shape)
        u = r + self.y
        w = np.sqrt(self.R ** 2 - u ** 2)
        return self.f0 + w, -u / w, -self.R ** 2 / w ** 3


@njit(cache=True)
def evaluate(params, r):
    """``(f, f', f'')`` of a meridian given by :attr:`Meridian.params` at one radius ``r`` (m)."""
    if params[0] == CONE:
        return params[3] - params[1] * r, -params[1], 0.0
    u = r + params[2]
    w = np.sqrt(params[1] * params[1] - u * u)
    return params[3] + w, -u / w, -params[1] * params[1] / (w * w * w)
