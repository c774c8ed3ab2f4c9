"""Tapered shaft elements: Gauss-integrated section over the Hermite/Timoshenko shape functions."""
import numpy as np
import pytest
import scipy.integrate as si
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.assembly import assemble
from cvtfem.elements import beam as bm
from cvtfem.elements.beam import BeamFamily, BeamOptions
from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.scene.loader import scene_from_dict

E, G, RHO = 2.1e11, 8.1e10, 7800.0
LENGTH, D_ROOT, D_TIP = 0.5, 0.06, 0.03   # solid cone-frustum cantilever, clamped at the thick end


def family(edges, Do, Di, Do_right=None, Di_right=None, shear=True):
    n = len(edges) - 1
    full = lambda v: np.full(n, v)  # noqa: E731
    return BeamFamily(nodes=np.stack([np.arange(n), np.arange(1, n + 1)], 1), L=np.diff(edges), Do=Do, Di=Di,
                      E=full(E), G=full(G), rho=full(RHO), Do_right=Do_right, Di_right=Di_right,
                      options=BeamOptions(shear=shear))


def diameter(x):
    return D_ROOT + (D_TIP - D_ROOT) * x / LENGTH


def cantilever(n, tapered, shear):
    """(K, M) of plane 1 (u1, theta2) with node 0 clamped: n tapered elements, or n uniform steps whose
    diameter is the cone's at each element's middle."""
    x = np.linspace(0, LENGTH, n + 1)
    if tapered:
        b = family(x, diameter(x[:-1]), np.zeros(n), diameter(x[1:]), np.zeros(n), shear=shear)
    else:
        b = family(x, diameter((x[:-1] + x[1:]) / 2), np.zeros(n), shear=shear)
    N = 6 * (n + 1)
    K, M = (assemble(N, [(X, b.dofs)]).toarray() for X in (b.stiffness(), b.mass()))
    keep = np.flatnonzero(np.isin(np.arange(N) % 6, [0, 4]) & (np.arange(N) >= 6))
    return K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], b


def exact_tip_deflection(shear):
    """Tip deflection under a unit tip force: int (L-x)^2 / EI dx (+ int 1 / (kappa G A) dx with shear)."""
    inertia = lambda x: np.pi / 64 * diameter(x) ** 4  # noqa: E731
    bend = si.quad(lambda x: (LENGTH - x) ** 2 / (E * inertia(x)), 0, LENGTH, epsabs=0, epsrel=1e-13)[0]
    if not shear:
        return bend
    kappa = float(bm.cowper_kappa(E / (2 * G) - 1, 0.0))
    return bend + si.quad(lambda x: 1 / (kappa * G * np.pi / 4 * diameter(x) ** 2), 0, LENGTH, epsabs=0, epsrel=1e-13)[0]


@pytest.mark.parametrize("shear", [False, True])
@pytest.mark.parametrize("rotary", [False, True])
def test_equal_ends_give_the_uniform_element(shear, rotary):
    """Quadrature of a constant (hollow) section = the closed-form matrices of spec §12.2a to round-off."""
    edges = np.array([0.0, 0.05, 0.2, 0.23])
    b = family(edges, np.array([0.05, 0.04, 0.06]), np.array([0.0, 0.01, 0.02]), shear=shear)
    q = b.integrated_blocks()
    L, ph = b.L, b.phi
    closed = {"stiffness": (b.E * b.inertia)[:, None, None] / ((1 + ph) * L**3)[:, None, None] * bm._kb_pattern(L, ph),
              "mass": (b.rho * b.area)[:, None, None] * bm._mt(L, ph),
              "rotary": (b.rho * b.inertia)[:, None, None] * bm._rot(L, ph),
              "axial_mass": (b.rho * b.area * L / 6)[:, None, None] * bm._BAR_M,
              "torsion_mass": (b.rho * 2 * b.inertia * L / 6)[:, None, None] * bm._BAR_M}
    for key, value in closed.items():
        np.testing.assert_allclose(q[key], value, rtol=0, atol=2e-15 * np.abs(value).max(), err_msg=key)
    # the family switches to quadrature only for tapered elements; a hair of taper moves nothing by more than it
    haired = family(edges, b.Do, b.Di, b.Do * (1 + 1e-9), b.Di, shear=shear)
    assert haired.tapered.all() and not b.tapered.any()
    for name in ("stiffness", "mass", "gyroscopic"):
        A, B = getattr(haired, name)(), getattr(b, name)()
        assert np.abs(A - B).max() < 1e-8 * np.abs(B).max(), name


