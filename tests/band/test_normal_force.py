"""6+2n model: normal force along the arcs (section 4.4), convergence in the Ritz order n = 1..9."""
import numpy as np
import pytest

from cvtfem.elements.band.compressible import CompressibleBand
from cvtfem.machines.cvt import band_model, closed_loop
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def distributions():
    scene = load_scene("band-6+2n")
    loop = closed_loop(scene)
    F, phi = loop.clamping.forces(200.0, 2.4), loop.clamping.span_angle(2.4)
    out = {}
    for n in range(1, 10):
        m = band_model(scene, n_ritz=n, n_gauss=32)
        _, _, M2, info = m.steady_state(phi, 366.5, F, 200.0)
        out[n] = (info["N"], M2, m)
    return out, F


def test_normal_force_converges_with_ritz_order(distributions):
    out, _ = distributions
    ref = out[9][0]
    err = [np.linalg.norm(out[n][0] - ref) / np.linalg.norm(ref) for n in range(1, 9)]
    assert err[0] > 0.05  # one Ritz function is not enough
    assert err[4] < 0.02  # n = 5 suffices (source, Fig. 1.11)
    assert err[7] < err[4] < err[0]
    assert err[7] < 0.005


def test_normal_force_is_not_uniform_and_carries_the_clamping_force(distributions):
    out, F = distributions
    N, M2, m = out[5]
    assert isinstance(m, CompressibleBand)
    spread = (N.max(axis=1) - N.min(axis=1)) / N.mean(axis=1)
    assert spread.min() > 0.5
    # axial balance of one sheave: int N cos(gamma) ds ~ F_k (friction's axial part is small)
    g = m.arcs(m.static_state(-0.2984, F)[0])
    cosg = 1 / np.sqrt(1 + g["tg"] ** 2)
    axial = (N * g["ds"]).sum(axis=1) * cosg
    assert axial == pytest.approx(F, rel=0.03)
    # the driven shaft needs M1 * i (no torque loss in steady running without damping losses)
    assert -M2 == pytest.approx(200.0 * 2.4, rel=2e-3)
