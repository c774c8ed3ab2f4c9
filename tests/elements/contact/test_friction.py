"""Regularised friction laws (contact-models digest §2.4–2.5, §10.4 item 3 and 6)."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.contact.friction import (LAWS, POTENTIAL_LAWS, friction_coefficient, friction_force,
                                              friction_gain, friction_potential, friction_slope, friction_vector)
from cvtfem.errors import InputError

F0, V0, EPS = 0.1, 1e-3, 0.2


@pytest.mark.parametrize("law", LAWS)
def test_slope_equals_difference_quotient_and_gain_is_f_over_v(law):
    v = V0 * np.concatenate([np.geomspace(1e-6, 1e3, 400), [0.3, 0.79, 0.81, 1.19, 1.21]])
    v = v[np.abs(v / V0 - 1) > 1e-3]            # off the kink of linear-saturated
    h = 1e-7 * V0
    fd = (friction_coefficient(v + h, F0, V0, law, EPS) - friction_coefficient(v - h, F0, V0, law, EPS)) / (2 * h)
    assert np.allclose(friction_slope(v, F0, V0, law, EPS), fd, rtol=1e-6, atol=1e-6 * F0 / V0)
    assert np.allclose(friction_gain(v, F0, V0, law, EPS) * v, friction_coefficient(v, F0, V0, law, EPS),
                       rtol=1e-13, atol=0)


@pytest.mark.parametrize("law", POTENTIAL_LAWS)
def test_potential_is_zero_at_rest_and_its_derivative_is_the_law(law):
    """``Phi(0) = 0``, ``Phi' = f`` by central differences, and ``Phi`` convex (the implicit friction step minimises
    it); a law without a closed form is an InputError naming it."""
    v = V0 * np.concatenate([np.geomspace(1e-4, 1e3, 300), [0.5, 0.99, 1.01, 2.0]])
    h = 1e-6 * V0
    fd = (friction_potential(v + h, F0, V0, law) - friction_potential(v - h, F0, V0, law)) / (2 * h)
    assert friction_potential(0.0, F0, V0, law) == pytest.approx(0.0, abs=1e-18)
    assert np.allclose(fd, friction_coefficient(v, F0, V0, law), rtol=1e-6, atol=1e-8 * F0)
    w = np.linspace(0, 5 * V0, 501)
    assert np.all(np.diff(friction_potential(w, F0, V0, law), 2) >= -1e-18)


def test_potential_of_the_table21_law_is_refused():
    with pytest.raises(InputError, match="`law`.*smooth"):
        friction_potential(1.0, F0, V0, "smooth")


@pytest.mark.parametrize("law", LAWS)
def test_zero_slip_small_slip_and_saturation(law):
    """psi(0) = f'(0) finite, f(0) = 0, f(v) -> f0 far above v0 and never above it."""
    slope0 = 1.5 if law == "smoothed" else 1.0
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        assert friction_gain(0.0, F0, V0, law, EPS) == pytest.approx(slope0 * F0 / V0, rel=1e-15)
        assert friction_coefficient(0.0, F0, V0, law, EPS) == 0.0
        assert friction_gain(1e-300, F0, V0, law, EPS) == pytest.approx(slope0 * F0 / V0, rel=1e-15)
    far = friction_coefficient(1e6 * V0, F0, V0, law, EPS)
    assert far == pytest.approx(F0, rel=1e-6)   # arctan: 1 - 4/(pi^2 1e6)
    v = V0 * np.geomspace(1e-9, 1e9, 1000)
    assert np.all(friction_coefficient(v, F0, V0, law, EPS) <= F0)
    assert np.all(np.diff(friction_coefficient(v, F0, V0, law, EPS)) >= 0.0)


def test_table21_smooth_law_values_and_c1_not_c2():
    """Table 2.1 'smooth': linear up to (1-eps) v0, f0 from (1+eps) v0, f(v0) = f0 (1 - eps/4);
    the slope is continuous at both seams, f'' jumps by -f0/(2 eps v0^2) (digest §2.4 [D])."""
    f = lambda v: friction_coefficient(v, F0, V0, "smooth", EPS)   # noqa: E731
    lo, hi = (1 - EPS) * V0, (1 + EPS) * V0
    assert f(lo) == pytest.approx(F0 * (1 - EPS), rel=1e-14)
    assert f(hi) == pytest.approx(F0, rel=1e-14)
    assert f(V0) == pytest.approx(F0 * (1 - EPS / 4), rel=1e-14)
    h = 1e-6 * V0
    for seam in (lo, hi):
        left, right = (f(seam) - f(seam - h)) / h, (f(seam + h) - f(seam)) / h
        assert abs(right - left) < 1e-4 * F0 / V0     # C1: slopes agree to O(h f'')
        d2_left = (f(seam - 2 * h) - 2 * f(seam - h) + f(seam)) / h ** 2
        d2_right = (f(seam) - 2 * f(seam + h) + f(seam + 2 * h)) / h ** 2
        # not C2: one side has f'' = 0, the other -f0/(2 eps v0^2)
        assert d2_right - d2_left == pytest.approx((-1 if seam == lo else 1) * F0 / (2 * EPS * V0 ** 2), rel=1e-3)


