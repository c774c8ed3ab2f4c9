"""Section properties (scikit-fem) against closed forms; meshes in meshes/ read with meshio."""
from math import gamma, pi

import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.sections import (annulus_mesh, disk_mesh, load_section_mesh, pin_mesh, rectangle_mesh,
                             section_properties)
from cvtfem.sections.meshes import MESH_DIR


def circle_energy_kappa(nu):
    """Energy shear coefficient of a circle from the exact flexure stresses (Timoshenko & Goodier §120)."""
    moment = lambda p, q: gamma(p + 0.5) * gamma(q + 0.5) / gamma(p + q + 2)   # int x^2p y^2q, unit disk
    I = pi / 4
    a, c, b = (3 + 2 * nu) / (8 * (1 + nu) * I), (1 - 2 * nu) / (3 + 2 * nu), (1 + 2 * nu) / (4 * (1 + nu) * I)
    energy = a**2 * (moment(0, 0) + moment(2, 0) + c**2 * moment(0, 2) - 2 * moment(1, 0) - 2 * c * moment(0, 1)
                     + 2 * c * moment(1, 1)) + b**2 * moment(1, 1)
    return 1 / (pi * energy)


@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_solid_circle(nu):
    R = 0.025
    p = section_properties(disk_mesh(R, nrefs=4), nu)
    assert p.A == pytest.approx(pi * R**2, rel=1e-6)
    assert p.Ixx == pytest.approx(pi * R**4 / 4, rel=1e-6) and p.Iyy == pytest.approx(p.Ixx, rel=1e-12)
    assert p.J == pytest.approx(pi * R**4 / 2, rel=1e-6)          # circle: no warping, J = Ip
    assert p.kappa_y == pytest.approx(circle_energy_kappa(nu), rel=1e-5)
    if nu == 0:
        assert p.kappa_y == pytest.approx(6 / 7, rel=1e-5)        # = Cowper's value at nu = 0


def test_hollow_circle():
    ri, ro = 0.024, 0.040
    p = section_properties(annulus_mesh(ri, ro, 6, 96), 0.3)
    assert p.A == pytest.approx(pi * (ro**2 - ri**2), rel=1e-5)
    assert p.Ixx == pytest.approx(pi * (ro**4 - ri**4) / 4, rel=1e-5)
    assert p.J == pytest.approx(pi * (ro**4 - ri**4) / 2, rel=1e-5)
    assert p.kappa_x == pytest.approx(p.kappa_y, rel=1e-6) and 0.45 < p.kappa_y < 0.6


def rectangle_torsion_constant(a, b, terms=200):
    """Saint-Venant series for an a x b rectangle (a >= b)."""
    n = np.arange(1, 2 * terms, 2)
    return a * b**3 / 3 * (1 - 192 * b / (np.pi**5 * a) * np.sum(np.tanh(n * np.pi * a / (2 * b)) / n**5))


@pytest.mark.parametrize("a,b", [(1.0, 1.0), (2.0, 1.0), (4.0, 1.0)])
def test_rectangle_torsion_constant_and_shear(a, b):
    p = section_properties(rectangle_mesh(a, b, n=16), 0.0)
    assert p.J == pytest.approx(rectangle_torsion_constant(a, b), rel=1e-4)   # O(h^3)-ish, corner-limited
    assert p.Ixx == pytest.approx(a * b**3 / 12, rel=1e-10)
    assert p.kappa_x == pytest.approx(5 / 6, rel=1e-5) and p.kappa_y == pytest.approx(5 / 6, rel=1e-5)


def test_torsion_converges_under_refinement():
    exact = rectangle_torsion_constant(2.0, 1.0)
    errs = [abs(section_properties(rectangle_mesh(2.0, 1.0, n), 0.0).J - exact) / exact for n in (2, 4, 8)]
    assert errs[2] < errs[1] < errs[0]
    assert np.log2(errs[1] / errs[2]) > 2.5      # P2 elements; corner singularities limit the rate


def test_mesh_files_in_repository_match_generators():
    for name, gen, nu in (("circle_d50mm.vtu", lambda: disk_mesh(0.025, 4), 0.3),
                          ("rocker_pin.vtu", lambda: pin_mesh(3e-3, 1.2e-3, 4e-3, 4), 0.3)):
        from_file = section_properties(load_section_mesh(MESH_DIR / name), nu)
        fresh = section_properties(gen(), nu)
        assert from_file.J == pytest.approx(fresh.J, rel=1e-10)
        assert from_file.A == pytest.approx(fresh.A, rel=1e-10)


def test_pin_profile_is_symmetric_and_between_bounds():
    p = section_properties(pin_mesh(3e-3, 1.2e-3, 4e-3, 4), 0.3)
    assert abs(p.cx) < 1e-12 and abs(p.cy) < 1e-12 and abs(p.Ixy) < 1e-20
    assert 4 * 3e-3 * 1.2e-3 * 0.9 < p.A < 4 * 3e-3 * 1.2e-3          # bar minus the rounded corners
    assert p.J < p.Ixx + p.Iyy                                        # warping lowers J below Ip


def test_bad_inputs():
    with pytest.raises(InputError, match="nu"):
        section_properties(rectangle_mesh(1.0, 1.0, 2), 0.7)
    with pytest.raises(InputError, match="mesh"):
        load_section_mesh("no/such/file.vtu")
