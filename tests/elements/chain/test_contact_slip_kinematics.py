"""Slip kinematics of the pin–sheave contacts (session 11, issue 14's efficiency): the slip is the velocity of the
pin's material point at the contact point minus the sheave's material point there (contact digest §5.6, (1.350)).

Pins that roll rigidly with their sheave do not slip (H1 at the pin-axis end, H2 at ``R_*`` ~3.5 mm inside it,
with the pin's spin from its link chords and its end slope turning along); a sheave spinning faster by ``dw``
slips by ``dw`` times the radius of the *contact point*; a pin whose rear link does not turn (the entry pin, its
rear link still on the span) spins at half the sheave's rate and its contact point slides circumferentially by
``w |x_*| / 2``; a pin sinking radially slides by the tangential part of its radial speed."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

CENTRES = np.array([[0.0, 0.0], [0.155, 0.0]])
FACES = {"cone": Sheave("conical", np.radians(11.0)),
         "torus": Sheave("toroidal", np.radians(10.0), R=1.5, y=0.2)}   # the reference sheaves
K = np.array([0.0, 0.0, 1.0])


def _kx(a):
    """``k x a`` of in-plane vectors (m, 2)."""
    return np.column_stack([-a[:, 1], a[:, 0]])


def _h2(face, slopes=True):
    f = FACES[face]
    return RefinedSheaveContact(CENTRES, (f, f), np.array([1e10, 1e10]), 0.1, 0.1, 0.02, 0.02,
                                np.array([2, 0, 1]), np.array([1, 2, 0]), slopes=slopes)


def _rolling(con, seed=0, m=50):
    """Inputs (m, n_in) of H2 contacts whose pins ``p-1, p, p+1`` sit on circles about their shaft (one pitch
    apart, random radii, angles, end slopes and axial positions) and turn rigidly with it at ``w``: the pin's
    position and slope vectors rotate at ``w``, its axial position and the sheave's stay."""
    rng = np.random.default_rng(seed)
    shafts = rng.integers(0, 2, m)
    r = rng.uniform(0.035, 0.085, m)
    th = rng.uniform(0, 2 * np.pi, m)
    w = rng.choice([-1, 1], m) * rng.uniform(150, 400, m)
    pts = [CENTRES[shafts] + r[:, None] * np.column_stack([np.cos(th + j * 0.009 / r), np.sin(th + j * 0.009 / r)])
           for j in (-1, 0, 1)]
    vel = [w[:, None] * _kx(p - CENTRES[shafts]) for p in pts]
    u3 = rng.uniform(0.012, 0.013, m)[:, None]
    z = rng.normal(0, 1e-4, (m, 1))
    zero = np.zeros((m, 1))
    P, V = [*pts, u3], [*vel, zero]
    if con.slopes:
        g = rng.normal(0, 2e-3, (m, 2))
        P.append(g)
        V.append(w[:, None] * _kx(g))
    X = np.column_stack(P + [z] + V + [zero, w[:, None]])
    return X, shafts, w


@pytest.mark.parametrize("face", ["cone", "torus"])
@pytest.mark.parametrize("slopes", [False, True])
def test_h2_pin_rolling_with_its_sheave_has_zero_slip(face, slopes):
    con = _h2(face, slopes)
    X, sh, w = _rolling(con)
    _, d = con.local(X, sh, details=True)
    assert np.all((np.linalg.norm(d["offset"], axis=1) > 2e-3) & (np.linalg.norm(d["offset"], axis=1) < 6e-3))  # R_* mm off the axis
    assert np.allclose(d["spin_rate"], w, rtol=1e-12)                             # the chords turn with the sheave
    assert np.abs(d["slip"]).max() < 1e-12 * np.abs(w).max() * 0.1


