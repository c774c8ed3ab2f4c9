"""A CVT scene's [cvt.chain] -> the discrete chain's geometry."""
import numpy as np
import pytest

from cvtfem.elements.chain.geometry import RHO_STEEL, reference_geometry
from cvtfem.errors import InputError
from cvtfem.machines.cvt import chain_geometry
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def reference():
    return load_scene("reference_cvt")


def test_reference_scene_gives_the_reference_chain(reference):
    g = chain_geometry(reference)
    r = reference_geometry(randomised=True, seed=reference.seed)
    np.testing.assert_array_equal(g.L, r.L)                      # the same seeded long/short pattern
    np.testing.assert_array_equal(g.xi, r.xi)                    # the same lacing
    np.testing.assert_allclose(g.m_eff, r.m_eff, rtol=1e-12)     # same pin area -> same masses
    np.testing.assert_allclose([g.c_link.sum(), g.c_pin.sum()], [r.c_link.sum(), r.c_pin.sum()], rtol=1e-12)
    # the scene gives I_min = 6.8e-12 m^4, the hard-coded 2.4 x 6 mm section 6.9e-12: bending agrees to 2 %
    assert g.A_tau == pytest.approx(r.A_tau, rel=0.02) and g.A_n == pytest.approx(r.A_n, rel=0.02)


def test_section_reproduces_area_and_second_moment(reference):
    ch = reference.cvt.chain
    g = chain_geometry(reference)
    E = reference.cvt.young_modulus
    assert g.m_pin[0] == pytest.approx(RHO_STEEL * ch.pin_area * ch.pin_length, rel=1e-12)
    # A_tau = 2 E I_half of two halves across the chain direction = E I_min / 4
    assert g.A_tau == pytest.approx(E * ch.pin_I_min / 4, rel=1e-12)
    assert (g.m_pin.sum() + g.m_plate.sum()) == pytest.approx(ch.mass, rel=1e-12)


def test_uniform_chain_when_no_long_links(reference):
    g = chain_geometry(reference.replace({"cvt": {"chain": {"long_fraction": 0.0}}}))
    np.testing.assert_array_equal(g.L, reference.cvt.chain.pitch_short)


def test_pin_section_must_be_a_rectangle(reference):
    with pytest.raises(InputError, match="cvt.chain.pin_I_min"):
        chain_geometry(reference.replace({"cvt": {"chain": {"pin_I_min": 1e-9}}}))
