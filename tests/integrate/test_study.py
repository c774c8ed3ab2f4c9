"""Study tools: stability functions by brute force vs closed forms, signed-log map."""
import numpy as np
import pytest

from cvtfem.integrate.study import amplification, real_stability_length, signed_log, signed_log_inverse

Z = np.array([-1 + 1j, -2.5, 0.5j, -3.0, -0.2 - 2j, 1.0 + 0.5j])


@pytest.mark.parametrize("method,opts,R", [
    ("rk4", {}, lambda z: 1 + z + z ** 2 / 2 + z ** 3 / 6 + z ** 4 / 24),
    ("euler", {}, lambda z: 1 + z),
    ("trapezoidal", {}, lambda z: (1 + z / 2) / (1 - z / 2)),
    ("implicit-euler", {}, lambda z: 1 / (1 - z)),
    ("w1", {"d": 0.5}, lambda z: 1 + z / (1 - 0.5 * z)),
    ("w1", {"d": 1.0}, lambda z: 1 + z / (1 - z)),
])
def test_brute_force_matches_closed_form(method, opts, R):
    assert np.allclose(amplification(method, Z, **opts), np.abs(R(Z)), rtol=1e-10)


def test_rk4_real_stability_length():
    assert abs(real_stability_length("rk4", x_max=4, n=4001) - 2.785293563405) < 1e-8


def test_signed_log_roundtrip_and_continuity():
    x = np.array([-1e6, -1.0, -1e-3, -1e-5, 0.0, 2e-4, 1e-3, 0.7, 1e8])
    assert np.allclose(signed_log_inverse(signed_log(x)), x, rtol=1e-12, atol=1e-18)
    eps = 1e-12
    assert abs(signed_log(1e-3 + eps) - signed_log(1e-3 - eps)) < 1e-6
    assert signed_log(1.0) == pytest.approx(1 + np.log(1e3))