@pytest.mark.parametrize("face", ["cone", "torus"])
def test_h2_sheave_spinning_faster_slips_by_its_extra_rate_times_the_contact_radius(face):
    """The sheave's material point is taken at ``R_*``, not under the pin axis: ``|v_r| = dw |d + x_*|``."""
    con = _h2(face)
    X, sh, w = _rolling(con, seed=1)
    dw = 0.7
    X[:, -1] += dw
    _, d = con.local(X, sh, details=True)
    arm = X[:, 2:4] - CENTRES[sh] + d["offset"]
    expect = -dw * _kx(arm)
    n = d["normal"]
    expect3 = np.column_stack([expect, np.zeros(len(X))])
    expect3 -= np.sum(n * expect3, axis=1)[:, None] * n
    assert np.abs(d["slip"] - expect3).max() < 1e-12
    pin_axis_radius = np.linalg.norm(X[:, 2:4] - CENTRES[sh], axis=1)
    assert np.all(d["radius"] < pin_axis_radius - 1e-3)                         # the face is steeper inside
    assert np.allclose(np.linalg.norm(d["slip"], axis=1), dw * d["radius"], rtol=1e-3)   # normal ~ (e, 1)


@pytest.mark.parametrize("face", ["cone", "torus"])
def test_h2_entry_pin_spins_at_half_the_sheave_rate_and_slides_by_half_omega_offset(face):
    """Rear neighbour moving with the pin (its link does not turn): ``omega_p = w / 2`` exactly (the bisector's
    angle is the mean of the chord angles), and the contact point slides by ``-(w/2) k x x_*``, of size
    ``w |x_*| / 2`` (0.64 m/s at 366 rad/s and 3.5 mm): the entry and exit pins' term."""
    con = _h2(face, slopes=False)
    X, sh, w = _rolling(con, seed=2)
    n = con.n_pos
    X[:, n:n + 2] = X[:, n + 2:n + 4]                       # pin p-1 moves as pin p: the rear chord translates
    _, d = con.local(X, sh, details=True)
    assert np.allclose(d["spin_rate"], w / 2, rtol=1e-12)
    x = d["offset"]
    expect = np.column_stack([-(w / 2)[:, None] * _kx(x), np.zeros(len(X))])
    assert np.abs(d["slip"] - expect).max() < 1e-12       # circumferential: in the face's tangent plane
    assert np.allclose(np.linalg.norm(d["slip"], axis=1), np.abs(w) / 2 * np.linalg.norm(x, axis=1), rtol=1e-12)


def test_h2_pin_sinking_radially_slides_by_the_tangential_part_of_its_radial_speed():
    """All three pins moving radially at ``c`` scale the polygon (chords keep their directions): the slip is
    the tangential projection of ``c e``."""
    con = _h2("cone", slopes=False)
    X, sh, w = _rolling(con, seed=3)
    n, c = con.n_pos, -0.05
    for j in range(3):
        dvec = X[:, 2 * j:2 * j + 2] - CENTRES[sh]
        X[:, n + 2 * j:n + 2 * j + 2] += c * dvec / np.linalg.norm(dvec, axis=1)[:, None]
    _, d = con.local(X, sh, details=True)
    e = (X[:, 2:4] - CENTRES[sh]) / np.linalg.norm(X[:, 2:4] - CENTRES[sh], axis=1)[:, None]
    v = np.column_stack([c * e, np.zeros(len(X))])
    nrm = d["normal"]
    expect = v - np.sum(nrm * v, axis=1)[:, None] * nrm
    assert np.allclose(d["spin_rate"], w, rtol=1e-12)
    assert np.abs(d["slip"] - expect).max() < 1e-13


def test_h1_pin_rolling_with_its_sheave_has_zero_slip_and_a_faster_sheave_slips_at_the_pin_end():
    f = FACES["cone"]
    con = SheaveContact(CENTRES, (f, f), np.array([1e10, 1e10]), 0.1, 0.1, 0.02)
    rng = np.random.default_rng(4)
    m = 50
    sh = rng.integers(0, 2, m)
    r, th = rng.uniform(0.035, 0.085, m), rng.uniform(0, 2 * np.pi, m)
    p = CENTRES[sh] + r[:, None] * np.column_stack([np.cos(th), np.sin(th)])
    w = rng.uniform(150, 400, m)
    X = np.column_stack([p, np.full(m, 0.0125), rng.normal(0, 1e-4, m), w[:, None] * _kx(p - CENTRES[sh]),
                         np.zeros(m), np.zeros(m), w])
    _, d = con.local(X, sh, details=True)
    assert np.abs(d["slip"]).max() < 1e-13
    X[:, -1] += 0.7
    _, d = con.local(X, sh, details=True)
    assert np.allclose(np.linalg.norm(d["slip"], axis=1), 0.7 * r, rtol=1e-12)