@pytest.mark.parametrize("shear", [False, True])
def test_tapered_cantilever_tip_deflection_is_exact(shear):
    """Tapered elements give int (L-x)^2/EI (+ 1/kappa G A) at the tip on any mesh (flexibility-exact under
    nodal loads, to the 6-point Gauss error of the rational integrand); uniform steps converge only as h^2."""
    exact = exact_tip_deflection(shear)

    def error(n, tapered):
        K, _, _ = cantilever(n, tapered, shear)
        f = np.zeros(len(K))
        f[-2] = 1.0   # u1 of the tip node
        return abs(np.linalg.solve(K, f)[-2] / exact - 1)

    assert error(1, True) < 2e-6 and error(2, True) < 5e-9
    assert max(error(n, True) for n in (4, 8, 16)) < 1e-11
    steps = np.array([error(n, False) for n in (8, 16, 32)])
    np.testing.assert_allclose(np.log2(steps[:-1] / steps[1:]), 2.0, atol=0.05)


def first_frequency(n, tapered, shear):
    """Lowest bending frequency of the cantilever, rad/s (shift-invert: accurate for the lowest eigenvalue)."""
    K, M, _ = cantilever(n, tapered, shear)
    w2 = spla.eigsh(sp.csc_matrix(K), 1, sp.csc_matrix(M), sigma=0.0, v0=np.ones(len(K)), return_eigenvectors=False)
    return np.sqrt(w2[0])


def test_tapered_cantilever_first_frequency_matches_the_fine_stepped_shaft():
    """Euler-Bernoulli first bending frequency: tapered elements converge as h^4 to the Richardson-extrapolated
    limit of 256 and 512 uniform steps (an independent discretisation, error O(h^2); the extrapolation itself is
    good to ~3e-7: from 512 and 1024 steps it moves by 3.8e-7)."""
    def first(n, tapered):
        return first_frequency(n, tapered, False)

    fine, finer = first(256, False), first(512, False)
    reference = finer + (finer - fine) / 3
    assert abs(finer / reference - 1) > 2e-6   # the steps' own error at 512 is above the tapered one at 16
    errors = np.array([abs(first(n, True) / reference - 1) for n in (2, 4, 8, 16)])
    assert np.all(np.log2(errors[:-2] / errors[1:-1]) > 3.9), errors
    assert errors[-1] < 1e-6, errors


def test_tapered_timoshenko_frequency_converges_as_h2():
    """Timoshenko: the mass matrix uses the shape functions of one mean shear parameter per element, which cannot
    follow the section; the first frequency converges as h^2 once phi is large (2.5e-6 at 16 elements), against
    the Richardson limit of 256 and 512 uniform steps (stable to 1.2e-10 from 512 and 1024)."""
    fine, finer = first_frequency(256, False, True), first_frequency(512, False, True)
    reference = finer + (finer - fine) / 3
    errors = np.array([abs(first_frequency(n, True, True) / reference - 1) for n in (4, 16, 32, 64)])
    assert errors[0] < 2e-4 and errors[1] < 3e-6, errors
    np.testing.assert_allclose(np.log2(errors[1:-1] / errors[2:]), 2.0, atol=0.1)


def test_scene_keys_make_tapered_elements():
    data = {"material": [{"name": "steel", "E": E, "G": G, "rho": RHO}],
            "shaft": [{"length": 0.2, "outer_diameter": 0.06, "outer_diameter_right": 0.04,
                       "inner_diameter": 0.01, "material": "steel", "repeat": 2},
                      {"length": 0.1, "outer_diameter": 0.04, "material": "steel"}],
            "bearing": [{"node": 0, "kxx": 1e7, "kyy": 1e7}, {"node": 3, "kxx": 1e7, "kyy": 1e7}]}
    model = build_model(scene_from_dict(data))
    b = model.beam
    np.testing.assert_array_equal(b.ends[2], [0.04, 0.04, 0.04])
    np.testing.assert_array_equal(b.ends[3], [0.01, 0.01, 0.0])
    np.testing.assert_array_equal(b.tapered, [True, True, False])
    mass = model.M.toarray()[0::6, 0::6].sum()   # u1 rows: total translating mass of the shaft
    frustum = RHO * np.pi / 4 * (2 * 0.2 * ((0.06**2 + 0.06 * 0.04 + 0.04**2) / 3 - 0.01**2) + 0.1 * 0.04**2)
    assert mass == pytest.approx(frustum, rel=1e-13)
    data["shaft"][0]["inner_diameter_right"] = 0.05
    with pytest.raises(InputError) as err:
        build_model(scene_from_dict(data))
    assert err.value.where == "shaft[0].inner_diameter_right"
