"""Sheave meridians for the contact tests: z - z_c = f(r), f' < 0 on the working radii 36–88 mm."""
from __future__ import annotations

import numpy as np
import pytest

RT, Y = 0.6, 0.05       # torus: meridian arc (r + y)^2 + (z - w)^2 = Rt^2 (digest §4.1, (1.37))
TAN_GAMMA = np.tan(np.radians(10.0))


def torus(r):
    u = r + Y
    w = np.sqrt(RT ** 2 - u ** 2)
    return w - RT, -u / w, -RT ** 2 / w ** 3


def cone(r):
    r = np.asarray(r, dtype=float)
    return -TAN_GAMMA * r, np.full(r.shape, -TAN_GAMMA), np.zeros(r.shape)


@pytest.fixture(params=["torus", "cone"])
def profile(request):
    return {"torus": torus, "cone": cone}[request.param]
