"""Craig–Bampton reduction of sheave harmonics: rigid-body inertia, frequencies on elastic supports and the
static ring deflection against the unreduced model."""
import numpy as np
import pytest
import scipy.linalg as sl
from scipy.integrate import quad

from cvtfem.elements.sheave_reduction import craig_bampton, ring_dofs
from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection
from cvtfem.errors import InputError

SHEAVE = SheaveSection(0.0175, 0.03, 0.095, 0.03, 0.008, np.radians(10.0), "toroidal", 0.5)
CONICAL = SheaveSection(0.0175, 0.03, 0.095, 0.03, 0.008, np.radians(10.0))
Z_C = 0.01                                     # the shaft node, m from the back face
SUPPORT = {"axial": 2e8, "spin": 3e5, "x": 2e8, "y": 2e8, "tilt_y": 1e6, "tilt_x": 1e6}   # N/m, N m/rad


def _disc_integral(s, f):
    pts = [s.bore_radius, s.hub_radius, s.outer_radius]
    return sum(quad(f, a, b, epsabs=0, epsrel=1e-13)[0] for a, b in zip(pts[:-1], pts[1:]))


def _rigid_inertia(s):
    """Mass, axial moment, static moment about z_c and transverse moment about z_c of the solid of revolution:
    the disc between the back face and the contact face, and the hub sleeve behind it."""
    zf, rho, hl = s.face_height, s.rho, s.hub_length
    b, rh = s.bore_radius, s.hub_radius
    ring1, ring3 = (rh ** 2 - b ** 2) / 2, (rh ** 4 - b ** 4) / 4        # int r dr, int r^3 dr over the sleeve
    m = 2 * np.pi * rho * (_disc_integral(s, lambda r: r * zf(r)) + hl * ring1)
    Jp = 2 * np.pi * rho * (_disc_integral(s, lambda r: r ** 3 * zf(r)) + hl * ring3)
    S = 2 * np.pi * rho * (_disc_integral(s, lambda r: r * (zf(r) ** 2 / 2 - Z_C * zf(r)))
                           + ring1 * (-hl ** 2 / 2 - Z_C * hl))
    Jt = Jp / 2 + 2 * np.pi * rho * (_disc_integral(s, lambda r: r * (zf(r) ** 3 / 3 - Z_C * zf(r) ** 2 + Z_C ** 2 * zf(r)))
                                     + ring1 * ((hl + Z_C) ** 3 - Z_C ** 3) / 3)
    return m, Jp, S, Jt


@pytest.mark.parametrize("face, rtol", [("conical", 1e-11), ("toroidal", 1e-8)])
@pytest.mark.parametrize("n, family", [(0, "cos"), (0, "sin"), (1, "cos"), (1, "sin")])
def test_interface_block_is_the_rigid_body_inertia(n, family, face, rtol):
    """Exact for straight faces; a toroidal face is followed by the quadratic elements' parabolic edges
    (1.4e-9 here)."""
    section = {"conical": CONICAL, "toroidal": SHEAVE}[face]
    m, Jp, S, Jt = _rigid_inertia(section)
    red = craig_bampton(HarmonicSheave(section, n, family, 24, 2), 4, tilt_centre=Z_C)
    expected = {(0, "cos"): [[m]], (0, "sin"): [[Jp]], (1, "cos"): [[m, S], [S, Jt]],
                (1, "sin"): [[m, -S], [-S, Jt]]}[(n, family)]
    k = len(expected)
    np.testing.assert_allclose(red.M[:k, :k], expected, rtol=rtol, atol=rtol * 1e-3 * Jt)
    np.testing.assert_allclose(red.K[:k, :k], 0.0, atol=1e-6 * np.abs(red.K).max())   # rigid: no strain


def _constrained_full(model, red, n_rigid, ring):
    """The unreduced model with its bore tied to the rigid coordinates and the ring DOFs kept: coordinates
    [rigid, ring, every interior DOF] (the Craig–Bampton basis with all interior DOFs as 'modes')."""
    K, M = model.matrices
    keep = model.free_dofs(clamped=False)
    boundary = np.union1d(np.intersect1d(model.bore_dofs(), keep), ring)
    interior = np.setdiff1d(keep, boundary)
    T = np.zeros((K.shape[0], n_rigid + len(ring) + len(interior)))
    T[boundary, :n_rigid + len(ring)] = red.basis[boundary, :n_rigid + len(ring)]
    T[interior, n_rigid + len(ring) + np.arange(len(interior))] = 1.0
    return T.T @ (K @ T), T.T @ (M @ T)


