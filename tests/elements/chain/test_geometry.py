"""Chain geometry: weave of period 3, effective masses (1.68), plate sums (1.108), reference chain, ring."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cvtfem.elements.chain.geometry import (REFERENCE_SECTION, ChainGeometry, chain_geometry, h1,
                                            reference_geometry, ring_positions, weave_stations)
from cvtfem.errors import InputError


def test_weave_period_three_never_puts_two_plates_of_one_pin_in_one_slot():
    xi = weave_stations(84, 12, period=3, pack=0.8)
    assert xi.shape == (84, 12)
    np.testing.assert_array_equal(xi[3:], xi[:-3])                      # period 3
    assert np.abs(xi).max() < 0.8 and len(np.unique(xi)) == 36          # 36 slots inside the pack
    for p in range(84):                                                 # pin p carries links p-1 and p
        assert not set(xi[p - 1]) & set(xi[p])
    # the three links of a period fill every slot once, so the pack is balanced about x3 = 0
    assert abs(xi[:3].sum()) < 1e-13


def test_effective_mass_is_pin_plus_half_the_adjacent_plates():
    g = reference_geometry()
    plates = g.m_plate.sum(axis=1)
    np.testing.assert_allclose(g.m_eff, g.m_pin + 0.5 * (plates + np.roll(plates, 1)), rtol=1e-15)
    assert np.isclose(g.m_eff.sum(), 1.5, rtol=1e-13)                   # the whole chain mass sits on the pins
    opened = dataclasses.replace(g, closed=False)
    assert np.isclose(opened.m_eff.sum(), 1.5 - plates[-1], rtol=1e-13)  # the closing link is absent
    assert np.isclose(opened.m_eff[0], g.m_pin[0] + 0.5 * plates[0], rtol=1e-15)


def test_plate_sums_of_the_elastic_layer():
    g = reference_geometry(randomised=True, seed=3)
    hk = 0.5 * g.l * (g.xi ** 2 - 1)
    np.testing.assert_allclose(g.c_link, 1.4e9, rtol=1e-14)
    np.testing.assert_allclose(g.c1_link, (g.c_plate * hk).sum(1), rtol=1e-14)
    assert np.all(g.c1_link < 0) and np.all(g.c2_link > 0)              # h1 <= 0 (§3.5)
    assert np.all(g.c1_link ** 2 <= g.c_link * g.c2_link)                # Cauchy-Schwarz: the layer is stable
    assert h1(1.0, g.l) == 0.0 and h1(0.0, g.l) == -g.l / 2


def test_reference_chain_and_randomised_pattern():
    g = reference_geometry(randomised=True, seed=1)
    assert g.n == 84 and np.isclose(g.length, 0.756, rtol=1e-12)
    assert set(np.round(g.L, 6)) == {0.0085, 0.0095}
    # pin section 2.4 x 6 mm: I_min of the whole pin 6.9e-12 m^4 (source 6.8e-12); independent halves 1/4 of it
    I_min = 0.006 * 0.0024 ** 3 / 12
    assert np.isclose(REFERENCE_SECTION.A_tau, 2.1e11 * I_min / 4, rtol=1e-14)
    assert np.isclose(REFERENCE_SECTION.area, 1.44e-5, rtol=1e-14)
    assert np.all(g.c_pin == 2.0e8)


def test_bad_input_is_an_input_error():
    with pytest.raises(InputError):
        weave_stations(9, 12, period=3, pack=1.5)
    with pytest.raises(InputError):
        chain_geometry(84, 0.033, 0.009, 12, 1.4e9, 0.01, REFERENCE_SECTION)    # lighter than its pins
    g = reference_geometry()
    with pytest.raises(InputError):
        ChainGeometry(L=g.L, l=g.l, xi=g.xi[:, :3], c_plate=g.c_plate, m_plate=g.m_plate, m_pin=g.m_pin,
                      c_pin=g.c_pin)


def test_ring_positions_close_the_loop_with_unstretched_links():
    L = reference_geometry(randomised=True, seed=2).L
    x, R = ring_positions(L)
    np.testing.assert_allclose(np.linalg.norm(np.roll(x, -1, axis=0) - x, axis=1), L, rtol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(x, axis=1), R, rtol=1e-15)
    assert np.isclose(R, 0.756 / (2 * np.pi), rtol=1e-3)