@pytest.mark.parametrize("face", ["cone", "torus"])
@pytest.mark.parametrize("slopes", [False, True])
def test_h2_pin_rolling_with_its_sheave_has_zero_slip_with_an_inclined_face(face, slopes):
    """The face inclined at the flank angle (session 12) turns with the pin: no slip either, the contact point near
    the axis (cone: on it up to the end slope's shift, ``|x_*| <= |gamma| / m_e``)."""
    con = replace(_h2(face, slopes), face_inclination=FACES[face].gamma)
    X, sh, w = _rolling(con, seed=6)
    _, d = con.local(X, sh, details=True)
    x = np.linalg.norm(d["offset"], axis=1)
    assert x.max() < {("cone", False): 1e-15, ("cone", True): 0.3e-3}.get((face, slopes), 2e-3)
    assert np.allclose(d["spin_rate"], w, rtol=1e-12)
    assert np.abs(d["slip"]).max() < 1e-12 * np.abs(w).max() * 0.1


@pytest.fixture(scope="module")
def a1_models():
    scene = load_scene("band-6+2n")
    F = np.array([30000.0, 35000.0])
    models = {"hertz": from_scene(scene, reference_geometry(), F, model="chain-A1", contact="hertz")}
    # H2 with the flat face (theta = 0) and with the presets' face, inclined at the flank angle
    for c, theta in (("hertz-refined", 0.0), ("inclined", scene.cvt.geometry.flank_angle)):
        models[c] = from_scene(scene, reference_geometry(), F, model="chain-A1", contact="hertz-refined",
                               face_inclination=theta)
    return models


@pytest.mark.parametrize("contact", ["hertz", "hertz-refined", "inclined"])
def test_a1_pins_turning_with_their_sheaves_do_not_slip(a1_models, contact):
    """The whole-pin chain A1 placed on its path, every pin of an arc (position, tilt and slopes, random) turning
    rigidly with its sheave: the contacts of pins whose two neighbours are on the same arc have zero slip, through
    the machine's contact map (end offsets ``u_0 +- u_1``, the end slopes, mirrored ends); a pin with a neighbour
    on the span (entry, exit) slips."""
    model = a1_models[contact]
    fam = model.family
    nc, iphi, iz, _ = model._idx
    pl, u3, z = model.wedge_guess(2.4, 35000.0)
    q, v = np.zeros(model.n2), np.zeros(model.n2)
    q[:nc] = model._placed(pl, u3)
    q[iz] = z
    u = fam.split(q[:nc])[0]
    rng = np.random.default_rng(5)
    u[1:] = rng.normal(0, 2e-5, u[1:].shape)                 # tilt and slope vectors (m)
    speed = 366.5 * pl.r[0]
    model.pin_positions(v[:nc])[:] = speed * pl.tangent
    v[iphi] = speed / pl.r
    for k in (0, 1):
        model._turn_with_sheave(q[:nc], v[:nc], np.nonzero(pl.piece == k)[0], v[iphi[k]], model.contact.centres[k])
    ends, shafts, _, (_, d) = model._contacts(q, v, details=True)
    p = model.pin_of(ends)
    inner = (pl.piece[p] == shafts) & (pl.piece[(p - 1) % fam.n] == shafts) & (pl.piece[fam.ip1[p]] == shafts)
    speed_slip = np.linalg.norm(d["slip"], axis=1)
    assert inner.sum() > 40
    assert speed_slip[inner].max() < 1e-12 * speed
    if contact != "hertz":
        edge = (pl.piece[p] == shafts) & ~inner
        assert speed_slip[edge].max() > 0.05 * (1 if contact == "hertz-refined" else 0.1)   # entry, exit: slower
    if contact == "inclined":   # both mirrored ends, both shafts: the face parallel to the flank near the pin axis
        x = np.linalg.norm(d["offset"], axis=1)[inner & (d["delta"] > 0)]
        x0 = np.linalg.norm(_contacts_details(a1_models["hertz-refined"], q, v)["offset"], axis=1)[inner & (d["delta"] > 0)]
        assert x.max() < 0.25 * x0.min() and x0.min() > 2.5e-3


def _contacts_details(model, q, v):
    """The contact details of ``model`` at ``(q, v)``."""
    return model._contacts(q, v, details=True)[3][1]
