"""Estimate formulas of section 1.3 and the 1-DOF equilibrium model (section 4.2)."""
import numpy as np
import pytest
from scipy.optimize import brentq

from cvtfem.elements.band.equilibrium import (cone_equilibrium_angle, equilibrium_angle, forces_for_angle,
                                              potential, potential_derivatives, toroidal_stability_limit)
from cvtfem.elements.band.estimates import (chain_frequency, compressed_stiffness_factor, euler_force,
                                            green_compressed, green_plain, link_frequency, min_clamping_force)
from cvtfem.elements.band.geometry import Sheave, radii
from cvtfem.elements.band.inertia import complex_step
from cvtfem.errors import InputError

LENGTH, L = 0.756, 0.1746


def test_clamping_estimate_published_values():
    assert min_clamping_force(200.0, 0.037, 0.1, np.radians(10)) == pytest.approx(26.6e3, rel=2e-3)
    # spec section 9: r1 = 36.7 mm at i = 2.4, gamma 9..10 deg -> 26.9 kN
    assert min_clamping_force(200.0, 0.0367, 0.1, np.radians(9.1)) == pytest.approx(26.9e3, rel=3e-3)
    with pytest.raises(InputError, match="radius"):
        min_clamping_force(200.0, -0.01, 0.1, 0.1)


def test_euler_force_and_green_functions():
    E, I, l = 2.1e11, 6.8e-12, 0.033
    P_star = euler_force(E, I, l)
    assert P_star == pytest.approx(12.94e3, rel=1e-3)
    EI = E * I
    assert green_plain(l / 2, l / 2, l, EI) == pytest.approx(l ** 3 / (48 * EI), rel=1e-13)
    # small compression tends to the plain function; amplification values of section 3.3
    assert green_compressed(0.3 * l, 0.6 * l, l, EI, 1e-6 * P_star) == pytest.approx(
        green_plain(0.3 * l, 0.6 * l, l, EI), rel=1e-5)
    P = 0.17 * P_star
    mid = green_compressed(l / 2, l / 2, l, EI, P) / green_plain(l / 2, l / 2, l, EI)
    assert mid == pytest.approx(1.20, abs=0.01)
    assert mid == pytest.approx(compressed_stiffness_factor(P, P_star), rel=0.02)
    s = np.linspace(0.01, 0.99, 99) * l
    S, S2 = np.meshgrid(s, s)
    assert (green_compressed(S, S2, l, EI, P) / green_plain(S, S2, l, EI)).max() == pytest.approx(1.237, abs=2e-3)
    # symmetry (Maxwell reciprocity)
    assert green_compressed(0.2 * l, 0.7 * l, l, EI, P) == pytest.approx(green_compressed(0.7 * l, 0.2 * l, l, EI, P))
    with pytest.raises(InputError, match="Euler"):
        green_compressed(0.1, 0.2, l, EI, 2 * P_star)


def test_chain_frequencies_ranges_of_section_3_4():
    r = radii(np.array([0.289, -0.299]), LENGTH, L)[0]
    w = np.array([1000, 6000]) * np.pi / 30
    assert link_frequency(w[0], r[0, 1], 0.009) == pytest.approx(427, abs=5)  # smallest r1 at 1000 rpm
    assert link_frequency(w[1], r[0, 0], 0.009) == pytest.approx(6100, abs=20)
    assert chain_frequency(w[1], r[0, 0], LENGTH) == pytest.approx(72.6, abs=0.5)


def test_cone_equilibrium_formula_and_unconditional_stability():
    g = np.radians(10)
    cone = Sheave("conical", g, w=0.0165)
    for F1, F2 in [(30e3, 30e3), (25e3, 35e3), (40e3, 20e3), (20e3, 40e3)]:
        phi = equilibrium_angle((F1, F2), (cone, cone), LENGTH, L)
        assert phi == pytest.approx(cone_equilibrium_angle(F1, F2, g), abs=1e-12)
        d1, d2 = potential_derivatives(phi, (F1, F2), (cone, cone), LENGTH, L)
        assert abs(d1) < 1e-9 * F1 and d2 > 0
    # the analytic derivatives agree with complex-step derivatives of the potential
    phi = 0.1
    d1, d2 = potential_derivatives(phi, (25e3, 35e3), (cone, cone), LENGTH, L)
    assert complex_step(lambda p: potential(p, (25e3, 35e3), (cone, cone), LENGTH, L), phi) == pytest.approx(d1)
    # Pi'' > 0 at every equilibrium of the admissible range (section 4.2: cones are always stable)
    for phi in np.linspace(-0.6, 0.6, 25):
        rho = forces_for_angle(phi, (cone, cone), LENGTH, L)
        assert potential_derivatives(phi, (rho * 1e4, 1e4), (cone, cone), LENGTH, L)[1] > 0


def _pi2_symmetric(R, gamma):
    """Pi'' at phi = 0 of equal tori whose flank angle at the contact radius is gamma."""
    r0 = radii(0.0, LENGTH, L)[0][0]
    sh = Sheave("toroidal", 0.0, R=R, y=R * np.sin(gamma) - r0, w=0.0165)
    return potential_derivatives(0.0, (3e4, 3e4), (sh, sh), LENGTH, L)[1]


@pytest.mark.parametrize("deg", [8.0, 10.0, 12.0])
def test_toroidal_stability_limit_by_bisection(deg):
    gamma = np.radians(deg)
    closed = toroidal_stability_limit(L, gamma)
    limit = brentq(lambda R: _pi2_symmetric(R, gamma), 0.05 * closed, 20 * closed, xtol=1e-10)
    assert limit == pytest.approx(closed, rel=1e-3)
    assert _pi2_symmetric(1.05 * closed, gamma) > 0 > _pi2_symmetric(0.95 * closed, gamma)


def test_stability_limit_published_example():
    assert toroidal_stability_limit(0.19, np.radians(10)) == pytest.approx(0.89, abs=0.005)


def test_reference_torus_equilibrium_at_ratio_2_4_is_stable():
    sh = Sheave("toroidal", 0.0, R=1.5, y=0.2, w=0.0165)
    phi = -0.2984
    rho = forces_for_angle(phi, (sh, sh), LENGTH, L)
    assert equilibrium_angle((rho * 3e4, 3e4), (sh, sh), LENGTH, L) == pytest.approx(phi, abs=1e-10)
    assert potential_derivatives(phi, (rho * 3e4, 3e4), (sh, sh), LENGTH, L)[1] > 0
