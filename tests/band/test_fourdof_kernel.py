"""Compiled 4-DOF right-hand side against its numpy twin (random admissible states)."""
import numpy as np
import pytest

from cvtfem.elements.band.geometry import admissible_phi, radii
from cvtfem.machines.cvt import band_model
from cvtfem.scene.loader import load_scene

pytest.importorskip("numba")


@pytest.mark.parametrize("profile", ["toroidal", "conical"])
@pytest.mark.parametrize("law,friction", [("tanh", True), ("linear-saturated", True), ("smoothed", True),
                                          ("tanh", False)])
def test_numba_kernel_equals_numpy_twin(profile, law, friction):
    scene = load_scene("band-4dof", {"cvt": {"geometry": {"sheave_profile": profile}, "friction": {"law": law},
                                             "effects": {"friction": friction}}})
    m = band_model(scene)
    assert m.backend == "numba"
    rng = np.random.default_rng(7)
    lo, hi = admissible_phi(m.p.length, m.p.L)
    for _ in range(8):
        phi = rng.uniform(0.6 * lo, 0.6 * hi)
        r = radii(phi, m.p.length, m.p.L)[0]
        q = np.array([phi, *rng.uniform(-10, 10, 3)])
        w1 = 366 * (1 + 0.01 * rng.normal())
        v1 = r[0] * w1 + 0.02 * rng.normal()  # slips around v0: the unsaturated branch is used
        v = np.array([0.3 * rng.normal(), v1, w1, (v1 + 0.02 * rng.normal()) / r[1]])
        F, M = rng.uniform(5e3, 4e4, 2), np.array([200.0, -480.0]) * rng.uniform(0.5, 1.5)
        a1, i1 = m.accel(q, v, F, M)
        a0, i0 = m.accel_numpy(q, v, F, M)
        assert np.abs(a1 - a0).max() <= 1e-12 * np.abs(a0).max()
        for key in ("N", "slip", "slip_max", "dissipation", "clamp_power"):
            ref = np.asarray(i0[key], float)
            assert np.abs(np.asarray(i1[key]) - ref).max() <= 1e-12 * max(np.abs(ref).max(), 1e-300), key


@pytest.mark.parametrize("profile", ["toroidal", "conical"])
def test_compiled_energies_equal_numpy_twin(profile):
    """``energies`` (compiled kinetic energy) against ``kinetic_energy`` / ``elastic_energy`` to 1e-12 relative."""
    m = band_model(load_scene("band-4dof", {"cvt": {"geometry": {"sheave_profile": profile}}}))
    assert m.backend == "numba"
    rng = np.random.default_rng(8)
    lo, hi = admissible_phi(m.p.length, m.p.L)
    for _ in range(8):
        q = np.array([rng.uniform(0.6 * lo, 0.6 * hi), *rng.uniform(-10, 10, 3)])
        v = np.array([0.3, 28.0, 366.0, 152.0]) * (1 + 0.1 * rng.standard_normal(4))
        T, V = m.energies(q, v)
        T0 = m.kinetic_energy(q, v)
        assert abs(T - T0) <= 1e-12 * abs(T0)
        assert V == m.elastic_energy(q) == 0.0
