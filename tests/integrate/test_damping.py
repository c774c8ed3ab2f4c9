"""|R(-inf)| per method (issue 19): one fixed step of ``y' = lambda y`` with ``h lambda = -1e12``
(the exact Jacobian) gives the stability function at -inf; defaults damp where the family allows."""
import numpy as np
import pytest

from cvtfem.integrate import solve

Z_INF = -1e12


def R(method, z, **options):
    """Stability function ``R(z) = y1/y0`` of one fixed step, ``lambda = z`` and ``h = 1``."""
    res = solve(lambda t, y: z * y, (0.0, 1.0), [1.0], method=method, h=1.0,
                jac=lambda t, y: np.array([[z]]), growth_limit=None, **options)
    assert res.success, res.message
    return res.y[0, -1]


@pytest.mark.parametrize("method,options,r_inf", [
    ("sw24", {}, 0.0),                       # d = 1 - 1/sqrt(2): L-stable
    ("sw24", {"d": 0.5}, -1.0),              # the source's d: no damping
    ("sw24", {"d": 1.0}, -0.5),
    ("w1", {}, 0.0),                         # d = 1: linearly implicit Euler
    ("w1", {"d": 0.5}, -1.0),
    ("w1-extrapolation", {}, 0.0),
    ("rodas4", {}, 0.0),
    ("rodas5p", {}, 0.0),
    ("ros34pw2", {}, 0.0),                   # stiffly accurate, L-stable with A = J
    ("radau5", {}, 0.0),
    ("implicit-euler", {}, 0.0),
    ("trapezoidal", {}, -1.0),
    ("theta", {"alpha": 0.75}, 1 - 1 / 0.75)])
def test_stability_function_at_minus_infinity(method, options, r_inf):
    assert R(method, Z_INF, **options) == pytest.approx(r_inf, abs=1e-9)


@pytest.mark.parametrize("d", [0.25, 1 - 2 ** -0.5, 0.5, 1.0])
def test_sw24_stability_function_closed_form(d):
    """SW24-d with A = J is the 2-stage Rosenbrock function [1 + (1-2d) z + (d^2-2d+1/2) z^2]/(1-dz)^2."""
    for z in (-0.3, -4.0, -70.0):
        closed = (1 + (1 - 2 * d) * z + (d * d - 2 * d + 0.5) * z * z) / (1 - d * z) ** 2
        assert R("sw24", z, d=d) == pytest.approx(closed, rel=1e-12)


@pytest.mark.parametrize("method", ["rodas4", "rodas5p", "radau5", "ros34pw2"])
def test_rodas_is_a_stable_on_the_imaginary_axis(method):
    """A-stability (Hairer-Wanner IV.7; Steinebach 2023): a rotation ``y' = [[0, w], [-w, 0]] y`` (eigenvalues
    ``+-iw``) is not amplified by one step, ``|R(iw)| <= 1``, and damped strongly for large ``w``."""
    for w in (0.1, 1.0, 3.0, 30.0, 1e4, 1e6):
        J = np.array([[0.0, w], [-w, 0.0]])
        res = solve(lambda t, u: J @ u, (0.0, 1.0), [1.0, 0.0], method=method, h=1.0, jac=lambda t, u: J,
                    growth_limit=None)
        assert np.linalg.norm(res.y[:, -1]) <= 1 + 1e-12
    assert np.linalg.norm(res.y[:, -1]) < 1e-4   # |R(iw)| -> 0 like 1/w (L-stability)
