"""Solid sheave discs (scikit-fem): the axisymmetric-harmonic model against thin-plate closed forms and
published plate frequencies, its rigid-body modes, and the 3D quadratic-tetrahedron reference (slow)."""
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import iv, ivp, jv, jvp, kv, kvp, yv, yvp

from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection, SolidSheave
from cvtfem.errors import InputError

#: Thin annular plate: clamped at b = 20 mm, free at a = 100 mm, h = 2 mm (h/a = 0.02), steel.
PLATE = SheaveSection(bore_radius=0.02, hub_radius=0.02, outer_radius=0.1, hub_length=0.0, rim_thickness=0.002)
#: A sheave: 35 mm bore, hub sleeve 60 mm diameter x 30 mm, 190 mm diameter, 10-degree face, 8 mm at the rim.
SHEAVE = SheaveSection(0.0175, 0.03, 0.095, 0.03, 0.008, np.radians(10.0))


def _plate_rigidity(sec):
    return sec.E * sec.rim_thickness ** 3 / (12 * (1 - sec.nu ** 2))


def _bessel_ops(n, k, r, nu):
    """Rows w, w', M_r / (-D), V_r / (-D) of the four solutions J, Y, I, K of the plate equation at radius r."""
    cols = []
    for F, dF, s in ((jv, jvp, -1), (yv, yvp, -1), (iv, ivp, 1), (kv, kvp, 1)):
        x = k * r
        W, W1, W2 = F(n, x), k * dF(n, x, 1), k * k * dF(n, x, 2)
        cols.append([W, W1, W2 + nu * (W1 / r - n * n * W / r ** 2),
                     s * k * k * W1 - (1 - nu) * n * n * (W1 - W / r) / r ** 2])
    return np.array(cols).T


def _roots(fun, lo, hi, count, m=3000):
    grid = np.linspace(lo, hi, m)
    vals = np.array([fun(x) for x in grid])
    out = [brentq(fun, a, b) for a, b, fa, fb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:])
           if np.sign(fa) != np.sign(fb)]
    return [r for r in out if abs(fun(r)) < 1e-6][:count]     # drop the poles of the normalised determinant


def kirchhoff_clamped_free(n, b, a, nu, count=2):
    """Frequency parameters ``lambda = k a`` of an annular Kirchhoff plate clamped at ``b``, free at ``a``."""
    def det(lam):
        A = np.vstack([_bessel_ops(n, lam / a, b, nu)[:2], _bessel_ops(n, lam / a, a, nu)[2:]])
        return np.linalg.det(A / np.abs(A).max(axis=0))
    return np.array(_roots(det, 0.3, 12.0, count))


def test_bessel_determinant_reproduces_leissa_clamped_circular_plate():
    # Leissa, Vibration of Plates (NASA SP-160, 1969), Table 2.1: lambda^2 = 10.2158, 21.260, 34.877 (s = 0)
    for n, ref in enumerate((10.2158, 21.260, 34.877)):
        lam = _roots(lambda x: np.linalg.det(np.array([[jv(n, x), iv(n, x)], [jvp(n, x), ivp(n, x)]])), 0.5, 7.0, 1)
        assert lam[0] ** 2 == pytest.approx(ref, rel=2e-5)


def test_ring_load_deflection_matches_thin_plate_closed_form():
    """Axial rim deflection of the annular plate clamped at the hub under a ring load at the rim (Roark's case
    of an outer-edge line load, inner edge fixed) from the general axisymmetric Kirchhoff solution."""
    b, a, nu, P = PLATE.bore_radius, PLATE.outer_radius, PLATE.nu, 1000.0
    D = _plate_rigidity(PLATE)

    def rows(r):  # w = C1 + C2 r^2 + C3 ln r + C4 r^2 ln r and its first three derivatives
        return (np.array([1, r ** 2, np.log(r), r ** 2 * np.log(r)]), np.array([0, 2 * r, 1 / r, r * (2 * np.log(r) + 1)]),
                np.array([0, 2, -1 / r ** 2, 2 * np.log(r) + 3]), np.array([0, 0, 2 / r ** 3, 2 / r]))

    wb, w1b, _, _ = rows(b)
    wa, w1a, w2a, w3a = rows(a)
    moment = w2a + nu * w1a / a                               # M_r(a) = 0
    shear = -D * (w3a + w2a / a - w1a / a ** 2)               # Q_r(a) = P / (2 pi a)
    C = np.linalg.solve(np.array([wb, w1b, moment, shear]), [0, 0, 0, P / (2 * np.pi * a)])
    model = HarmonicSheave(PLATE, 0, n_r=60, n_z=2)
    u = model.static(model.rim_load(P))
    assert model.rim_mean(u) == pytest.approx(wa @ C, rel=0.005)   # observed 1e-3 (shear of h/a = 0.02)


