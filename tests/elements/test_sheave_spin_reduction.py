"""The spinning disc's Omega^2 terms (prestress, spin softening) and Coriolis coupling in the Craig–Bampton sheave
(issue 20): reduced travelling waves and critical speeds against the closed form of the clamped-free plate."""
import numpy as np
import pytest

from cvtfem.elements.sheave_reduction import craig_bampton, spin_reduction
from cvtfem.elements.sheave_solid import HarmonicSheave
from cvtfem.errors import InputError
from tests.elements.test_sheave_solid import PLATE, _southwell

MODES = 6                 # fixed-interface modes kept per family


@pytest.fixture(scope="module")
def unit_prestress():
    m0 = HarmonicSheave(PLATE, 0, n_r=60, n_z=2)
    return m0.stress(m0.centrifugal_displacement(1.0))


@pytest.fixture(scope="module", params=(2, 3))
def reduced(request, unit_prestress):
    n = request.param
    model = HarmonicSheave(PLATE, n, n_r=60, n_z=2)
    return model, spin_reduction(model, craig_bampton(model, MODES), unit_prestress)


def test_reduced_waves_follow_southwell_in_the_rotating_frame(reduced):
    """Both waves of the lowest bending mode at 500 and 1000 rad/s against ``w_0^2 + lambda_n Omega^2`` (``lambda_n``
    the Rayleigh quotient of the plane-stress rotating-disc prestress over the Kirchhoff mode: 2.30 and 3.88 for
    n = 2, 3), to 1 % (observed 0.01 %); both waves are the unreduced Coriolis model's (6 of ~700 modes kept) to
    1e-5 (observed 1.2e-6)."""
    model, spin = reduced
    n = model.n
    w0 = 2 * np.pi * model.modes(1)[0][0]
    lam = _southwell(n, PLATE)
    for omega in (500.0, 1000.0):
        f = spin.waves(omega)[:2]
        np.testing.assert_allclose(f, np.sqrt(w0 ** 2 + lam * omega ** 2) / (2 * np.pi), rtol=0.01)
    m0 = HarmonicSheave(PLATE, 0, n_r=60, n_z=2)
    full, _ = model.travelling_modes(1000.0, m0.stress(m0.centrifugal_displacement(1000.0)), 1)
    np.testing.assert_allclose(spin.waves(1000.0)[:2], full, rtol=1e-5)


def test_reduced_fixed_frame_sees_the_waves_shifted_and_the_backward_one_stand_still(reduced):
    """In the fixed frame the reduced pair runs at ``f +- n Omega / 2 pi`` (to 1e-6 of the rotating-frame
    frequency), and its stiffness ``K + Omega^2 K2_fixed`` turns singular first at the closed-form critical speed
    ``Omega_c = w_0 / sqrt(n^2 - lambda_n)`` (1545.4 and 1740.3 rad/s), to 1 % (observed 0.03 %), where the backward
    wave's fixed-frame frequency changes sign (1 % below and above)."""
    model, spin = reduced
    n, omega = model.n, 700.0
    rotating = spin.waves(omega)[:2]
    shift = n * omega / (2 * np.pi)
    fixed = spin.waves(omega, "fixed")
    for f, sense in zip(rotating, (1.0, -1.0)):              # the lower wave runs forward (docs/sheaves.md)
        assert np.min(np.abs(fixed - abs(f + sense * shift))) < 1e-6 * f
    w0 = 2 * np.pi * model.modes(1)[0][0]
    critical = w0 / np.sqrt(n * n - _southwell(n, PLATE))
    assert spin.critical_speeds()[0] == pytest.approx(critical, rel=0.01)
    backward = [spin.waves(s)[1] - n * s / (2 * np.pi) for s in (0.99 * critical, 1.01 * critical)]
    assert backward[0] > 0 > backward[1]                      # seen from outside it runs backwards past it


def test_spin_reduction_needs_a_travelling_harmonic(unit_prestress):
    model = HarmonicSheave(PLATE, 0, n_r=8, n_z=1)
    with pytest.raises(InputError, match="n >= 1"):
        spin_reduction(model, craig_bampton(model, 2), unit_prestress)
