"""The scene schema names exactly the methods the integrators offer."""
from __future__ import annotations

from cvtfem.integrate import METHODS
from cvtfem.scene.schema.common import METHODS as SCENE_METHODS

SCIPY = {"RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA"}


def test_solver_methods_match_integrators():
    assert set(SCENE_METHODS) == set(METHODS) | SCIPY
