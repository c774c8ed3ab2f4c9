"""Modal damping of the flexible sheaves' fixed-interface modes in the rotor (``[sheave] damping_ratio``, issue 20)."""
import numpy as np
import pytest

from tests.machines.test_sheave_rotor import scene_text

ZETA = 0.005


def _build(tmp_path, zeta):  # noqa: ANN001, ANN202
    from cvtfem.machines.rotor import build_model
    from cvtfem.scene.loader import load_scene

    path = tmp_path / f"rotor{zeta}.toml"
    path.write_text(scene_text(modes=4, cells=(8, 1)) + f"damping_ratio = {zeta}\n")
    return build_model(load_scene(path))


def test_sheave_modes_get_their_damping_ratio_and_shaft_modes_none(tmp_path):
    """At rest, with no other damping, the damped eigen-solution's ratio of every mode below 12 kHz equals the
    first-order estimate ``x^T C x / (2 w x^T M x)`` over the undamped shape to 2 % (observed 1e-4): ``zeta``
    weighted by the sheaves' modal coordinates in the mode (``2 zeta omega_k`` each, so a sheave mode pulled below its
    fixed-interface frequency by the shaft damps a little more than ``zeta``: 1.23 ``zeta`` here).  Modes holding
    over 90 % of their strain energy in the sheaves damp at 0.5..1.5 ``zeta``, shaft modes with under 1 % at below
    0.02 ``zeta``; without the key the rotor has no damping at all."""
    from cvtfem.modal import ModalProblem

    model = _build(tmp_path, ZETA)
    assert _build(tmp_path, 0.0).C.nnz == 0
    undamped = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, damped=False).solve(0.0, 24)
    damped = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind).solve(0.0, 24)
    X = np.real(undamped.shapes)
    w = undamped.wn
    estimate = np.einsum("ik,ik->k", X, model.C @ X) / (2 * w * np.einsum("ik,ik->k", X, model.M @ X))
    keep = w < 2 * np.pi * 12e3
    np.testing.assert_allclose(damped.wn[keep], w[keep], rtol=1e-4)
    np.testing.assert_allclose(damped.damping_ratio[keep], estimate[keep], rtol=0.02, atol=1e-4 * ZETA)
    share, _ = model.sheave_share(X)
    assert np.any(share[keep] > 0.9) and np.any(share[keep] < 0.01)
    sheave, shaft = keep & (share > 0.9), keep & (share < 0.01)
    assert np.all((damped.damping_ratio[sheave] > 0.5 * ZETA) & (damped.damping_ratio[sheave] < 1.5 * ZETA))
    assert np.all(damped.damping_ratio[shaft] < 0.02 * ZETA)
