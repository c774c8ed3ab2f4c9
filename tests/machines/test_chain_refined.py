"""The refined pin–sheave contact H2 on the running chain (issue 13, deliverable 3): RefinedSheaveContact
against the H2 primitives and H1, forces as gradients, friction power, Jacobian, the restoring moment."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.chain.sheave_contact_refined import face_derivatives
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.contact.hertz import hertz_force
from cvtfem.elements.contact.refined import (pin_coefficients, pin_loads, refined_contact, refined_slip,
                                             sheave_coefficients)
from cvtfem.errors import InputError, NumericalError
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_cvt_refined import RefinedChainCVT
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import (assert_energy_balance, assert_forces_are_minus_the_hertz_gradient,
                                         assert_friction_power_is_the_work_rate, assert_jacobian_columns)

RATIO = 2.4
F_APPL = np.array([30000.0, 35000.0])
S = -1.0                                  # side of the sheave the x3 > 0 pin end touches
CONE = Sheave("conical", np.radians(10.0), w=0.0165)


@pytest.fixture(scope="module")
def scene():
    return load_scene("band-6+2n")


@pytest.fixture(scope="module")
def pin_faces(scene):
    """The refined chains by pin end face: ``flat`` (theta = 0, the face the closed forms below assume) and
    ``inclined`` (the presets' face, parallel to the nominal flank: theta = ``geometry.flank_angle``)."""
    return {face: {m: from_scene(scene, reference_geometry(), F_APPL, model=m, contact="hertz-refined", **kw)
                   for m in ("chain-S2", "chain-S3")}
            for face, kw in (("flat", {"face_inclination": 0.0}), ("inclined", {}))}


@pytest.fixture(scope="module")
def models(pin_faces):
    return pin_faces["flat"]


def test_the_presets_face_is_inclined_at_the_flank_angle(scene, pin_faces):
    assert scene.cvt.chain.face_inclination == scene.cvt.geometry.flank_angle > 0
    assert pin_faces["inclined"]["chain-S3"].contact.face_inclination == scene.cvt.geometry.flank_angle
    assert pin_faces["flat"]["chain-S3"].contact.face_inclination == 0.0


def _contact(models, model, face):
    c = models[model].contact
    return c if face == "torus" else replace(c, faces=(CONE, CONE))


def _random_inputs(contact, m=200, seed=0, slope=2e-3, slip=0.2):
    """Local inputs of ``m`` contacts near contact (penetrations -2 ... 40 um) on random arc points of both
    shafts, neighbours one pitch away along the arc, random slopes, slips and rates."""
    rng = np.random.default_rng(seed)
    shafts = rng.integers(0, 2, m)
    r = rng.uniform(0.035, 0.085, m)
    th = rng.uniform(0, 2 * np.pi, m)
    dth = 0.009 / r * (1 + rng.normal(0, 0.02, (3, m)))
    pts = [contact.centres[shafts] + r[:, None] * np.column_stack([np.cos(th + j * dth[j + 1]),
                                                                    np.sin(th + j * dth[j + 1])])
           for j in (-1, 0, 1)]
    pts = [p + rng.normal(0, 2e-5, p.shape) for p in pts]
    w = rng.choice([-1, 1], m) * rng.uniform(150, 400, m)
    z = rng.normal(0, 1e-4, m)
    cols = [*pts, np.zeros((m, 1))] + ([rng.normal(0, slope / 2, (m, 2))] if contact.slopes else []) + [z[:, None]]
    P = np.column_stack(cols)
    vel = [w[:, None] * np.column_stack([-(p - contact.centres[shafts])[:, 1], (p - contact.centres[shafts])[:, 0]])
           + rng.normal(0, slip, (m, 2)) for p in pts]
    V = np.column_stack(vel + [rng.normal(0, slip, (m, 1))] + ([rng.normal(0, 1.0, (m, 2))] if contact.slopes else [])
                        + [rng.normal(0, 0.01, (m, 1))])
    X = np.column_stack([P, V, w])
    d0 = contact.local(X, shafts, details=True)[1]["delta"]
    X[:, 6] += rng.uniform(-2e-6, 4e-5, m) - d0         # u3 sets the penetration (dDelta/du3 = 1)
    return X, shafts


def _unit_chord_normal(X):
    """In-plane pin normal ``k x tau_p`` of the bisector of the unit chords, independently."""
    a, b = X[:, 2:4] - X[:, 0:2], X[:, 4:6] - X[:, 2:4]
    x = a / np.linalg.norm(a, axis=1)[:, None] + b / np.linalg.norm(b, axis=1)[:, None]
    t = x / np.linalg.norm(x, axis=1)[:, None]
    return np.column_stack([-t[:, 1], t[:, 0], np.zeros(len(X))])


@pytest.mark.parametrize("face", ["torus", "cone"])
def test_closed_form_equals_the_h2_primitives(models, face):
    """Penetration, contact point, normal, slip at R_* and the friction loads (1.351) against the numpy H2
    primitives (sheave_coefficients, pin_coefficients, refined_contact, refined_slip, pin_loads)."""
    con = _contact(models, "chain-S3", face)
    X, shafts = _random_inputs(con, seed=1)
    Y, d = con.local(X, shafts, details=True)
    m = len(X)
    R_pin = np.column_stack([X[:, 2:4], X[:, 6]])
    R_c = np.column_stack([con.centres[shafts], X[:, 9]])
    slope = END_SLOPE_FACTOR * X[:, 7:9]
    n_perp = _unit_chord_normal(X)
    tau = np.column_stack([n_perp[:, 1], -n_perp[:, 0]])
    prof = lambda r: face_derivatives(con.faces[0], r)[:3]  # noqa: E731
    sh = sheave_coefficients(X[:, 2:4], R_c, np.zeros((m, 2)), prof, S)
    pin = pin_coefficients(X[:, 6], slope, tau, np.zeros(m), np.zeros((m, 2)),
                           np.broadcast_to(np.eye(2) / con.face_radius, (m, 2, 2)), S)
    ref = refined_contact(X[:, 2:4], *sh, *pin, S)
    np.testing.assert_allclose(d["delta"], ref.delta, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d["offset"], ref.offset, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d["point"], ref.point, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d["normal"], ref.normal, rtol=0, atol=1e-14)
    # slip of the material points at R_*: the pin turns with omega_p (k + gamma) + k x gamma'
    V = X[:, 10:20]
    sd = END_SLOPE_FACTOR * V[:, 7:9]
    a, b = X[:, 2:4] - X[:, 0:2], X[:, 4:6] - X[:, 2:4]
    la, lb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    x = a / la[:, None] + b / lb[:, None]
    dx = ((V[:, 2:4] - V[:, 0:2]) - a * ((a * (V[:, 2:4] - V[:, 0:2])).sum(1) / la ** 2)[:, None]) / la[:, None] \
        + ((V[:, 4:6] - V[:, 2:4]) - b * ((b * (V[:, 4:6] - V[:, 2:4])).sum(1) / lb ** 2)[:, None]) / lb[:, None]
    om = (n_perp[:, :2] * dx).sum(1) / np.linalg.norm(x, axis=1)
    np.testing.assert_allclose(d["spin_rate"], om, rtol=1e-10)
    k = np.array([0.0, 0.0, 1.0])
    g3 = np.column_stack([slope, np.zeros(m)])
    omega_pin = np.cross(k, np.column_stack([sd, np.zeros(m)])) + om[:, None] * (k + g3)
    w3 = np.column_stack([np.zeros((m, 2)), X[:, -1]])
    slip = refined_slip(ref, R_pin, np.column_stack([V[:, 2:4], V[:, 6]]), omega_pin, R_c,
                        np.column_stack([np.zeros((m, 2)), V[:, 9]]), w3)
    np.testing.assert_allclose(d["slip"], slip, rtol=0, atol=1e-12 * np.abs(slip).max())
    assert np.abs(slip).max() > 0.05
    _, Q_slope, Q_phi = pin_loads(d["F_fr"], ref.point - R_pin, g3, np.zeros(m), n_perp)
    Y0 = replace(con, f0=0.0).local(X, shafts)
    np.testing.assert_allclose((Y - Y0)[:, 7:9], 2 * END_SLOPE_FACTOR * Q_slope[:, :2], rtol=0,
                               atol=1e-10 * np.abs(Q_slope).max())
    # the twist moment Q_phi goes to pins p-1, p, p+1 and sums to zero force (a moment)
    np.testing.assert_allclose((Y - Y0)[:, 0:2] + (Y - Y0)[:, 2:4] + (Y - Y0)[:, 4:6], 2 * d["F_fr"][:, :2],
                               rtol=0, atol=1e-10 * np.abs(d["F_fr"]).max())
    assert np.abs(Q_phi).max() > 0
    # the normal force of the exact gradient and the source's N (k - g_*) at R_* differ only at third order
    N = hertz_force(ref.delta, con.c[shafts])[0]
    on = N > 0
    F_src = -N[:, None] * ref.grad
    F_exact = d["F"] - d["F_fr"]
    rel = np.abs(F_exact - F_src)[on].max(axis=1) / N[on]
    assert rel.max() < 2e-3 * (np.abs(ref.offset).max() / 3.5e-3) ** 2


@pytest.mark.parametrize("face", ["torus", "cone"])
def test_s2_is_h1_shifted(models, face):
    """S2 (no slope): H2 is H1 with the penetration raised by f'^2 / (2 m_e) and the contact point moved by
    x_* = f' / m_e along the radius; on a cone (f'' = f''' = 0) the frictionless forces are H1's exactly."""
    con = _contact(models, "chain-S2", face)
    h1 = SheaveContact(con.centres, con.faces, con.c, con.r_outer, 0.0, con.v0, con.law)
    X, shafts = _random_inputs(con, seed=2)
    Y2, d2 = replace(con, f0=0.0).local(X, shafts, details=True)
    X1 = np.column_stack([X[:, 2:4], X[:, 6], X[:, 7], X[:, 10:12], X[:, 14], X[:, 15], X[:, 16]])
    r = np.linalg.norm(X[:, 2:4] - con.centres[shafts], axis=1)
    face_ = con.faces[0]
    tg, fpp = face_.tan_gamma(r), face_.d2z0(r)
    me = 1 / con.face_radius - fpp
    shift = tg ** 2 / (2 * me)
    d1 = h1.local(X1, shafts, details=True)[1]
    np.testing.assert_allclose(d2["delta"] - d1["delta"], shift, rtol=1e-9, atol=1e-15)
    e = (X[:, 2:4] - con.centres[shafts]) / r[:, None]
    np.testing.assert_allclose(d2["offset"], -(tg / me)[:, None] * e, rtol=0, atol=1e-15)
    np.testing.assert_allclose(d2["radius"], r - tg / me, rtol=1e-12)
    X1s = X1.copy()
    X1s[:, 2] += shift                                      # the H1 pin end pushed in by the shift
    Y1 = h1.local(X1s, shafts)
    scale = np.abs(Y1).max()
    if face == "cone":
        np.testing.assert_allclose(Y2[:, 2:4], Y1[:, 0:2], rtol=0, atol=1e-12 * scale)
    # in-plane: H1's radial force with the face slope at the contact radius r + x_e (third order in x_e)
    N = hertz_force(d2["delta"], con.c[shafts])[0]
    np.testing.assert_allclose(Y2[:, 2:4], (2 * N * face_.tan_gamma(r - tg / me))[:, None] * e, rtol=0,
                               atol=1e-7 * scale)
    np.testing.assert_allclose(Y2[:, [6, 7, 8]], Y1[:, [2, 3, 4]], rtol=0, atol=1e-9 * scale)   # u3 + shift rounds
    assert np.all(Y2[:, [0, 1, 4, 5]] == 0)                 # no twist without friction


@pytest.mark.parametrize("pin_face", ["flat", "inclined"])
@pytest.mark.parametrize("model, face", [("chain-S3", "torus"), ("chain-S3", "cone"), ("chain-S2", "torus")])
def test_forces_are_minus_the_gradient_of_the_hertz_potential(pin_faces, pin_face, model, face):
    """Frictionless generalized forces on every position input (neighbours, pin end, slopes, sheave) and on
    the shaft spin = minus the central-difference gradient of 2 x 2/5 c Delta^{5/2}, 1e-6 relative."""
    con = replace(_contact(pin_faces[pin_face], model, face), f0=0.0)
    X, shafts = _random_inputs(con, seed=3)
    Y = assert_forces_are_minus_the_hertz_gradient(con, X, shafts)
    assert np.all(Y[:, con.n_pos] == 0)                     # axisymmetric sheave: no moment on phi


@pytest.mark.parametrize("pin_face", ["flat", "inclined"])
@pytest.mark.parametrize("model", ["chain-S3", "chain-S2"])
def test_friction_power_is_the_work_rate_of_the_friction_forces(pin_faces, pin_face, model):
    con = pin_faces[pin_face][model].contact
    X, shafts = _random_inputs(con, seed=4)
    assert_friction_power_is_the_work_rate(con, X, shafts)


def test_restoring_moment_against_misalignment(models):
    """A pin tilted in its radial plane (turned about tau) gets the end moment that untilts it: on ``u'``
    ``dY/du'_e = -2 F^2 (N / m_e + N' x_e^2)`` < 0 (F = END_SLOPE_FACTOR), by central differences; H1 has none."""
    con = replace(models["chain-S3"].contact, f0=0.0)
    X, shafts = _random_inputs(con, seed=5, slope=0.0)
    Y, d = con.local(X, shafts, details=True)
    on = d["delta"] > 1e-6                                  # away from grazing (N'' ~ Delta^-1/2)
    r_vec = X[:, 2:4] - con.centres[shafts]
    r = np.linalg.norm(r_vec, axis=1)
    e = r_vec / r[:, None]
    h = 1e-7
    Xp, Xm = X.copy(), X.copy()
    Xp[:, 7:9] += h * e
    Xm[:, 7:9] -= h * e
    dY = ((con.local(Xp, shafts)[:, 7:9] - con.local(Xm, shafts)[:, 7:9]) * e).sum(1) / (2 * h)
    _, fp, fpp, _ = face_derivatives(con.faces[0], r)
    me = 1 / con.face_radius - fpp
    N, dN = hertz_force(d["delta"], con.c[shafts])
    xe = fp / me
    expected = -2 * END_SLOPE_FACTOR ** 2 * (N / me + dN * xe ** 2)
    np.testing.assert_allclose(dY[on], expected[on], rtol=1e-6)
    assert np.all(dY[on] < 0)


def test_bad_face_radius_and_a_pin_on_the_axis_fail_loudly(models):
    con = models["chain-S3"].contact
    with pytest.raises(InputError, match="face_radius"):
        replace(con, face_radius=0.0)
    X, shafts = _random_inputs(con, m=3, seed=6)
    X[1, 2:4] = con.centres[shafts[1]]
    with pytest.raises(NumericalError, match="shaft axis"):
        con.local(X, shafts)


def test_scene_builds_the_refined_chain(scene):
    from cvtfem.machines.cvt import chain_loop
    m = chain_loop(load_scene("chain-S3-refined"))
    assert isinstance(m, RefinedChainCVT) and m.contact.slopes and m.family.ndof == 5
    m2 = chain_loop(load_scene("chain-S3-refined").replace({"cvt": {"model": "chain-S2",
                                                                       "effects": {"pin_bending": False}}}))
    assert isinstance(m2, RefinedChainCVT) and not m2.contact.slopes


#: Largest contact point offset |x_*| (m) at the quasi-static start: flat face R_f tan(gamma) / (1 - R_f f'') ~ 3.4 mm
#: (the point inside the face half-height 3.02 mm only for some pins), inclined at the flank angle 0.3-0.4 mm
#: (docs/transmission.md, session 12: the toroidal flank runs 9.1-11.1 deg against the face's 10 deg).
OFFSET_BAND = {"flat": (2e-3, 4e-3), "inclined": (1e-4, 6e-4)}


@pytest.fixture(scope="module")
def static_s3(pin_faces, scene):
    """The quasi-static start of chain-S3 with the pin face ``flat`` or ``inclined`` (each solved on first use)."""
    starts = {}

    def start(pin_face):
        if pin_face not in starts:
            starts[pin_face] = pin_faces[pin_face]["chain-S3"].static_state(RATIO, scene.cvt.regime.input_speed)
        return starts[pin_face]
    return start


@pytest.mark.parametrize("pin_face", ["flat", "inclined"])
def test_static_state_with_refined_contact(pin_faces, pin_face, static_s3):
    """The quasi-static start with H2: balanced, pins on the planned radii (the driving sheave shifted by the
    H2 approach), axial forces = clamping forces, contact points x_* where the face puts them."""
    m = pin_faces[pin_face]["chain-S3"]
    x0, rep = static_s3(pin_face)
    assert rep["residual"] < 1e-8 and rep["max_penetration"] < 5e-5
    o = m.outputs(0.0, x0)
    np.testing.assert_allclose(o["contact.sheave_axial_force"], [rep["F1"], F_APPL[1]], rtol=1e-8)
    q = x0[:m.n2]
    pins, shafts, X, (Y, d) = m._contacts(q, np.zeros(m.n2), details=True)
    on = d["delta"] > 0
    u = m.family.split(q[:m.family.size])[0]
    pl = rep["placement"]
    for k in (0, 1):
        r = np.linalg.norm(u[pins[on & (shafts == k)]] - m.contact.centres[k], axis=1)
        assert np.abs(r - pl.r[k]).max() < 2e-4          # within 0.2 mm of the planned arc
    low, high = OFFSET_BAND[pin_face]
    assert low < np.abs(d["offset"][on]).max() < high
    # the start turns the pins and their slopes with their sheave: no slip at the offset contact points, but the
    # first and last pin of an arc turn slower than the sheave (one link on the span), so their contact point,
    # x_* off the axis, slips by about w |x_*| / 2 (flat face: 0.47 m/s driving, 0.20 m/s driven; inclined: 0.04 /
    # 0.02 m/s); the measured factor, 0.85 driving and 0.69 driven, is the same for both faces to 2 %
    n = m.family.n
    slip = o["contact.slip_speed"].reshape(n, 2)
    N = o["contact.normal_force"].reshape(n, 2)
    offset = o["contact.face_offset"].reshape(n, 2)
    for k in (0, 1):
        on = N[:, k] > 0
        inner = on & on[m.family.im1] & on[m.family.ip1]
        assert np.all(slip[inner, k] < 1e-9) and (on & ~inner).sum() == 2
        w_k = x0[m.n2 + m._idx[1][k]]
        factor = slip[on & ~inner, k] / (w_k * offset[on & ~inner, k] / 2)
        assert np.all(np.abs(factor - (0.85, 0.69)[k]) < 0.03)


@pytest.mark.parametrize("pin_face", ["flat", "inclined"])
def test_jacobian_of_the_refined_chain_against_differences(pin_faces, pin_face, static_s3):
    m = pin_faces[pin_face]["chain-S3"]
    rng = np.random.default_rng(7)
    x = static_s3(pin_face)[0].copy()
    nc, n2 = m.family.size, m.n2
    x[:nc] += rng.normal(0.0, 2e-6, nc)
    x[n2:n2 + nc] += rng.normal(0.0, 0.05, nc)
    J = m.jac(0.0, x).toarray()
    assert not np.any(J[~m.jac_sparsity.toarray()])
    n = m.family.n
    slopes = 3 * n + rng.choice(2 * n, 12, replace=False)      # u' columns
    cols = np.concatenate([rng.choice(3 * n, 12, replace=False), slopes, n2 + rng.choice(nc, 12, replace=False),
                           n2 + slopes[:6], np.arange(nc, n2), n2 + np.arange(nc, n2)])
    assert_jacobian_columns(m, x, J, cols)


@pytest.mark.parametrize("pin_face", ["flat", "inclined"])
def test_energy_balance_over_a_short_run(pin_faces, pin_face, static_s3):
    """20 us of running from the quasi-static start (Radau, rtol 1e-6): E(t) - E(0) = input - output +
    clamping - dissipated work to 1e-6 of the input work."""
    x0, rep = static_s3(pin_face)
    m = pin_faces[pin_face]["chain-S3"].with_clamping([rep["F1"], F_APPL[1]])
    assert_energy_balance(m, x0, 2e-5)


@pytest.mark.slow
def test_run_chain_s3_refined_balances_energy_and_axial_forces(cli, tmp_path):
    """2 ms of the chain-S3-refined preset through the CLI: the work integrals close the energy balance to 1e-5
    of the input work, every output is finite, and over the second millisecond the pins' axial forces on each
    sheave balance its clamping force on average to 1 %."""
    import h5py
    h5 = tmp_path / "r.h5"
    r = cli("run", "chain-S3-refined", "--until", "2e-3", "--results", str(h5), timeout=900)
    assert r.returncode == 0, r.stderr
    with h5py.File(h5) as f:
        s = f["series"]
        for name in s:
            assert np.isfinite(s[name][:]).all(), name
        W, E = s["work"][-1], s["energy"][:]
        late = s["time"][:] >= 1e-3 - 1e-12
        axial = s["contact.sheave_axial_force"][late]
        clamping = np.column_stack([s["driving.clamping_force"][late], s["driven.clamping_force"][late]])
    assert W[0] > 100.0
    assert abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-5 * W[0]
    np.testing.assert_allclose(axial.mean(axis=0), clamping.mean(axis=0), rtol=0.01)


@pytest.mark.parametrize("law", ["tanh", "smooth", "arctan", "linear-saturated", "smoothed"])
@pytest.mark.parametrize("pin_face", ["flat", "inclined"])
@pytest.mark.parametrize("model, face", [("chain-S3", "torus"), ("chain-S3", "cone"), ("chain-S2", "torus")])
def test_kernel_equals_the_numpy_twin(pin_faces, pin_face, model, face, law):
    con = replace(_contact(pin_faces[pin_face], model, face), law=law)
    X, shafts = _random_inputs(con, seed=8)
    X[:3, con.n_pos:] = 0.0                                      # three contacts without any motion: zero slip
    Yk, Yr = con.local(X, shafts), con.local(X, shafts, reference=True)
    assert np.all(np.abs(Yk - Yr) <= 1e-12 * np.abs(Yr).max(axis=0))
    assert np.all(Yr[:3, -1] == 0) and np.abs(Yr[3:, -1]).max() > 1.0


@pytest.mark.parametrize("face", [Sheave("toroidal", 0.0, R=1.5, y=0.2), CONE])
def test_face_derivatives_are_derivatives_of_the_sheave_face(face):
    """``f = -s(r)`` of the band's Sheave (z0 with w = 0) and its first three derivatives, by differences."""
    r, h = np.linspace(0.03, 0.09, 13), 1e-6
    f, fp, fpp, f3 = face_derivatives(face, r)
    np.testing.assert_allclose(f, replace(face, w=0.0).z0(r), rtol=0, atol=1e-15)
    up, dn = face_derivatives(face, r + h), face_derivatives(face, r - h)
    for i, deriv in enumerate((fp, fpp, f3)):
        np.testing.assert_allclose((up[i] - dn[i]) / (2 * h), deriv, rtol=1e-7, atol=1e-7 * np.abs(deriv).max() + 1e-12)
