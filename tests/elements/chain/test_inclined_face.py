"""The inclined pin end face in H2 (session 12, issue 14): the face ``z = tan(theta) xi_o + |xi|^2 / (2 R_f)`` over
the pin section, its normal tilted by ``theta`` outward in the pin's radial plane (digest §5.4, linear coefficient
``beta``), turning with the pin spin.  Checked: ``theta = 0`` is the session-11 kernel bit for bit; the compiled kernel
equals its numpy twin; on a cone with ``theta`` = the flank angle an untilted pin parallel to the axis touches on its
axis (``x_* = 0``, H1's forces); the closed form equals the independent H2 primitives (``pin_coefficients`` with
``beta``) for untilted pins and differs by ``O(|gamma| tan(theta))`` with end slopes (the dropped cross terms); the
frictionless forces are minus the gradient of the Hertz potential (now also on the neighbours: the face turns with
the pin); the friction power is the work rate of the friction forces."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.contact.refined import pin_coefficients, refined_contact, sheave_coefficients
from cvtfem.elements.chain.sheave_contact_refined import face_derivatives
from cvtfem.errors import InputError
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene
from tests.machines.chain_checks import (assert_forces_are_minus_the_hertz_gradient,
                                         assert_friction_power_is_the_work_rate)
from tests.machines.test_chain_refined import CONE, F_APPL, S, _random_inputs, _unit_chord_normal

FIXTURE = Path(__file__).parents[2] / "data" / "refined_kernel_theta0.npz"
THETA = np.radians(10.0)                        # the flank angle of CONE


@pytest.fixture(scope="module")
def contacts():
    """The refined contacts with the flat face (theta = 0, session 11's; the presets' face is inclined): the tests
    below incline it where they mean to."""
    scene = load_scene("band-6+2n")
    out = {}
    for model in ("chain-S2", "chain-S3"):
        con = from_scene(scene, reference_geometry(), F_APPL, model=model, contact="hertz-refined",
                         face_inclination=0.0).contact
        out[model, "torus"], out[model, "cone"] = con, replace(con, faces=(CONE, CONE))
    return out


@pytest.mark.parametrize("model", ["chain-S2", "chain-S3"])
@pytest.mark.parametrize("face", ["torus", "cone"])
def test_zero_inclination_is_the_session_11_kernel_bit_for_bit(contacts, model, face):
    """Inputs and outputs stored from the kernel before the inclination (git 9af04cd, 40 contacts)."""
    data = np.load(FIXTURE)
    key = f"{model}_{face}"
    con = contacts[model, face]
    assert con.face_inclination == 0.0
    Y = con.local(data[key + "_X"], data[key + "_shafts"])
    assert np.array_equal(Y, data[key + "_Y"]) and np.abs(Y).max() > 0


@pytest.mark.parametrize("model", ["chain-S2", "chain-S3"])
@pytest.mark.parametrize("face", ["torus", "cone"])
def test_compiled_kernel_equals_its_numpy_twin(contacts, model, face):
    con = replace(contacts[model, face], face_inclination=THETA)
    X, shafts = _random_inputs(con, seed=21)
    Y, Yref = con.local(X, shafts), con.local(X, shafts, reference=True)
    np.testing.assert_allclose(Y, Yref, rtol=1e-12, atol=1e-12 * np.abs(Yref).max())


def _rolling_pins(con, m=60, seed=0):
    """Frictionless inputs of pins ``p-1, p, p+1`` one pitch apart on circles about their shaft, counter-clockwise
    (the chain's sense), untilted (slopes 0), at rest, penetrations 1-30 um of the contact's own closed form."""
    rng = np.random.default_rng(seed)
    shafts = rng.integers(0, 2, m)
    r = rng.uniform(0.035, 0.085, m)
    th = rng.uniform(0, 2 * np.pi, m)
    pts = [con.centres[shafts] + r[:, None] * np.column_stack([np.cos(th + j * 0.009 / r), np.sin(th + j * 0.009 / r)])
           for j in (-1, 0, 1)]
    z = rng.normal(0, 1e-4, (m, 1))
    P = np.column_stack([*pts, np.zeros((m, 1))] + ([np.zeros((m, 2))] if con.slopes else []) + [z])
    X = np.column_stack([P, np.zeros_like(P), np.zeros(m)])
    d0 = con.local(X, shafts, details=True)[1]["delta"]
    X[:, 6] += rng.uniform(1e-6, 3e-5, m) - d0
    return X, shafts


@pytest.mark.parametrize("model", ["chain-S2", "chain-S3"])
def test_face_inclined_at_the_flank_angle_touches_a_cone_on_the_pin_axis(contacts, model):
    """Cone of flank angle gamma, face inclined at gamma, pin parallel to the shaft axis: the two surfaces' slopes
    agree at the axis end, so ``x_* = 0`` exactly, no extra approach, and the frictionless forces are H1's at the
    axis end (no bending or twist moment).  At ``theta = 0`` the point is ``R_f tan(gamma)`` = 3.5 mm inside."""
    con = replace(contacts[model, "cone"], face_inclination=THETA, f0=0.0)
    X, shafts = _rolling_pins(con)
    Y, d = con.local(X, shafts, details=True)
    assert np.abs(d["offset"]).max() < 1e-17
    np.testing.assert_allclose(con.extra_approach(0, np.array([0.05])), 0.0, atol=1e-20)
    h1 = SheaveContact(con.centres, con.faces, con.c, con.r_outer, 0.0, con.v0, con.law)
    X1 = np.column_stack([X[:, 2:4], X[:, 6], X[:, con.n_pos - 1], np.zeros((len(X), 4)), X[:, -1]])
    Y1, d1 = h1.local(X1, shafts, details=True)
    np.testing.assert_allclose(d["delta"], d1["delta"], rtol=0, atol=1e-17)
    scale = np.abs(Y1).max()
    np.testing.assert_allclose(Y[:, 2:4], Y1[:, 0:2], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(Y[:, 6], Y1[:, 2], rtol=0, atol=1e-12 * scale)
    assert np.abs(Y[:, [0, 1, 4, 5]]).max() < 1e-12 * scale                  # no twist
    if con.slopes:
        assert np.abs(Y[:, 7:9]).max() < 1e-12 * scale                       # no bending moment
    x0 = replace(con, face_inclination=0.0).local(X, shafts, details=True)[1]["offset"]
    np.testing.assert_allclose(np.linalg.norm(x0, axis=1), 0.02 * np.tan(THETA), rtol=1e-12)


@pytest.mark.parametrize("face", ["torus", "cone"])
def test_closed_form_equals_the_h2_primitives_with_beta(contacts, face):
    """Penetration, contact point and normal against ``pin_coefficients`` with the face slope ``beta = (0, T)`` in
    the pin frame ``(tau_p, n_perp)``: equal to round-off for untilted pins (S2), within ``O(|gamma| T)`` with end
    slopes (S3: the kernel drops the primitives' cross terms ``gamma . beta`` of the tilted face)."""
    for model, tol in (("chain-S2", 1e-15), ("chain-S3", None)):
        con = replace(contacts[model, face], face_inclination=THETA)
        X, shafts = _random_inputs(con, seed=22)
        _, d = con.local(X, shafts, details=True)
        m = len(X)
        slope = END_SLOPE_FACTOR * X[:, 7:9] if con.slopes else np.zeros((m, 2))
        n_perp = _unit_chord_normal(X)
        tau = np.column_stack([n_perp[:, 1], -n_perp[:, 0]])
        R_c = np.column_stack([con.centres[shafts], X[:, con.n_pos - 1]])
        prof = lambda r: face_derivatives(con.faces[0], r)[:3]  # noqa: E731
        sh = sheave_coefficients(X[:, 2:4], R_c, np.zeros((m, 2)), prof, S)
        beta = np.column_stack([np.zeros(m), np.full(m, np.tan(THETA))])
        pin = pin_coefficients(X[:, 6], slope, tau, np.zeros(m), beta,
                               np.broadcast_to(np.eye(2) / con.face_radius, (m, 2, 2)), S)
        ref = refined_contact(X[:, 2:4], *sh, *pin, S)
        if tol is not None:
            np.testing.assert_allclose(d["delta"], ref.delta, rtol=0, atol=tol)
            np.testing.assert_allclose(d["offset"], ref.offset, rtol=0, atol=tol)
            np.testing.assert_allclose(d["point"], ref.point, rtol=0, atol=tol)
            np.testing.assert_allclose(d["normal"], ref.normal, rtol=0, atol=1e-14)
        else:   # |gamma| up to ~3e-3 here: x_* within |gamma| T |x_*| + R_f |gamma| T ~ 1e-5 m
            g = np.abs(slope).max()
            assert g > 1e-3
            assert np.abs(d["offset"] - ref.offset).max() < 2 * con.face_radius * g * np.tan(THETA)
            assert np.abs(d["delta"] - ref.delta).max() < 2 * g * np.tan(THETA) * np.abs(ref.offset).max()


@pytest.mark.parametrize("model, face", [("chain-S3", "torus"), ("chain-S3", "cone"), ("chain-S2", "torus")])
def test_forces_are_minus_the_gradient_of_the_hertz_potential(contacts, model, face):
    """Frictionless generalized forces on every position input (the neighbours too: the face turns with the pin
    spin) = minus the central-difference gradient of 2 x 2/5 c Delta^{5/2}, 1e-6 relative; nonzero twist."""
    con = replace(contacts[model, face], f0=0.0, face_inclination=THETA)
    X, shafts = _random_inputs(con, seed=23)
    Y = assert_forces_are_minus_the_hertz_gradient(con, X, shafts)
    assert np.abs(Y[:, [0, 1, 4, 5]]).max() > 1e-4 * np.abs(Y[:, 2:4]).max()     # twist from the turning face
    assert np.all(Y[:, con.n_pos] == 0)


@pytest.mark.parametrize("model", ["chain-S3", "chain-S2"])
def test_friction_power_is_the_work_rate_of_the_friction_forces(contacts, model):
    con = replace(contacts[model, "torus"], face_inclination=THETA)
    X, shafts = _random_inputs(con, seed=24)
    assert_friction_power_is_the_work_rate(con, X, shafts)


def test_bad_inclination_is_refused(contacts):
    con = contacts["chain-S3", "torus"]
    for bad in (-0.1, np.pi / 4, np.nan):
        with pytest.raises(InputError, match="face_inclination"):
            replace(con, face_inclination=bad)


def test_face_offset_output_is_the_contact_points_distance_from_the_axis():
    """``contact.face_offset`` of an H2 chain = |x_*| of its contacts in contact (0 off contact); H1 has none."""
    from cvtfem.machines.chain_cvt import from_scene as chain_from_scene

    scene = load_scene("band-6+2n")
    F = np.array([30000.0, 35000.0])
    h1 = chain_from_scene(scene, reference_geometry(), F, model="chain-A1", contact="hertz")
    assert "contact.face_offset" not in {s.name for s in h1.output_specs}
    model = chain_from_scene(scene, reference_geometry(), F, model="chain-A1", contact="hertz-refined",
                             face_inclination=THETA)
    nc, _, iz, _ = model._idx
    pl, u3, z = model.wedge_guess(2.4, 35000.0)
    x = np.zeros(model.size)
    x[:nc] = model._placed(pl, u3)
    x[iz] = z
    out = model.outputs(0.0, x)
    ends, shafts, _, (_, d) = model._contacts(x[:model.n2], x[model.n2:2 * model.n2], details=True)
    on = d["delta"] > 0
    expect = np.zeros(2 * model.n_ends)
    expect[2 * ends[on] + shafts[on]] = np.linalg.norm(d["offset"][on], axis=1)
    assert on.sum() > 40
    np.testing.assert_array_equal(out["contact.face_offset"], expect)


def _made_up_run(path, offsets, normal):
    """A results file of the variant-a scene with the history's series and the given ``contact.face_offset`` and
    ``contact.normal_force`` rows (rows, 2 n)."""
    from cvtfem.io.results import ResultsWriter
    from cvtfem.outputs import OutputSpec

    scene = load_scene("variant-a")
    n2 = offsets.shape[1]
    specs = [OutputSpec(name, "", "", size) for name, size in (
        ("driving.speed", 1), ("driven.speed", 1), ("ratio", 1), ("work", 4), ("energy", 1),
        ("driving.clamping_force", 1), ("driven.clamping_force", 1), ("contact.face_offset", n2),
        ("contact.normal_force", n2))]
    with ResultsWriter(path, scene.to_toml(), "run", specs) as w:
        for j, (x, N) in enumerate(zip(offsets, normal)):
            t = 1e-4 * j
            w.append(t, {"driving.speed": 366.0, "driven.speed": 152.0, "ratio": 2.4,
                         "work": [100 * t, 97 * t, 3 * t, 0.0], "energy": 1.0, "driving.clamping_force": 4e4,
                         "driven.clamping_force": 3.5e4, "contact.face_offset": x, "contact.normal_force": N})
    return path


def test_history_reports_the_share_of_contacts_off_the_pin_face(tmp_path, capsys):
    """Ends in contact on the driving shaft with 1 in 10 beyond the face half-height ``width_n / 2`` (the scene's
    pin: ``pin_area / sqrt(12 pin_I_min / pin_area) / 2`` = 3.02 mm) and none on the driven: 10 % and 0 %, a
    warning (more than 5 %); an end off contact with a large offset does not count."""
    from cvtfem.cli import main
    from cvtfem.io.results import read_results
    from cvtfem.analysis.chain_results import off_face

    ch = load_scene("variant-a").cvt.chain
    h = 0.5 * ch.pin_area / np.sqrt(12 * ch.pin_I_min / ch.pin_area)
    rows, n = 5, 84
    x = np.zeros((rows, n, 2))
    N = np.zeros((rows, n, 2))
    N[:, :20, 0], N[:, 40:70, 1] = 3000.0, 900.0
    x[:, :20, 0] = 0.5 * h
    x[:, :2, 0] = 1.01 * h                                      # 2 of 20 driving contacts off the face
    x[:, 40:70, 1] = 0.9 * h
    x[:, 80, 1] = 5 * h                                         # off contact: not counted
    path = _made_up_run(tmp_path / "run.h5", x.reshape(rows, -1), N.reshape(rows, -1))
    face = off_face(read_results(path))
    np.testing.assert_allclose(face["half_height"], h, rtol=1e-12)
    np.testing.assert_allclose(face["fraction"], [0.1, 0.0], rtol=1e-12)
    np.testing.assert_allclose(face["mean"], [(18 * 0.5 + 2 * 1.01) / 20 * h, 0.9 * h], rtol=1e-12)
    assert main(["history", str(path)]) == 0
    printed = capsys.readouterr().out
    assert "driving 10.0%, driven 0.0%" in printed and "warning: 10% of the contacts" in printed
    x[:, :2, 0] = 0.99 * h
    path = _made_up_run(tmp_path / "run2.h5", x.reshape(rows, -1), N.reshape(rows, -1))
    assert main(["history", str(path)]) == 0
    printed = capsys.readouterr().out
    assert "driving 0.0%, driven 0.0%" in printed and "warning" not in printed


def test_hertz_constant_of_the_inclined_face_lies_between_those_of_its_two_radii():
    """The inclined graph face has the radii ``R_f / cos(theta)`` (circumferential) and ``R_f / cos^3(theta)``
    (radial): its Hertz constant lies between those of spheres with either radius; theta = 0 is the sphere's."""
    from cvtfem.elements.band.geometry import Sheave
    from cvtfem.elements.chain.sheave_contact import hertz_constant

    g = load_scene("variant-a").cvt.geometry
    for face in (CONE, Sheave(g.sheave_profile, g.flank_angle, g.torus_radius, g.torus_offset)):
        c = hertz_constant(face, 0.06, 0.02, 2.1e11, 0.3, THETA)
        low = hertz_constant(face, 0.06, 0.02 / np.cos(THETA), 2.1e11, 0.3)
        high = hertz_constant(face, 0.06, 0.02 / np.cos(THETA) ** 3, 2.1e11, 0.3)
        assert low < c < high and high / low < 1.03
        assert hertz_constant(face, 0.06, 0.02, 2.1e11, 0.3, 0.0) == hertz_constant(face, 0.06, 0.02, 2.1e11, 0.3)


def test_run_summary_reports_the_share_of_contacts_off_the_face():
    """chain-S3 with H2 from its quasi-static start: with the symmetric face (theta = 0) every driven contact point
    lies ``R_f tan(gamma) / (1 - R_f f'')`` ~ 3.8 mm inside the pin axis, beyond the 3.02 mm face half-height; with
    the face inclined at the flank angle (the presets' face since session 13) none does."""
    from cvtfem.analysis.run import run_scene

    tilted = load_scene("chain-S3-refined")
    assert tilted.cvt.chain.face_inclination == tilted.cvt.geometry.flank_angle
    flat = run_scene(tilted.replace({"cvt": {"chain": {"face_inclination": 0.0}}}), until=1e-5, results=None,
                     show_progress=False)
    assert flat.off_face_fraction[1] == 1.0 and 0.0 <= flat.off_face_fraction[0] < 0.5
    assert run_scene(tilted, until=1e-5, results=None, show_progress=False).off_face_fraction == [0.0, 0.0]
