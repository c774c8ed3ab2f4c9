"""ERP of a rigid annular face: panel sums against the closed form; a rigid disc on springs end to end."""
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.errors import InputError
from cvtfem.modal.forced import frf_direct, OutputMap
from cvtfem.modal.radiation import C_AIR, RHO_AIR, erp, power_db, rigid_annulus


def closed_form(q, w, ri, ro):
    """rho c w^2 / 2 (pi (ro^2 - ri^2) |u3|^2 + pi (ro^4 - ri^4) / 4 (|theta1|^2 + |theta2|^2)) for the face of a
    rigid disc with w(r, a) = u3 + r (theta1 sin a - theta2 cos a)."""
    u3, t1, t2 = q
    return 0.5 * RHO_AIR * C_AIR * w**2 * (np.pi * (ro**2 - ri**2) * abs(u3) ** 2
                                             + np.pi * (ro**4 - ri**4) / 4 * (abs(t1) ** 2 + abs(t2) ** 2))


@pytest.mark.parametrize("rings,sectors", [(1, 3), (3, 7), (8, 16)])
def test_panel_sum_is_exact_for_rigid_motion(rings, sectors):
    rng = np.random.default_rng(rings)
    q = rng.normal(size=3) + 1j * rng.normal(size=3)
    face = rigid_annulus(3, (0, 1, 2), 0.035, 0.09, rings, sectors)
    assert face.area.sum() == pytest.approx(np.pi * (0.09**2 - 0.035**2), rel=1e-14)
    w = np.array([100.0, 3000.0])
    assert np.allclose(erp(face, np.column_stack([q, q]), w), closed_form(q, w, 0.035, 0.09), rtol=1e-12)


def test_tilt_sign_convention():
    """A tilt theta1 about e1 lifts the face at a = 90 deg (e2 side): theta x (r e2) . e3 = r theta1."""
    face = rigid_annulus(3, (0, 1, 2), 0.0, 1.0, 1, 4)
    w = face.N @ np.array([0.0, 1.0, 0.0])
    a = (np.arange(4) + 0.5) * np.pi / 2
    assert np.allclose(w, np.sqrt(0.5) * np.sin(a))


def test_rigid_disc_on_springs_erp_from_the_frf():
    """A rigid disc (m, B) on axial spring k and tilt spring kt, force F axial and moment Mt about e1: the ERP from
    the direct FRF equals the closed form with u3 = F / (k - m w^2), theta1 = Mt / (kt - B w^2)."""
    m, B, k, kt, F, Mt, ri, ro = 2.0, 0.004, 1e7, 2e4, 3.0, 0.2, 0.02, 0.09
    M = sp.diags([m, B, B])
    K = sp.diags([k, kt, kt])
    Z = sp.csr_matrix((3, 3))
    face = rigid_annulus(3, (0, 1, 2), ri, ro)
    w = np.array([200.0, 1500.0, 4000.0])
    q = frf_direct(M, K, Z, Z, np.array([F, Mt, 0.0]), OutputMap(sp.identity(3, format="csr"), Z, ("u3", "t1", "t2")),
                   w)[..., 0]
    exact = np.column_stack([F / (k - m * w**2), Mt / (kt - B * w**2), 0 * w]).T
    assert np.allclose(q.T, exact, rtol=1e-12)
    assert np.allclose(erp(face, q.T, w), closed_form(exact, w, ri, ro), rtol=1e-12)


def test_levels_and_bad_faces():
    assert power_db([1.0, 1e-12, 0.0]).tolist() == [120.0, 0.0, -np.inf]
    with pytest.raises(InputError, match="face radii"):
        rigid_annulus(3, (0, 1, 2), 0.1, 0.05)
    with pytest.raises(InputError, match="face panels"):
        rigid_annulus(3, (0, 1, 2), 0.0, 0.05, 1, 2)


def test_panel_sum_converges_for_a_flexural_field():
    """The hook for a flexible sheave: a Face from :func:`annulus_panels` with the normal displacement
    w = r^2 cos(2a) (a two-nodal-diameter bending shape).  Exact: rho c w^2 / 2 pi (ro^6 - ri^6) / 6; the panel sum
    converges at second order in the ring width (observed order 2 +- 0.05 over 4 .. 32 rings)."""
    from cvtfem.modal.radiation import Face, annulus_panels

    ri, ro, w = 0.035, 0.09, 2000.0
    exact = 0.5 * RHO_AIR * C_AIR * w**2 * np.pi * (ro**6 - ri**6) / 6
    errs = []
    for rings in (4, 8, 16, 32):
        r, a, area = annulus_panels(ri, ro, rings, 12)
        face = Face(area, sp.diags(r**2 * np.cos(2 * a)).tocsr())  # one "DOF" per panel, unit amplitude
        errs.append(abs(erp(face, np.ones(len(area)), [w])[0] - exact) / exact)
    order = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.allclose(order, 2.0, atol=0.05), order
