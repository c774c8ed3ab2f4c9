"""slepc4py PEP backend agrees with scipy to 1e-8 on Friswell 5.9.1 (skips without slepc4py)."""
import numpy as np
import pytest

from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem, mac
from cvtfem.modal.slepc_backend import available
from cvtfem.scene.loader import load_scene

pytestmark = [pytest.mark.slepc, pytest.mark.skipif(not available(), reason="slepc4py is not installed")]


@pytest.mark.parametrize("rpm", [0.0, 4000.0])
def test_slepc_matches_scipy(rpm):
    m = build_model(load_scene("friswell_5_9_1"))
    speed = rpm * np.pi / 30
    ref = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method="dense").solve(speed, 10)
    problem = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method="slepc")
    assert "slepc" in [problem.backend(b, 10) for b in range(len(problem.blocks))]
    got = problem.solve(speed, 10)
    np.testing.assert_allclose(got.wd, ref.wd, rtol=1e-8)
    assert got.whirl == ref.whirl
    assert np.all(np.diag(mac(ref.shapes, got.shapes)) > 1 - 1e-8)