@pytest.mark.parametrize("n", range(5))
def test_bending_frequencies_match_kirchhoff_annular_plate(n):
    """Nodal diameters 0..4, nodal circles 0..1 of the clamped-free annular plate within 1 % (the solid model
    includes the shear and rotary inertia thin-plate theory drops: observed 0.05-0.8 %)."""
    sec = PLATE
    lam = kirchhoff_clamped_free(n, sec.bore_radius, sec.outer_radius, sec.nu)
    exact = lam ** 2 / sec.outer_radius ** 2 * np.sqrt(_plate_rigidity(sec) / (sec.rho * sec.rim_thickness)) / (2 * np.pi)
    model = HarmonicSheave(sec, n, n_r=60, n_z=2)
    f, shapes = model.modes(6)
    z = np.array([np.sum(shapes[model.basis.split_indices()[2], j] ** 2) / np.sum(shapes[:, j] ** 2)
                  for j in range(6)])
    bending = f[z > 0.5][:2]                                  # out-of-plane modes: mostly axial motion
    np.testing.assert_allclose(bending, exact, rtol=0.01)


@pytest.mark.parametrize("n, rigid", [(0, 1), (1, 2), (2, 0)])
def test_free_disc_has_exactly_the_rigid_modes_of_its_harmonic(n, rigid):
    """Free disc: n = 0 (cos) moves only along the axis, n = 1 translates sideways and tilts, n = 2 has no rigid
    motion; the twin family at n = 0 is the spin about the axis."""
    f, _ = HarmonicSheave(SHEAVE, n, n_r=12, n_z=2).modes(rigid + 1, clamped=False)
    assert np.all(f[:rigid] < 1e-3 * f[rigid]) and f[rigid] > 1000.0
    spin, _ = HarmonicSheave(SHEAVE, 0, "sin", n_r=12, n_z=2).modes(2, clamped=False)
    assert spin[0] < 1e-3 * spin[1]


def test_both_families_give_the_same_frequencies_for_n_at_least_one():
    for n in (1, 3):
        a, _ = HarmonicSheave(SHEAVE, n, "cos", 12, 2).modes(4)
        b, _ = HarmonicSheave(SHEAVE, n, "sin", 12, 2).modes(4)
        np.testing.assert_allclose(a, b, rtol=1e-9)


def test_bad_sections_are_refused():
    with pytest.raises(InputError, match="sheave.radii"):
        SheaveSection(0.05, 0.03, 0.095, 0.04, 0.008)
    with pytest.raises(InputError, match="sheave.hub_length"):
        SheaveSection(0.03, 0.03, 0.095, 0.01, 0.008)                        # a sleeve of zero width
    with pytest.raises(InputError, match="sheave.torus_radius"):
        SheaveSection(0.0175, 0.03, 0.095, 0.03, 0.008, np.radians(10.0), "toroidal", 0.01)
    with pytest.raises(InputError, match="family"):
        HarmonicSheave(SHEAVE, 1, "tan")


