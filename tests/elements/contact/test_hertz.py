"""Hertz law, stiffness and contact ellipse (contact-models digest §4.1, §4.3, §10.4 items 2 and 7)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ellipe, ellipk

from cvtfem.elements.contact.hertz import (compliance, contact_ellipse, hertz_force, hertz_potential,
                                           hertz_shape, hertz_stiffness, relative_curvature,
                                           sheave_curvatures)
from cvtfem.errors import InputError

E, NU = 2.1e11, 0.3
ETA = compliance(E, NU, E, NU)


def test_sphere_on_plane_fixture_of_the_digest():
    """Digest §4.3 fixture: R = 20 mm steel sphere on a steel plane, N = 2 kN: c = 4/3 E* sqrt(R)
    = 2.176e10 N/m^1.5, Delta = 20.4 um, a = b = 0.638 mm, p_max = 2.34 GPa, dN/dDelta = 1.47e8 N/m."""
    R, N = 0.02, 2000.0
    sum_k, Om = relative_curvature(np.eye(2) / R, np.zeros((2, 2)))
    assert (sum_k, Om) == (pytest.approx(2 / R, rel=1e-15), 0.0)
    c = hertz_stiffness(sum_k, Om, ETA)
    assert c == pytest.approx(4 / 3 * E / (2 * (1 - NU ** 2)) * np.sqrt(R), rel=1e-14)
    assert c == pytest.approx(2.176e10, rel=5e-4)
    delta = (N / c) ** (2 / 3)
    assert delta == pytest.approx(20.4e-6, rel=5e-3)
    a, b, p_max = contact_ellipse(N, sum_k, Om, ETA)
    assert a == b == pytest.approx(0.638e-3, rel=1e-3)
    assert a ** 2 / R == pytest.approx(delta, rel=1e-13)       # Hertz: Delta = a^2 / R
    assert p_max == pytest.approx(2.34e9, rel=5e-3)
    assert hertz_force(delta, c)[1] == pytest.approx(1.47e8, rel=5e-3)


def test_shape_coefficients_reproduce_the_digest_table():
    Om = np.array([0.1, 0.3, 0.5, 0.7, 0.9, 0.99])
    n_a, n_b, n_d = hertz_shape(Om)
    assert np.allclose(n_a, [1.0704, 1.2416, 1.4858, 1.9051, 3.0929, 7.7742], rtol=0, atol=6e-5)
    assert np.allclose(n_b, [0.9364, 0.8224, 0.7171, 0.6080, 0.4607, 0.2866], rtol=0, atol=6e-5)
    assert np.allclose(n_d, [0.9978, 0.9792, 0.9376, 0.8586, 0.6799, 0.3839], rtol=0, atol=6e-5)
    assert np.array_equal(hertz_shape(np.zeros(2)), np.ones((3, 2)))


def test_ellipse_satisfies_johnsons_elliptic_contact_solution():
    """Independent check (Johnson, Contact Mechanics, ch. 3-4): the pressure p0 sqrt(1 - x^2/a^2 -
    y^2/b^2) with p0 = p_max displaces the surface by (L - M x^2 - N y^2)/E*, where
    L = p0 b K(e), M = p0 b (K - E)/(e^2 a^2), N = p0 b (a^2/b^2 E - K)/(e^2 a^2), e^2 = 1 - b^2/a^2.
    Contact requires M/E* = lambda_2/2, N/E* = lambda_1/2 (the relative curvatures) and L/E* = Delta."""
    rng = np.random.default_rng(2)
    n = 200
    lam2 = rng.uniform(1.0, 100.0, n)
    lam1 = lam2 * rng.uniform(1.01, 500.0, n)
    theta = rng.uniform(0, np.pi, n)
    c_, s_ = np.cos(theta), np.sin(theta)
    Q = np.stack([np.stack([c_, -s_], -1), np.stack([s_, c_], -1)], -2)
    Krel = Q @ (np.array([[1.0, 0.0], [0.0, 0.0]]) * lam1[:, None, None]
                + np.array([[0.0, 0.0], [0.0, 1.0]]) * lam2[:, None, None]) @ np.swapaxes(Q, 1, 2)
    K1 = Krel * rng.uniform(0.2, 0.8, n)[:, None, None]
    sum_k, Om = relative_curvature(K1, Krel - K1)
    assert np.allclose(sum_k, lam1 + lam2, rtol=1e-13)
    N = rng.uniform(10.0, 5e3, n)
    a, b, p0 = contact_ellipse(N, sum_k, Om, ETA)
    m = 1 - (b / a) ** 2
    Kk, Ee = ellipk(m), ellipe(m)
    Es = 1 / ETA
    assert np.allclose(p0 * b * (Kk - Ee) / (m * a ** 2) / Es, lam2 / 2, rtol=1e-9)
    assert np.allclose(p0 * b * ((a / b) ** 2 * Ee - Kk) / (m * a ** 2) / Es, lam1 / 2, rtol=1e-9)
    delta = (N / hertz_stiffness(sum_k, Om, ETA)) ** (2 / 3)
    assert np.allclose(p0 * b * Kk / Es, delta, rtol=1e-9)
    assert np.allclose(p0, 3 * N / (2 * np.pi * a * b), rtol=1e-14)


def test_equal_curvatures_give_a_circle_and_stiffness_grows_without_bound_towards_line_contact():
    sum_k, Om = relative_curvature(np.diag([40.0, 40.0])[None], np.diag([10.0, 10.0])[None])
    a, b, _ = contact_ellipse(1e3, sum_k, Om, ETA)
    assert Om[0] == 0.0 and a[0] == b[0]
    Om = np.array([0.9, 0.99, 0.999, 0.9999, 1 - 1e-8])
    c = hertz_stiffness(100.0, Om, ETA)
    assert np.all(np.diff(c) > 0.0) and c[-1] > 10 * c[0]
    with pytest.raises(InputError):
        hertz_shape(1.0)


def test_force_law_at_grazing_and_potential_derivative():
    c = 2e10
    delta = np.array([-1e-9, 0.0, 1e-300, 1e-9, 2e-5])
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        N, dN = hertz_force(delta, c)
    assert np.array_equal(N[:2], [0.0, 0.0]) and np.array_equal(dN[:2], [0.0, 0.0])
    assert np.all(np.isfinite(N)) and np.all(np.isfinite(dN))
    assert N[3] == pytest.approx(c * 1e-9 ** 1.5, rel=1e-15)
    d = np.geomspace(1e-9, 1e-4, 50)
    h = 1e-7 * d
    assert np.allclose((hertz_potential(d + h, c) - hertz_potential(d - h, c)) / (2 * h), hertz_force(d, c)[0],
                       rtol=1e-8)
    assert np.allclose((hertz_force(d + h, c)[0] - hertz_force(d - h, c)[0]) / (2 * h), hertz_force(d, c)[1],
                       rtol=1e-8)


def test_sheave_curvatures_of_a_torus_and_a_cone():
    """Torus meridian z = sqrt(Rt^2 - (r + y)^2): meridional curvature 1/Rt; cone: 0 and
    circumferential sin(gamma) / r (tan gamma / (r sqrt(1 + tan^2 gamma)))."""
    Rt, y, r = 0.25, -0.1, np.linspace(0.036, 0.088, 5)
    u = r + y
    fp, fpp = -u / np.sqrt(Rt ** 2 - u ** 2), -Rt ** 2 / (Rt ** 2 - u ** 2) ** 1.5
    assert np.allclose(sheave_curvatures(r, fp, fpp)[0], 1 / Rt, rtol=1e-13)
    g = np.radians(10.0)
    km, kc = sheave_curvatures(r, -np.tan(g), 0.0)
    assert np.all(km == 0.0) and np.allclose(kc, np.sin(g) / r, rtol=1e-14)
