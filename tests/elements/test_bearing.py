"""Bearings: linear blocks and the nonlinear radial law's tangent stiffness (spec §12.4)."""
import numpy as np
import pytest

from cvtfem.elements.bearing import BearingFamily, RadialLaw
from cvtfem.errors import InputError

LAWS = [RadialLaw(coeffs=(2e7, 0.0, 5e13)),
        RadialLaw(u=(0.0, 1e-5, 2e-5, 4e-5, 8e-5), f=(0.0, 250.0, 600.0, 1500.0, 4000.0))]


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("u0", [(3e-5, 1e-5), (-2e-5, 2.5e-5)])
def test_tangent_matches_finite_differences_of_reaction(law, u0):
    u0 = np.array(u0)
    h = 1e-10
    fd = np.column_stack([-(law.reaction(u0 + h * e) - law.reaction(u0 - h * e)) / (2 * h) for e in np.eye(2)])
    np.testing.assert_allclose(law.tangent(u0), fd, rtol=1e-5)


def test_tangent_at_zero_and_anisotropy_when_loaded():
    law = LAWS[0]
    np.testing.assert_allclose(law.tangent(np.zeros(2)), 2e7 * np.eye(2))
    Kt = law.tangent(np.array([5e-5, 0.0]))
    assert Kt[0, 0] == pytest.approx(2e7 + 3 * 5e13 * 25e-10)   # radial: f'(u)
    assert Kt[1, 1] == pytest.approx(2e7 + 5e13 * 25e-10)       # tangential: f(u)/u


def test_linear_blocks():
    b = BearingFamily.from_dicts(np.array([3]), [{"kxx": 1.0, "kxy": 2.0, "kyx": 3.0, "kyy": 4.0, "kzz": 5.0,
                                                 "cxx": 6.0, "m": 2.0, "Ip": 0.5}])
    assert b.dofs.tolist() == [[18, 19, 20, 21, 22, 23]]
    K = b.stiffness()[0]
    assert K[:2, :2].tolist() == [[1.0, 2.0], [3.0, 4.0]] and K[2, 2] == 5.0 and K[5, 5] == 0.0
    assert b.damping()[0][0, 0] == 6.0
    assert np.diag(b.mass()[0]).tolist() == [2.0, 2.0, 2.0, 0.0, 0.0, 0.5]


def test_bad_table_is_input_error():
    with pytest.raises(InputError, match="radial law table"):
        RadialLaw(u=(0.0, 2e-5, 1e-5), f=(0.0, 1.0, 2.0))


def test_radial_damping_is_radial_only():
    law = LAWS[0]
    D = law.damping(np.array([3e-5, 4e-5]), beta=1e-4)
    e = np.array([0.6, 0.8])
    np.testing.assert_allclose(D, 1e-4 * 2e7 * np.outer(e, e))
    np.testing.assert_allclose(D @ np.array([-0.8, 0.6]), 0.0, atol=1e-12)      # no circumferential damping
    np.testing.assert_allclose(law.damping(np.zeros(2), 1e-4), 1e-4 * 2e7 * np.eye(2))