@pytest.mark.slow
def test_solid_reference_matches_harmonic_model():
    """The 3D quadratic-tetrahedron model (48 cells around) and the harmonic model on the same section mesh:
    rim deflection under a ring load and the lowest modes of n = 0..4 agree to 1 % (observed 0.2-0.3 %: the
    polygonal 3D body is slightly stiffer)."""
    solid = SolidSheave(SHEAVE, n_r=12, n_z=2, n_theta=48)
    P = 20000.0
    u = solid.static(solid.rim_load(P))
    p = solid.basis.mesh.p
    rim3 = np.hypot(p[0], p[1]) > SHEAVE.outer_radius * (1 - 1e-9)
    axisym = HarmonicSheave(SHEAVE, 0, n_r=12, n_z=2)
    v = axisym.static(axisym.rim_load(P))
    assert u[solid.basis.nodal_dofs[2]][rim3].mean() == pytest.approx(axisym.rim_mean(v), rel=0.01)
    f3, _ = solid.modes(12)
    harmonic = []
    for n, family, count in ((0, "cos", 1), (0, "sin", 1), (1, "cos", 2), (2, "cos", 1), (3, "cos", 1), (4, "cos", 1)):
        f, _ = HarmonicSheave(SHEAVE, n, family, 12, 2).modes(count)
        harmonic += list(f) * (1 if n == 0 else 2)            # n >= 1: a pair of equal frequencies in 3D
    np.testing.assert_allclose(f3, np.sort(harmonic), rtol=0.01)


# --- the spinning disc ------------------------------------------------------------------------------------

def _plane_stress_rotating_disc(sec):
    """Hoop and radial stress per omega^2 (Pa s^2) of a thin disc spinning with ``u_r = 0`` at the bore and a
    free rim: ``u = A r + B / r - (1 - nu^2) rho r^3 / (8 E)`` (Timoshenko & Goodier, rotating discs)."""
    b, a, nu, E = sec.bore_radius, sec.outer_radius, sec.nu, sec.E
    c = (1 - nu ** 2) * sec.rho / (8 * E)
    A, B = np.linalg.solve([[b, 1 / b], [1 + nu, -(1 - nu) / a ** 2]], [c * b ** 3, c * (3 + nu) * a ** 2])
    fac = E / (1 - nu ** 2)
    return (lambda r: fac * (A * (1 + nu) - B * (1 - nu) / r ** 2 - c * (3 + nu) * r ** 2),
            lambda r: fac * (A * (1 + nu) + B * (1 - nu) / r ** 2 - c * (1 + 3 * nu) * r ** 2))


def _southwell(n, sec):
    """``lambda_n`` of ``omega^2 = omega_0^2 + lambda_n Omega^2``: the Rayleigh quotient of the membrane prestress
    per ``Omega^2`` over the Kirchhoff mode shape of the clamped-free plate (first-order perturbation)."""
    from scipy.integrate import quad

    b, a, h, nu = sec.bore_radius, sec.outer_radius, sec.rim_thickness, sec.nu
    k = kirchhoff_clamped_free(n, b, a, nu, 1)[0] / a
    coef = np.linalg.svd(np.vstack([_bessel_ops(n, k, b, nu)[:2], _bessel_ops(n, k, a, nu)[2:]]))[2][-1]
    fns = ((jv, jvp), (yv, yvp), (iv, ivp), (kv, kvp))

    def w(r):
        return sum(c * F(n, k * r) for c, (F, _) in zip(coef, fns))

    def dw(r):
        return sum(c * k * dF(n, k * r, 1) for c, (_, dF) in zip(coef, fns))

    s_r, s_t = _plane_stress_rotating_disc(sec)
    num = quad(lambda r: h * (s_r(r) * dw(r) ** 2 + s_t(r) * n * n * w(r) ** 2 / r ** 2) * r, b, a, limit=200)[0]
    return num / quad(lambda r: sec.rho * h * w(r) ** 2 * r, b, a, limit=200)[0]


@pytest.fixture(scope="module")
def axisymmetric_plate():
    return HarmonicSheave(PLATE, 0, n_r=60, n_z=2)


def test_centrifugal_prestress_matches_rotating_disc(axisymmetric_plate):
    m = axisymmetric_plate
    omega = 1000.0
    s_rr, s_tt, _, _ = m.stress(m.centrifugal_displacement(omega))
    r = m.basis.global_coordinates()[0]
    s_r, s_t = _plane_stress_rotating_disc(PLATE)
    away = (r > 0.04) & (r < 0.095)               # clear of the clamped bore face (local 3D constraint)
    scale = np.abs(s_t(r) * omega ** 2).max()
    assert np.abs(s_rr - s_r(r) * omega ** 2)[away].max() < 0.005 * scale     # observed 6e-4
    assert np.abs(s_tt - s_t(r) * omega ** 2)[away].max() < 0.005 * scale     # observed 1.3e-3