@pytest.mark.parametrize("n, family", [(0, "cos"), (0, "sin"), (1, "cos"), (2, "cos"), (3, "cos")])
def test_reduced_frequencies_on_supports_match_the_full_model(n, family):
    """Bore on elastic supports (the shaft's stiffness), 10 fixed-interface modes: every frequency below 10 kHz of
    the reduced model within 0.5 % of the unreduced one."""
    model = HarmonicSheave(SHEAVE, n, family, 24, 2)
    red = craig_bampton(model, 10, ring_radius=0.06, tilt_centre=Z_C)
    rigid = [label for label in red.labels if label in SUPPORT]
    ring = np.intersect1d(ring_dofs(model, 0.06), model.free_dofs(clamped=False))
    Kf, Mf = _constrained_full(model, red, len(rigid), ring)
    Kr = red.K.copy()
    for j, label in enumerate(rigid):
        Kf[j, j] += SUPPORT[label]
        Kr[j, j] += SUPPORT[label]
    full = np.sqrt(np.abs(sl.eigh(Kf, Mf, eigvals_only=True))) / (2 * np.pi)
    reduced = np.sqrt(np.abs(sl.eigh(Kr, red.M, eigvals_only=True))) / (2 * np.pi)
    low = full[full < 10e3]
    assert len(low) >= 1
    np.testing.assert_allclose(reduced[:len(low)], low, rtol=0.005)


def test_static_ring_load_is_exact():
    """An axial ring load at the contact ring, bore clamped: the reduced model's ring deflection equals the full
    model's (the ring's static modes are in the basis), and the rim follows within 1 %."""
    model = HarmonicSheave(SHEAVE, 0, "cos", 24, 2)
    red = craig_bampton(model, 6, ring_radius=0.06, tilt_centre=Z_C)
    K, _ = model.matrices
    dofs = ring_dofs(model, 0.06)
    load = np.zeros(K.shape[0])
    load[dofs[2]] = 2e4
    full = model.static(load)
    free = [i for i, label in enumerate(red.labels) if label != "axial"]
    f_red = red.basis[:, free].T @ load
    q = np.linalg.solve(red.K[np.ix_(free, free)], f_red)
    u = red.basis[:, free] @ q
    assert u[dofs[2]] == pytest.approx(full[dofs[2]], rel=1e-9)
    rim = np.flatnonzero(np.isclose(model.basis.doflocs[0], SHEAVE.outer_radius))
    np.testing.assert_allclose(u[rim], full[rim], rtol=0.01, atol=1e-3 * abs(full[dofs[2]]))


def test_ring_must_lie_on_the_face():
    with pytest.raises(InputError, match="ring_radius"):
        craig_bampton(HarmonicSheave(SHEAVE, 0, "cos", 12, 1), 2, ring_radius=0.2)


def test_scene_sheave_inertia_matches_the_rigid_disk_of_the_rotor_model():
    """Two implementations: the rotor's rigid sheave (Green's theorem on the section polygon; the toroidal face as
    1024 chords here, the rotor's 64 fall 1e-5 short of the arc) and the Craig–Bampton interface block of the
    solid model of the same scene disk (quadratic elements, tilts about the centre of mass): mass, polar and
    diametral moments agree to 1e-7."""
    from cvtfem.elements.disk import axisymmetric_properties, sheave_profile
    from cvtfem.machines.sheave import sheave_section
    from cvtfem.scene.loader import load_scene

    scene = load_scene("cvt_sheave_shaft")
    d = scene.disk[0]
    section = sheave_section(scene)
    rigid = axisymmetric_properties(*sheave_profile(d.inner_diameter, d.outer_diameter, d.hub_diameter,
                                                    d.hub_length, d.rim_thickness, d.cone_angle, d.face,
                                                    d.torus_radius, n_arc=1024), section.rho)
    axial = craig_bampton(HarmonicSheave(section, 0, "cos", 24, 2), 0)
    spin = craig_bampton(HarmonicSheave(section, 0, "sin", 24, 2), 0)
    lateral = craig_bampton(HarmonicSheave(section, 1, "cos", 24, 2), 0, tilt_centre=rigid.zc)
    np.testing.assert_allclose([axial.M[0, 0], spin.M[0, 0], lateral.M[1, 1]], [rigid.m, rigid.Ip, rigid.Id],
                               rtol=1e-7)
    assert abs(lateral.M[0, 1]) < 1e-6 * rigid.m * section.outer_radius      # tilting about the centre of mass


def test_scene_without_sheave_is_refused():
    from cvtfem.machines.sheave import sheave_section
    from cvtfem.scene.loader import load_scene

    with pytest.raises(InputError, match="disk"):
        sheave_section(load_scene("friswell_5_9_1"))
