"""Acceptance: Friswell et al., Dynamics of Rotating Machines, example 5.9.1 (rad/s, within 0.1 %)."""
import numpy as np
import pytest
import scipy.linalg as sla

from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem
from cvtfem.scene.loader import load_scene

RPM = np.pi / 30


@pytest.fixture(scope="module")
def problem():
    m = build_model(load_scene("friswell_5_9_1"))
    return ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)


def test_zero_speed(problem):
    r = problem.solve(0.0, 7)
    bending = [w for w, k in zip(r.wd, r.whirl) if k in ("forward", "backward")]
    torsion = [w for w, k in zip(r.wd, r.whirl) if k == "torsional"]
    np.testing.assert_allclose(bending, [86.66, 86.66, 274.31, 274.31, 716.79, 716.79], rtol=1e-3)
    np.testing.assert_allclose(torsion, [650.41], rtol=1e-3)
    assert list(r.whirl[:4]) == ["backward", "forward", "backward", "forward"]
    np.testing.assert_allclose(np.abs(r.whirl_ratio[:4]), 1.0, atol=1e-6)  # circular limits of the pairs


def test_4000_rpm(problem):
    r = problem.solve(4000 * RPM, 6)
    assert list(r.whirl) == ["backward", "forward", "backward", "forward", "backward", "torsional"]
    np.testing.assert_allclose(r.wd, [85.39, 87.80, 251.78, 294.71, 600.18, 650.41], rtol=1e-3)
    assert np.all(r.damping_ratio == pytest.approx(0.0, abs=1e-9))


def test_sparse_shift_invert_agrees_with_dense():
    m = build_model(load_scene("friswell_5_9_1"))
    dense = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method="dense").solve(4000 * RPM, 10)
    p = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method="sparse")
    assert [p.backend(b, 10) for b in range(len(p.blocks))].count("sparse") == 1   # the lateral block
    sparse = p.solve(4000 * RPM, 10)
    np.testing.assert_allclose(sparse.wd, dense.wd, rtol=1e-10)
    assert sparse.whirl == dense.whirl
    from cvtfem.modal import mac

    assert np.all(np.diag(mac(dense.shapes, sparse.shapes)) > 1 - 1e-8)


def test_damped_bearings_give_positive_damping_and_log_dec():
    scene = load_scene("friswell_5_9_1", {"bearing": [{"node": 0, "kxx": 1e6, "kyy": 1e6, "cxx": 300.0,
                                                               "cyy": 300.0},
                                                              {"node": 6, "kxx": 1e6, "kyy": 1e6, "cxx": 300.0,
                                                               "cyy": 300.0}]})
    m = build_model(scene)
    r = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind).solve(2000 * RPM, 4)
    assert np.all(r.damping_ratio > 0)
    np.testing.assert_allclose(r.log_dec, 2 * np.pi * r.damping_ratio / np.sqrt(1 - r.damping_ratio**2))
    np.testing.assert_allclose(r.wn * np.sqrt(1 - r.damping_ratio**2), r.wd, rtol=1e-12)
    undamped = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, damped=False).solve(2000 * RPM, 4)
    assert np.all(undamped.damping_ratio == pytest.approx(0.0, abs=1e-9))


def test_negative_speed_mirrors_whirl(problem):
    """Whirl is relative to the spin: reversing the spin gives the same frequencies and labels.

    The two spectra belong to different (mirror-similar) state matrices, so they agree to the accuracy of
    LAPACK's ``geev``, ``|d lambda| <~ n eps |lambda|_max`` (n = 2 x DOF), not to a fixed relative 1e-12:
    with |lambda|_max = 5.2e4 rad/s the 85 rad/s pair differs by 1.1e-10 rad/s (rel. 1.3e-12) under the
    Sandybridge OpenBLAS kernel and 1.3e-11 under Haswell (issue 11)."""
    pos, neg = problem.solve(4000 * RPM, 6), problem.solve(-4000 * RPM, 6)
    w_max = np.sqrt(sla.eigh(problem.K.toarray(), problem.M.toarray(), eigvals_only=True).max())
    np.testing.assert_allclose(neg.wd, pos.wd, rtol=0, atol=2 * problem.n * np.finfo(float).eps * w_max)
    assert neg.whirl == pos.whirl


def test_bad_matrices_are_input_errors():
    from cvtfem.errors import InputError

    M = np.eye(4)
    with pytest.raises(InputError, match="`K`"):
        ModalProblem(M, np.eye(3), M, M, np.arange(4))
    with pytest.raises(InputError, match="dof_kind"):
        ModalProblem(M, M, M, M, np.arange(3))