@pytest.mark.parametrize("n", range(4))
def test_spinning_frequencies_follow_southwell(n, axisymmetric_plate):
    """Rotating-frame frequencies at 500 and 1000 rad/s against ``omega_0^2 + lambda_n Omega^2`` with the closed-form
    ``lambda_n`` (0.92, 1.27, 2.30, 3.88 for n = 0..3): observed within 0.08 %."""
    m, m0 = HarmonicSheave(PLATE, n, n_r=60, n_z=2), axisymmetric_plate
    f0 = m.modes(1)[0][0]
    lam = _southwell(n, PLATE)
    for omega in (500.0, 1000.0):
        f = m.spinning_modes(omega, m0.stress(m0.centrifugal_displacement(omega)), 1)[0][0]
        assert f == pytest.approx(np.sqrt((2 * np.pi * f0) ** 2 + lam * omega ** 2) / (2 * np.pi), rel=0.005)


@pytest.mark.parametrize("n", (2, 3))
def test_backward_wave_meets_zero_at_the_critical_speed(n, axisymmetric_plate):
    """In the fixed frame the backward wave of n diameters runs at ``omega(Omega) - n Omega``; it reaches zero at
    ``Omega_c = omega_0 / sqrt(n^2 - lambda_n)`` (the disc's critical speed), within 1 % (observed 0.1-0.2 %)."""
    m, m0 = HarmonicSheave(PLATE, n, n_r=60, n_z=2), axisymmetric_plate

    def backward(omega):
        f = m.spinning_modes(omega, m0.stress(m0.centrifugal_displacement(omega)), 1)[0][0]
        return 2 * np.pi * f - n * omega

    w0 = 2 * np.pi * m.modes(1)[0][0]
    predicted = w0 / np.sqrt(n * n - _southwell(n, PLATE))
    found = brentq(backward, 0.7 * predicted, 1.3 * predicted, xtol=1e-3 * predicted)
    assert found == pytest.approx(predicted, rel=0.01)


@pytest.mark.parametrize("n", (1, 3))
def test_travelling_waves_with_coriolis_follow_southwell(n, axisymmetric_plate):
    """With the Coriolis coupling of the two families each diameter number splits into a forward and a backward
    wave (relative to the disc); both follow ``omega_0^2 + lambda_n Omega^2`` at 1000 rad/s to 1 % (observed
    0.06 %), their mean is the uncoupled model's frequency to 1e-4 (Coriolis acts on the small in-plane part of a
    bending wave), and one of the pair runs each way."""
    m, m0 = HarmonicSheave(PLATE, n, n_r=60, n_z=2), axisymmetric_plate
    omega = 1000.0
    prestress = m0.stress(m0.centrifugal_displacement(omega))
    f, sense = m.travelling_modes(omega, prestress, 1)
    closed = np.sqrt((2 * np.pi * m.modes(1)[0][0]) ** 2 + _southwell(n, PLATE) * omega ** 2) / (2 * np.pi)
    np.testing.assert_allclose(f, closed, rtol=0.01)
    assert f.mean() == pytest.approx(m.spinning_modes(omega, prestress, 1)[0][0], rel=1e-4)
    assert sorted(sense) == [-1.0, 1.0] and 0.0 < f[1] - f[0] < 1e-3 * f[0]


@pytest.mark.parametrize("n", (3,))
def test_backward_wave_with_coriolis_stands_still_at_the_critical_speed(n, axisymmetric_plate):
    """A fixed observer sees the backward wave at ``f - n Omega / 2 pi``: with Coriolis coupling it is still
    positive 1 % below the closed-form critical speed ``omega_0 / sqrt(n^2 - lambda_n)`` and negative 1 % above."""
    m, m0 = HarmonicSheave(PLATE, n, n_r=60, n_z=2), axisymmetric_plate
    critical = 2 * np.pi * m.modes(1)[0][0] / np.sqrt(n * n - _southwell(n, PLATE))
    fixed = []
    for omega in (0.99 * critical, 1.01 * critical):
        f, sense = m.travelling_modes(omega, m0.stress(m0.centrifugal_displacement(omega)), 1)
        fixed.append(f[sense < 0][0] - n * omega / (2 * np.pi))
    assert fixed[0] > 0 > fixed[1]


