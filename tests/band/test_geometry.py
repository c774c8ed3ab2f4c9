"""Band geometry (spec 4.1), inertia A(phi) (1.45 corrected) and Ritz data (4.4)."""
import numpy as np
import pytest

from cvtfem.elements.band.geometry import Sheave, admissible_phi, path_point, phi_for_ratio, phi_for_ratios, radii
from cvtfem.elements.band.inertia import band_inertia, complex_step
from cvtfem.elements.band.ritz import ritz_alpha, ritz_functions, ritz_shapes
from cvtfem.errors import InputError

LENGTH, L, MASS = 0.756, 0.1746, 1.5


@pytest.mark.parametrize("phi", np.linspace(-0.6, 0.6, 7))
def test_closure_and_derivatives(phi):
    r, dr, ddr = radii(phi, LENGTH, L)
    # (1.36): band length closes and the radius difference matches the span angle
    assert r[0] * (np.pi + 2 * phi) + r[1] * (np.pi - 2 * phi) + 2 * L * np.cos(phi) == pytest.approx(LENGTH, rel=1e-14)
    assert r[0] - r[1] == pytest.approx(L * np.sin(phi), rel=1e-12, abs=1e-15)
    # analytic derivatives against complex-step derivatives of the radii
    assert complex_step(lambda p: radii(p, LENGTH, L)[0], phi) == pytest.approx(dr, rel=1e-12)
    assert complex_step(lambda p: radii(p, LENGTH, L)[1], phi) == pytest.approx(ddr, rel=1e-10, abs=1e-14)


def test_reference_table_of_spec_section_9():
    for ratio, phi_ref, r1, r2 in [(0.43, 0.289, 87.4, 37.6), (1.0, 0.0, 64.8, 64.8), (2.4, -0.299, 36.7, 88.0)]:
        phi = phi_for_ratio(ratio, LENGTH, L)
        r, _, _ = radii(phi, LENGTH, L)
        assert phi == pytest.approx(phi_ref, abs=1e-3)
        assert r * 1e3 == pytest.approx([r1, r2], abs=0.06)
        assert r[1] / r[0] == pytest.approx(ratio, rel=1e-12)


def test_unreachable_ratio_is_an_input_error():
    with pytest.raises(InputError, match="ratio"):
        phi_for_ratio(1e4, LENGTH, L)


def test_torus_flank_angle_and_curvature():
    sh = Sheave("toroidal", 0.0, R=1.5, y=0.2, w=0.0165)
    r = np.linspace(0.036, 0.088, 5)
    assert np.degrees(sh.gamma_at(np.array([0.0367, 0.088]))) == pytest.approx([9.1, 11.1], abs=0.05)
    # tan(gamma) = -dz0/dr and d2z0/dr2 = -1 / (R cos^3 gamma)
    assert -complex_step(sh.z0, r) == pytest.approx(sh.tan_gamma(r), rel=1e-12)
    assert complex_step(lambda x: -sh.tan_gamma(x), r) == pytest.approx(sh.d2z0(r), rel=1e-10)
    cone = Sheave("conical", np.radians(10.0), w=0.0165)
    assert -complex_step(cone.z0, r) == pytest.approx(np.tan(np.radians(10.0)), rel=1e-14)


@pytest.mark.parametrize("phi", np.linspace(-0.62, 0.62, 9))
def test_band_inertia_matches_quadrature_of_kinetic_energy(phi):
    """A(phi) = rho int |du/dphi|^2 ds over the path map (section 4.3), Gauss quadrature per piece."""
    r, _, _ = radii(phi, LENGTH, L)
    a1, a2, Lc = r[0] * (np.pi / 2 + phi), r[1] * (np.pi / 2 - phi), L * np.cos(phi)
    x, w = np.polynomial.legendre.leggauss(48)
    total = 0.0
    for lo, hi in [(-a1, a1), (a1, a1 + Lc), (LENGTH / 2 - a2, LENGTH / 2 + a2), (LENGTH / 2 + a2, LENGTH - a1)]:
        s = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        du = np.imag(path_point(s, phi + 1e-30j, LENGTH, L)) / 1e-30
        total += 0.5 * (hi - lo) * np.sum(w * (du ** 2).sum(axis=0))
    assert band_inertia(phi, LENGTH, L, MASS) == pytest.approx(MASS / LENGTH * total, rel=1e-8)
    assert admissible_phi(LENGTH, L)[1] > 0.62


def test_printed_inertia_lacks_the_span_rotation_term():
    """Erratum 1: dropping +1/6 changes A by rho L^3 cos^3 / 6, visible at the 2 % level."""
    rho = MASS / LENGTH
    missing = rho * L ** 3 / 6
    assert missing / band_inertia(0.0, LENGTH, L, MASS) > 0.02


def test_path_map_is_continuous_and_closed():
    phi = 0.2
    s = np.linspace(0, LENGTH, 20001)
    u = path_point(s, phi, LENGTH, L)
    steps = np.linalg.norm(np.diff(u, axis=1), axis=0)
    assert steps.max() == pytest.approx(LENGTH / 20000, rel=1e-6)
    assert np.allclose(u[:, 0], u[:, -1], atol=1e-12)


def test_ritz_alpha_table_and_inextensibility():
    a = ritz_alpha(6)
    table = np.array([[2.4674, 0, 4.1888, 0, 0, 0], [0, 0.4674, 0, 2.0944, 0, 2.0],
                      [4.1888, 0, 9.8696, 0, 7.5398, 0], [0, 2.0944, 0, 9.8696, 0, 11.3097],
                      [0, 0, 7.5398, 0, 22.2066, 0], [0, 2.0, 0, 11.3097, 0, 20.2066]])
    assert a == pytest.approx(table, abs=6e-5)
    j = np.arange(1, 4)
    assert np.diag(a)[::2] == pytest.approx(j ** 2 * np.pi ** 2 / 4, rel=1e-13)
    assert np.diag(a)[1::2] == pytest.approx(j ** 2 * np.pi ** 2 / 4 - 2 * np.sin(j * np.pi / 2) ** 2, rel=1e-13)
    # f_theta vanishes at the arc ends (global length), f_r = -d f_theta / d theta (1.54), int f_r = 0
    F, _ = ritz_shapes(np.array([-1.0, 1.0]), 8)
    assert np.abs(F).max() < 1e-14
    ts = 1.3
    xi = np.linspace(-0.9, 0.9, 7)
    ft, fr = ritz_functions(xi, ts, 8)
    h = 1e-6
    num = (ritz_shapes(xi + h, 8)[0] - ritz_shapes(xi - h, 8)[0]) / (2 * h) / ts
    assert fr == pytest.approx(-num, abs=1e-7)
    x, w = np.polynomial.legendre.leggauss(40)
    assert np.abs(ritz_functions(x, ts, 8)[1] @ w).max() < 1e-12


def test_vectorised_ratio_inversion_equals_the_scalar_one():
    ratios = np.geomspace(0.3, 3.5, 50)
    phis = phi_for_ratios(ratios, LENGTH, L)
    assert np.abs(phis - [phi_for_ratio(i, LENGTH, L) for i in ratios]).max() < 1e-13
    r = radii(phis, LENGTH, L)[0]
    assert np.abs(r[1] / r[0] / ratios - 1).max() < 1e-13
    with pytest.raises(InputError, match="ratio"):
        phi_for_ratios([2.0, 1e4], LENGTH, L)
