"""Shaft beam element: symmetry, rigid modes, mass, static exactness, closed forms vs quadrature."""
import numpy as np
import pytest

from cvtfem.elements.beam import PLANE1, BeamFamily, BeamOptions, cowper_kappa, shape_functions

STEEL = dict(E=2.11e11, G=8.12e10, rho=7810.0)


def family(n=1, L=0.4, Do=0.06, Di=0.0, **opts):
    return BeamFamily(nodes=np.stack([np.arange(n), np.arange(1, n + 1)], 1), L=np.full(n, L),
                      Do=np.full(n, Do), Di=np.full(n, Di), E=np.full(n, STEEL["E"]),
                      G=np.full(n, STEEL["G"]), rho=np.full(n, STEEL["rho"]), options=BeamOptions(**opts))


@pytest.mark.parametrize("Di", [0.0, 0.04])
def test_symmetry_skew_and_rigid_modes(Di):
    b = family(Di=Di)
    K, M, G = b.stiffness()[0], b.mass()[0], b.gyroscopic()[0]
    assert np.allclose(K, K.T, rtol=0, atol=1e-9 * abs(K).max())
    assert np.allclose(M, M.T, rtol=0, atol=1e-12 * abs(M).max())
    assert np.allclose(G, -G.T, rtol=0, atol=1e-12 * abs(G).max())
    assert np.all(np.linalg.eigvalsh(M) > 0)
    ev = np.linalg.eigvalsh(K)
    assert np.sum(np.abs(ev) < 1e-9 * ev.max()) == 6  # six rigid-body modes of a free element


def test_total_mass_and_polar_inertia():
    b = family(n=3, Di=0.02)
    M = b.mass()
    ones = np.zeros(12)
    ones[[0, 6]] = 1.0
    m_total = sum(ones @ Me @ ones for Me in M)
    assert m_total == pytest.approx(STEEL["rho"] * b.area[0] * 0.4 * 3, rel=1e-12)
    tw = np.zeros(12)
    tw[[5, 11]] = 1.0
    assert sum(tw @ Me @ tw for Me in M) == pytest.approx(STEEL["rho"] * 2 * b.inertia[0] * 1.2, rel=1e-12)


@pytest.mark.parametrize("shear", [True, False])
def test_cantilever_tip_exact_with_one_element(shear):
    """w = PL^3/3EI + PL/(kappa GA) + ML^2/2EI (spec §12.2a checks), both planes."""
    b = family(L=0.3, Do=0.08, shear=shear)
    K = b.stiffness()[0]
    free = np.arange(6, 12)
    P, Mo = 1e3, 50.0
    f = np.zeros(6)
    f[0], f[4] = P, Mo           # plane 1: force u1 and moment about e2 (beta = theta2)
    f[1] = P                     # plane 2: force u2
    q = np.linalg.solve(K[np.ix_(free, free)], f)
    EI, L = STEEL["E"] * b.inertia[0], 0.3
    shear_term = P * L / (b.shear_coefficient[0] * STEEL["G"] * b.area[0]) if shear else 0.0
    assert q[0] == pytest.approx(P * L**3 / (3 * EI) + shear_term + Mo * L**2 / (2 * EI), rel=1e-10)
    assert q[4] == pytest.approx(P * L**2 / (2 * EI) + Mo * L / EI, rel=1e-10)
    assert q[1] == pytest.approx(P * L**3 / (3 * EI) + shear_term, rel=1e-10)
    assert q[3] == pytest.approx(-P * L**2 / (2 * EI), rel=1e-10)  # plane 2: beta = -theta1


def test_closed_form_matrices_match_quadrature_of_shape_functions():
    """M_t = int rho A Nw^T Nw, R = int Nb^T Nb, K = int EI Nb'^2 + kGA (Nw' - Nb)^2 (independent check)."""
    b = family(n=1, L=0.1, Do=0.08)           # short, thick: phi ~ 1
    x, w = np.polynomial.legendre.leggauss(8)
    eta, w = (x + 1) / 2, w / 2 * b.L[0]
    Nw, dNw, Nb, dNb = shape_functions(eta, b.L, b.phi)
    EI, kGA = STEEL["E"] * b.inertia[0], b.shear_coefficient[0] * STEEL["G"] * b.area[0]
    Kq = np.einsum("g,gi,gj->ij", w, EI * dNb[0], dNb[0]) + kGA * np.einsum("g,gi,gj->ij", w, dNw[0] - Nb[0],
                                                                            dNw[0] - Nb[0])
    Mq = STEEL["rho"] * (b.area[0] * np.einsum("g,gi,gj->ij", w, Nw[0], Nw[0])
                         + b.inertia[0] * np.einsum("g,gi,gj->ij", w, Nb[0], Nb[0]))
    K, M = b.stiffness()[0], b.mass()[0]
    assert b.phi[0] > 0.5
    assert np.allclose(K[np.ix_(PLANE1, PLANE1)], Kq, rtol=1e-10, atol=1e-6 * abs(Kq).max())
    assert np.allclose(M[np.ix_(PLANE1, PLANE1)], Mq, rtol=1e-10, atol=1e-10 * abs(Mq).max())


def test_geometric_stiffness_reduces_to_euler_bernoulli_form():
    b = family(L=0.5, shear=False)
    P = 2e4
    Kg = (b.stiffness(P) - b.stiffness())[0][np.ix_(PLANE1, PLANE1)]
    L = 0.5
    ref = P / (30 * L) * np.array([[36, 3 * L, -36, 3 * L], [3 * L, 4 * L**2, -3 * L, -L**2],
                                   [-36, -3 * L, 36, -3 * L], [3 * L, -L**2, -3 * L, 4 * L**2]])
    assert np.allclose(Kg, ref, rtol=1e-12, atol=1e-9 * abs(ref).max())


def test_cowper_values_of_spec():
    assert cowper_kappa(0.3, 0.0) == pytest.approx(0.886, abs=5e-4)
    assert cowper_kappa(0.3, 0.6) == pytest.approx(0.582, abs=5e-4)
    assert cowper_kappa(0.3, 1.0) == pytest.approx(2 * 1.3 / (4 + 0.9), rel=1e-12)


def test_bad_input_names_argument():
    from cvtfem.errors import InputError

    with pytest.raises(InputError, match="BeamFamily.L"):
        BeamFamily(nodes=np.array([[0, 1]]), L=np.array([-1.0]), Do=np.array([0.1]), Di=np.array([0.0]),
                   E=np.array([1.0]), G=np.array([1.0]), rho=np.array([1.0]))
