"""Rigid disks and sheaves: mass properties from sections, gyroscopic tilt frequencies."""
import numpy as np
import pytest

from cvtfem.elements.disk import (DiskFamily, axisymmetric_properties, connection_stiffness, disc_profile,
                                  sheave_profile)


@pytest.mark.parametrize("outer,m,Id,Ip", [(0.28, 32.59, 0.1781, 0.3296), (0.35, 51.53, 0.4236, 0.8051)])
def test_friswell_disks_from_geometry(outer, m, Id, Ip):
    """Friswell et al. example 5.9.1: width 0.07, bore 0.05 m, rho 7810 (4 significant digits given)."""
    p = axisymmetric_properties(*disc_profile(0.07, 0.05, outer), 7810.0)
    assert p.m == pytest.approx(m, rel=2e-4)
    assert p.Id == pytest.approx(Id, rel=5e-4)
    assert p.Ip == pytest.approx(Ip, rel=2e-4)
    assert p.zc == pytest.approx(0.0, abs=1e-15)


def test_sheave_is_sum_of_parts_and_closed_forms():
    """Flat sheave (cone angle 0) = disc + hub sleeve; conical face volume by Pappus."""
    rho, Di, Dh, Do, Lh, t = 7800.0, 0.04, 0.08, 0.2, 0.05, 0.01
    flat = axisymmetric_properties(*sheave_profile(Di, Do, Dh, Lh, t, 0.0), rho)
    disc = axisymmetric_properties(*disc_profile(t, Di, Do), rho)
    hub = axisymmetric_properties(*disc_profile(Lh, Di, Dh), rho)
    assert flat.m == pytest.approx(disc.m + hub.m, rel=1e-12)
    assert flat.Ip == pytest.approx(disc.Ip + hub.Ip, rel=1e-12)
    zc = (disc.m * t / 2 - hub.m * Lh / 2) / (disc.m + hub.m)
    assert flat.zc == pytest.approx(zc, rel=1e-12)
    Id = disc.Id + disc.m * (t / 2 - zc) ** 2 + hub.Id + hub.m * (Lh / 2 + zc) ** 2
    assert flat.Id == pytest.approx(Id, rel=1e-12)
    alpha = 0.2
    cone = axisymmetric_properties(*sheave_profile(Di, Do, Dh, 0.0, t, alpha), rho)
    h = (Do - Dh) / 2 * np.tan(alpha)
    ro, rh = Do / 2, Dh / 2
    wedge = 0.5 * (ro - rh) * h * 2 * np.pi * (rh + (ro - rh) / 3)       # Pappus: area x path of centroid
    base = np.pi * (ro**2 - (Di / 2) ** 2) * t + np.pi * (rh**2 - (Di / 2) ** 2) * h
    assert cone.m == pytest.approx(rho * (wedge + base), rel=1e-12)


@pytest.mark.parametrize("R", [0.05, 0.1, 1.0])
def test_toroidal_face_adds_circular_segment(R):
    """Toroidal - conical mass = rho * 2 pi * (segment area) * (segment centroid radius) (Pappus)."""
    Di, Do, Dh, Lh, t, alpha, rho = 0.04, 0.2, 0.08, 0.03, 0.01, 0.2, 7800.0
    cone = axisymmetric_properties(*sheave_profile(Di, Do, Dh, Lh, t, alpha, face="conical"), rho)
    tor = axisymmetric_properties(*sheave_profile(Di, Do, Dh, Lh, t, alpha, face="toroidal", torus_radius=R,
                                                  n_arc=512), rho)
    ro, rh = Do / 2, Dh / 2
    chord = (ro - rh) / np.cos(alpha)
    theta = 2 * np.arcsin(chord / (2 * R))
    area = R**2 / 2 * (theta - np.sin(theta))
    d_centroid = 4 * R * np.sin(theta / 2) ** 3 / (3 * (theta - np.sin(theta)))   # from the arc centre
    d_chord = d_centroid - R * np.cos(theta / 2)                                   # beyond the chord
    r_centroid = (ro + rh) / 2 + d_chord * np.sin(alpha)                           # outward normal (sin a, cos a)
    assert tor.m - cone.m == pytest.approx(rho * 2 * np.pi * area * r_centroid, rel=1e-4)


def test_disk_on_tilt_spring_gyroscopic_split():
    """B w^2 -+ A Omega w - k = 0 (spec §12.9): forward root rises with speed."""
    from cvtfem.modal import ModalProblem

    A, B, k, Omega = 0.8, 0.42, 2e5, 400.0
    d = DiskFamily(np.array([0]), np.array([30.0]), np.array([B]), np.array([A]))
    M, G = d.mass()[0][3:5, 3:5], d.gyroscopic()[0][3:5, 3:5]
    r = ModalProblem(M, k * np.eye(2), np.zeros((2, 2)), G, np.array([3, 4]), method="dense").solve(Omega, 2)
    fw = (A * Omega + np.sqrt((A * Omega) ** 2 + 4 * B * k)) / (2 * B)
    bw = (-A * Omega + np.sqrt((A * Omega) ** 2 + 4 * B * k)) / (2 * B)
    assert r.whirl == ("backward", "forward")
    np.testing.assert_allclose(r.wd, [bw, fw], rtol=1e-12)


def test_connection_stiffness_is_symmetric_with_six_rigid_modes():
    K = connection_stiffness(*(np.array([v]) for v in (1e8, 1e6, 1e7, 1e5)))[0]
    assert np.allclose(K, K.T)
    ev = np.linalg.eigvalsh(K)
    assert np.sum(np.abs(ev) < 1e-9 * ev.max()) == 6


def test_family_from_geometry_uses_the_section():
    profiles = [disc_profile(0.07, 0.05, 0.28), sheave_profile(0.04, 0.2, 0.08, 0.03, 0.01, 0.2, "toroidal", 0.3)]
    fam = DiskFamily.from_geometry(np.array([2, 5]), profiles, np.array([7810.0, 7850.0]))
    ref = [axisymmetric_properties(*profiles[0], 7810.0), axisymmetric_properties(*profiles[1], 7850.0)]
    np.testing.assert_allclose(fam.m, [p.m for p in ref])
    np.testing.assert_allclose(fam.Id, [p.Id for p in ref])
    assert fam.dofs.tolist()[1] == list(range(30, 36))
    M = fam.mass()[0]
    assert np.diag(M).tolist() == [fam.m[0]] * 3 + [fam.Id[0]] * 2 + [fam.Ip[0]]
