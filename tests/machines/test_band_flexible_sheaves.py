"""Band-6+2n on flexible sheaves (issue 20): the faces open under the contact arcs (quasi-static, the solid sheave's
face compliance); power balance of the coupled model, static equilibrium, the stiff-sheave limit, scene errors."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.machines.cvt import band_model, closed_loop
from cvtfem.scene.loader import load_scene

CHEAP = {"sheave": {"harmonics": 10, "cells_radial": 12, "cells_axial": 1}}     # physics unchanged, ~1 s to build


def _scene(name="band-6+2n-flexible", **sheave):
    return load_scene(name, {"sheave": {**CHEAP["sheave"], **sheave}})


@pytest.fixture(scope="module")
def flexible_loop():
    return closed_loop(_scene())


def test_power_balance_of_the_coupled_model(flexible_loop):
    """``d(T + V)/dt = M1 w1 + M2 w2 + P_clamp - D`` away from steady running, with ``V`` the band's and the sheaves'
    strain energy: the generalized forces of the flexible faces are the gradient of that energy (rel 1e-8)."""
    model = flexible_loop
    x = model.initial_state(ratio=1.3)
    x[model.n2:2 * model.n2] += 1e-2
    f = model.rhs(0.01, x)
    h = 1e-6
    dE = (model.energy(x + h * f) - model.energy(x - h * f)) / (2 * h)
    P = model.power(0.01, x)
    assert dE == pytest.approx(P[0] - P[1] + P[3] - P[2], rel=1e-8)
    assert model.model.face_opening(x[:model.n2]).min() > 0.0         # both faces give way along both arcs


def _elastic_forces(band, q, F):
    """Generalized forces on ``[z1, z2, h]`` at rest (``M a`` with the model's mass matrix; no torques)."""
    a, info = band.accel(q, np.zeros(band.n2), F, np.zeros(2))
    bi = band._band_index()
    Qb = band.band_mass(q[0]) @ a[bi]
    return np.concatenate([np.asarray(band.p.m_sheave) * a[4:6], Qb[2:]]), info


def test_static_state_balances_the_elastic_coordinates(flexible_loop):
    """:meth:`static_state` (a closed-form solve with ``W = (D^-1 + c' K_f)^-1``) leaves no generalized force on
    the elastic coordinates in :meth:`accel` (``A^-1`` applied to the strain): below 1e-9 of the clamping force
    (a 1 um step of each gives 8 % of it); and the edge forces on each sheave add up to its clamping force."""
    band = flexible_loop.model
    F = np.array([30e3, 35e3])
    q = band.static_state(0.3, F)
    Q, info = _elastic_forces(band, q, F)
    moved, _ = _elastic_forces(band, q + 1e-6 * (np.arange(band.n2) >= 4), F)
    assert np.abs(Q).max() < 1e-9 * F.max() < 1e-9 * 1e2 * np.abs(moved).max()
    g = band.arcs(q[0])
    np.testing.assert_allclose(-band.p.c * np.sum(info["eps"] * g["ds"], axis=1), F, rtol=1e-9)


def test_stiff_sheaves_tend_to_the_rigid_model():
    """Steady running at the reference regime with sheaves 10 and 40 times as stiff as steel against the rigid
    model (the kernel's rigid path, untouched by the faces): the gap in the elastic coordinates falls as 1/E
    (log-log slope -1 +- 0.1) and the driven torque moves by less than 1e-3 relative at 40 x."""
    rigid = closed_loop(load_scene("band-6+2n"))
    w1, M1, i = rigid.regime.targets(0.0)
    F, phi = rigid.clamping.forces(M1, i), rigid.clamping.span_angle(i)
    q0, _, M2_0, _ = rigid.model.steady_state(phi, w1, F, M1)
    el = rigid.model._elastic_index()
    gaps = []
    for factor in (10.0, 40.0):
        band = band_model(_scene(young_modulus=factor * 2.1e11))
        q, _, M2, _ = band.steady_state(phi, w1, F, M1)
        gaps.append(np.abs(q[el] - q0[el]).max())
    slope = np.log(gaps[1] / gaps[0]) / np.log(4.0)
    assert slope == pytest.approx(-1.0, abs=0.1)
    assert M2 == pytest.approx(M2_0, rel=1e-3)


def test_flexible_sheaves_need_their_section_and_a_band_6_2n_model():
    with pytest.raises(InputError, match="sheave.bore_diameter"):
        band_model(load_scene("band-6+2n", {"sheave": {"flexibility": "reduced"}}))
    with pytest.raises(InputError, match="sheave.flexibility"):
        band_model(load_scene("band-4dof", {"sheave": {"flexibility": "reduced"}}))
    with pytest.raises(InputError, match="sheave.bore_diameter"):
        load_scene("cvt_sheave_shaft", {"sheave": {"bore_diameter": 0.03}})


def test_rigid_sheaves_run_the_compiled_kernel_unchanged():
    """Without ``[sheave]`` (or with ``flexibility = "rigid"``) the band model has no faces: the right-hand side is
    bitwise that of the scene without the table."""
    plain = closed_loop(load_scene("band-6+2n"))
    marked = closed_loop(load_scene("band-6+2n", {"sheave": {"flexibility": "rigid"}}))
    assert plain.model.faces is None and marked.model.faces is None
    x = plain.initial_state(ratio=1.3)
    assert np.array_equal(plain.rhs(0.01, x), marked.rhs(0.01, x))


@pytest.mark.parametrize("intervals", [256, 0])
def test_compiled_flexible_faces_equal_the_numpy_twin(flexible_loop, intervals):
    """The compiled kernel with flexible faces against ``accel_numpy`` at random states, with the face table (both
    interpolate it) and without (the kernel: Clenshaw for ``c_n(r)``, the Chebyshev recurrence for ``cos n theta``,
    one complex LU for ``A`` and the complex step through it; the twin: ``A^-1 E^T`` condensed and its derivative in
    phi; both form ``eps_r = E^T x~`` with ``z - z0`` rounded once): accelerations, normal forces, slips and powers
    within 1e-12 relative or 10 x the strain's rounding sensitivity (observed below 0.02 of that), energies to 1e-12
    (observed 8e-15)."""
    import dataclasses

    from tests.band.test_compressible_kernel import _random_states, _rounding_scale

    pytest.importorskip("numba")
    m = dataclasses.replace(flexible_loop.model, face_intervals=intervals)
    assert m.backend == "numba"
    for q, v, F, M in _random_states(m, np.random.default_rng(5), 3):
        a1, i1 = m.accel(q, v, F, M)
        a0, i0 = m.accel_numpy(q, v, F, M)
        unit = _rounding_scale(m, q, v, F, M)
        for key, ref, val in [("a", a0, a1)] + [(k, np.asarray(i0[k], float), np.asarray(i1[k], float))
                                                for k in ("N", "slip", "slip_max", "dissipation", "clamp_power")]:
            tol = max(1e-12 * np.abs(ref).max(), 10 * unit.get(key, 0.0))
            assert np.abs(val - ref).max() <= tol, key
        np.testing.assert_allclose(m.energies(q, v), (m.kinetic_energy(q, v), m.elastic_energy(q)), rtol=1e-12)
