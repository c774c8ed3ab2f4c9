"""The quasi-static start of the per-plate chain A4 (bounded plate moments) on the sheaves (issue 13)."""
import numpy as np
import pytest

from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])   # N per sheave, as the A1 and A3 tests


@pytest.mark.slow
def test_a4_start_converges_from_the_a1_balance():
    """A4 continued from the balance of A1 with the same plates (chain coordinates and movable sheaves) by the lifted
    Newton solve converges (Levenberg-Marquardt stopped at 3e-5 of F2): residual, the movable sheaves' axial forces =
    the clamping force and the reaction F1, the fixed sheaves' = the movable ones to 1e-3 (issue 13 asks 1 %; the
    spans carry 7 N axially from one shaft to the other), the chain's axial balance across all four sheaves, and the
    mean tension as A1's (the homogenised layer) to 0.1 %."""
    scene = load_scene("band-6+2n")
    a4 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A4")
    x0, rep = a4.static_state(RATIO, scene.cvt.regime.input_speed)
    assert rep["residual"] < 1e-8
    at_rest = x0.copy()
    at_rest[a4.n2:2 * a4.n2] = 0.0
    o = a4.outputs(0.0, at_rest)
    mov = o["contact.sheave_axial_force"]
    np.testing.assert_allclose(mov, [rep["F1"], F_APPL[1]], rtol=1e-8)
    fix = o["contact.fixed_sheave_axial_force"]
    np.testing.assert_allclose(fix, mov, rtol=1e-3)                   # measured 2.4e-4: the links carry 7 N axially
    assert mov[0] + fix[1] == pytest.approx(fix[0] + mov[1], rel=1e-9)
    a1 = from_scene(scene, reference_geometry(), F_APPL, model="chain-A1")
    _, rep1 = a1.static_state(RATIO, scene.cvt.regime.input_speed)
    assert rep["tension"] == pytest.approx(rep1["tension"], rel=1e-3)
