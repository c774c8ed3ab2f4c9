"""A method added in a test file with one registration call runs everywhere: ``solve()``, ``cvtfem run``
(the scene's ``solver.method``) and a resumed run (issue 12, deliverable 3)."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.analysis.run import resume_run, run_scene
from cvtfem.errors import InputError
from cvtfem.integrate import METHODS, register_method, solve, unregister_method
from cvtfem.integrate.rk import ExplicitRK
from cvtfem.io.results import read_results
from cvtfem.scene.loader import load_scene
from tests.hard.test_resume import _interrupted, _series_equal


class Heun(ExplicitRK):
    """Heun's method with the explicit Euler step as embedded estimate: order 2(1)."""

    name, order, low_order = "heun-test", 2, 1
    A = np.array([[0.0, 0.0], [1.0, 0.0]])
    b = np.array([0.5, 0.5])
    b_low = np.array([1.0, 0.0])
    c = np.array([0.0, 1.0])


@pytest.fixture(scope="module")
def heun():
    name = register_method(Heun)   # the one registration
    yield name
    unregister_method(name)       # keep the session's method list (and docs/scenes.md) as built


def test_registered_method_in_solve_has_its_order(heun):
    """Fixed steps on y' = -y: the error falls 4x per halving (order 2); adaptive steps meet rtol."""
    errs = [abs(solve(lambda t, y: -y, (0.0, 1.0), [1.0], method=heun, h=h).y[0, -1] - np.exp(-1.0))
            for h in (0.02, 0.01)]
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.02)
    res = solve(lambda t, y: -y, (0.0, 1.0), [1.0], method=heun, rtol=1e-6, atol=1e-9)
    assert res.success and abs(res.y[0, -1] - np.exp(-1.0)) < 1e-5 and res.stats["nreject"] >= 0


def test_registration_is_checked(heun):
    assert METHODS[heun] is Heun
    assert register_method(Heun) == heun          # the same class again: nothing changes
    with pytest.raises(InputError, match="already a registered method"):
        register_method(type("Other", (Heun,), {}), name=heun)
    with pytest.raises(InputError, match="must be a cvtfem.integrate Stepper"):
        register_method(dict, name="not-a-method")


def test_registered_method_in_cvtfem_run_and_resume(heun, tmp_path):
    """The scene names the method; a run interrupted after its first checkpoint resumes to the same bits."""
    scene = load_scene("band-4dof", {"solver": {"method": heun, "rtol": 1e-4},
                                     "output": {"checkpoint_interval": 0.004}})
    ref = run_scene(scene, until=0.012, results=tmp_path / "ref.h5", show_progress=False)
    assert ref.solver["name"] == heun and ref.solver["steps"] > 10
    _interrupted(scene, tmp_path / "r.h5", 1, 0.012)
    res = resume_run(tmp_path / "r.h5", show_progress=False)
    assert _series_equal(read_results(tmp_path / "ref.h5"), read_results(tmp_path / "r.h5"))
    assert res.solver == ref.solver and res.ratio == ref.ratio