def test_linear_saturated_is_c0_with_a_slope_jump_and_arctan_limits():
    f = lambda v: friction_coefficient(v, F0, V0, "nonsmooth")     # noqa: E731
    h = 1e-9 * V0
    assert abs(f(V0 + h) - f(V0 - h)) < 2e-9 * F0
    assert friction_slope(V0 * (1 - 1e-9), F0, V0, "nonsmooth") == F0 / V0
    assert friction_slope(V0 * (1 + 1e-9), F0, V0, "nonsmooth") == 0.0
    # arctan: f'(0) = f0/v0, f(v0) = f0 (2/pi) atan(pi/2), psi ~ f0/v0 [1 - (pi v / 2 v0)^2 / 3]
    assert friction_coefficient(V0, F0, V0, "arctan") == pytest.approx(F0 * 2 / np.pi * np.arctan(np.pi / 2))
    v = 1e-5 * V0
    assert friction_gain(v, F0, V0, "arctan") == pytest.approx(F0 / V0 * (1 - (np.pi * v / (2 * V0)) ** 2 / 3),
                                                               rel=1e-15)


@pytest.mark.parametrize("law", LAWS)
def test_vector_force_and_jacobian_against_finite_differences(law):
    rng = np.random.default_rng(3)
    n = 300
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    v = rng.normal(size=(n, 3)) * V0 * np.geomspace(1e-3, 1e2, n)[:, None]
    N = rng.uniform(10.0, 2000.0, n)
    F, J = friction_force(v, N, F0, V0, law, EPS, normal=normal)
    vt = v - np.sum(v * normal, axis=1, keepdims=True) * normal
    speed = np.linalg.norm(vt, axis=1)
    assert np.allclose(np.linalg.norm(F, axis=1), N * friction_coefficient(speed, F0, V0, law, EPS), rtol=1e-13)
    ref = -N[:, None] * friction_vector(vt, F0, V0, law, EPS)
    assert np.all(np.abs(F - ref) <= 1e-13 * np.linalg.norm(ref, axis=1, keepdims=True))
    assert np.allclose(np.sum(F * normal, axis=1), 0.0, atol=1e-12 * N * F0)
    keep = np.abs(speed / V0 - 1) > 1e-3
    if law == "smooth":
        keep &= (np.abs(speed / V0 - 1 + EPS) > 1e-3) & (np.abs(speed / V0 - 1 - EPS) > 1e-3)
    h = 1e-7 * np.maximum(speed, 1e-3 * V0)
    for j in range(3):
        dv = np.zeros((n, 3))
        dv[:, j] = h
        fd = (friction_force(v + dv, N, F0, V0, law, EPS, normal)[0]
              - friction_force(v - dv, N, F0, V0, law, EPS, normal)[0]) / (2 * h[:, None])
        scale = N * F0 / V0
        assert np.all(np.abs(J[keep, :, j] - fd[keep]) <= 1e-6 * scale[keep, None])


@pytest.mark.parametrize("law", LAWS)
def test_zero_slip_force_is_zero_and_jacobian_is_viscous(law):
    """Digest §10.4 item 3: v_r = 0 and |v_r| = 1e-300 give a finite force tending to 0 and the
    Jacobian -(f'(0) N) E_t (f'(0) = f0/v0; 1.5 f0/v0 for 'smoothed')."""
    normal = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    N = np.array([1e3, 5e3])
    slope0 = (1.5 if law == "smoothed" else 1.0) * F0 / V0
    Et = np.eye(3) - normal[:, :, None] * normal[:, None, :]
    for v in (np.zeros((2, 3)), np.array([[1e-300, 0.0, 0.0], [0.0, -1e-300, 0.0]])):
        with np.errstate(divide="raise", invalid="raise", over="raise"):
            F, J = friction_force(v, N, F0, V0, law, EPS, normal)
        assert np.all(np.abs(F) <= slope0 * N[:, None] * 1e-300)
        assert np.allclose(J, -slope0 * N[:, None, None] * Et, rtol=1e-14, atol=0)


def test_unknown_law_and_bad_eps_are_input_errors():
    with pytest.raises(InputError):
        friction_coefficient(1.0, F0, V0, "coulomb")
    with pytest.raises(InputError):
        friction_gain(1.0, F0, V0, "smooth", eps=1.0)