@pytest.mark.slow
def test_solid_reference_with_coriolis_matches_harmonic_travelling_waves():
    """Two implementations of the spinning disc at 1000 rad/s: the 3D P2 tetrahedra with prestress, spin softening
    and the Coriolis matrix assembled by scikit-fem (12,096 DOFs) against the harmonic models on the same section
    mesh.  Every one of the 10 lowest waves has its diameter number and sense from u_z on the face; the frequencies
    agree to 1.5 % (one element across the 2 mm plate, 32 sectors: the polygonal 3D body is 1.1 % stiffer), and
    the Coriolis split of each pair, a 2e-4 effect, to 5 % (observed 1-2 %)."""
    omega = 1000.0
    solid = SolidSheave(PLATE, 10, 1, 32)
    f3, n3, s3 = solid.travelling_modes(omega, 5)
    m0 = HarmonicSheave(PLATE, 0, n_r=10, n_z=1)
    prestress = m0.stress(m0.centrifugal_displacement(omega))
    for n in (1, 2, 3):
        fh, sh = HarmonicSheave(PLATE, n, n_r=10, n_z=1).travelling_modes(omega, prestress, 1)
        pick = np.flatnonzero(n3 == n)[:2]
        assert sorted(s3[pick]) == [-1.0, 1.0]
        for sense in (-1.0, 1.0):
            assert f3[pick][s3[pick] == sense][0] == pytest.approx(fh[sh == sense][0], rel=0.015)
        split3 = f3[pick][s3[pick] < 0][0] - f3[pick][s3[pick] > 0][0]
        assert split3 == pytest.approx(fh[sh < 0][0] - fh[sh > 0][0], rel=0.05)


@pytest.mark.parametrize("n", (1, 2))
def test_fixed_frame_form_of_the_spinning_disc_sees_the_waves_shifted_by_n_omega(n, axisymmetric_plate):
    """The fixed-frame equation the rotor uses for flexible sheaves: amplitudes turned by ``n Omega t`` between
    the families obey ``M y'' + Omega (G_c - 2 n M J) y' + (K_t - n Omega^2 (n M + G_c J)) y = 0`` with
    ``J = [[0, -P], [P, 0]]`` (``P`` flips ``U_theta``).  Solved directly (bore clamped, 600 rad/s), its
    frequencies are the rotating-frame waves of :meth:`travelling_modes` shifted by ``+- n Omega / 2 pi``,
    forward up and backward down, to 1e-7."""
    from cvtfem.elements.sheave_solid import _gyroscopic_modes
    import scipy.sparse as sp

    omega = 600.0
    m0 = axisymmetric_plate
    prestress = m0.stress(m0.centrifugal_displacement(omega))
    cos, sin = HarmonicSheave(PLATE, n, "cos", 60, 2), HarmonicSheave(PLATE, n, "sin", 60, 2)
    free = cos.free_dofs()
    assert np.array_equal(free, sin.free_dofs())
    P = np.ones(cos.basis.N)
    P[cos.basis.split_indices()[1]] = -1.0
    P = sp.diags(P)
    B = cos.coriolis
    Kt = [m.matrices[0] + m.geometric_stiffness(prestress) - omega ** 2 * m.spin_softening for m in (cos, sin)]
    M1, M2 = cos.matrices[1], sin.matrices[1]
    K = sp.block_diag([Kt[0] - n * omega ** 2 * (n * M1 + B @ P), Kt[1] - n * omega ** 2 * (n * M2 - B @ P)])
    G = sp.bmat([[None, B + 2 * n * M1 @ P], [B - 2 * n * P @ M1, None]])
    both = np.concatenate([free, cos.basis.N + free])
    fixed, _ = _gyroscopic_modes(K.tocsr()[both][:, both], sp.block_diag([M1, M2]).tocsr()[both][:, both],
                                 omega * G.tocsr()[both][:, both], 1)
    f, sense = cos.travelling_modes(omega, prestress, 1)
    np.testing.assert_allclose(np.sort(fixed), np.sort(f + sense * n * omega / (2 * np.pi)), rtol=1e-7)
