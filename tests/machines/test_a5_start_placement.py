"""The placement of the A5 chain with the preset's randomised long/short links (issue 13): halves rolling on each
other around rolling points on the band path, the links unstretched or at a given tension, read back through the
element family's own forces (an independent implementation of the same geometry)."""
import numpy as np
import pytest

from cvtfem.elements.chain.halves_placement import half_centres, rolling_link_directions, rolling_spacing
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene

RATIO = 2.4


@pytest.fixture(scope="module")
def model():
    return chain_loop(load_scene("chain-A5"))


@pytest.fixture(scope="module")
def placements(model):
    """Placement of ``tension`` (N) (each computed once)."""
    cache = {}

    def at(tension):
        if tension not in cache:
            cache[tension] = model._placement(RATIO, tension)
        return cache[tension]
    return at


def test_the_preset_chain_has_unequal_links(model):
    """The case this placement is for: long and short links in random order, so joint angles on an arc differ."""
    L = model.family.geom.L
    assert set(np.round(L * 1e4, 6)) == {85.0, 95.0}
    assert np.count_nonzero(np.diff(L)) > 20


@pytest.mark.parametrize("tension", [0.0, 3000.0])
def test_links_carry_the_placement_tension_and_the_faces_touch(model, placements, tension):
    """Every link at the half-axis distance ``L + T / c_link + 2 h_pin`` (to 1e-11 m, the placement's criterion) and
    the model's link tension equals ``T`` to 1e-6 of F2 on all 84 links (arcs, spans and the transitions between
    them); every rolling contact carries ``T`` (the faces pressed by ``T / (l k)``), so at ``T = 0`` they touch
    without pressure.  The former
    placement (link directions taken as the chords of the rolling points) pressed the faces of pins between a long
    and a short link on the arcs by up to 937 N and stretched the links at the arc ends to 7.4 kN."""
    fam = model.family
    q = model._placed(placements(tension), np.full(fam.n, fam.chain.l / 2))   # half lengths unloaded
    u = fam.split(q)[0]
    x = np.roll(u[1, 0], -1, 0) - u[0, 0]
    stretch = tension / fam.geom.c_link
    np.testing.assert_allclose(np.linalg.norm(x, axis=1), fam.geom.L + stretch + 2 * fam.chain.h_pin, rtol=0,
                               atol=1e-11)
    out = fam.outputs(q, None)
    F2 = model.F_appl[1]
    np.testing.assert_allclose(out["chain.link_tension"], tension, rtol=0, atol=1e-6 * F2)
    np.testing.assert_allclose(out["chain.roll_force"], tension, rtol=1e-9, atol=1e-9 * F2)


def test_rolling_points_lie_on_the_path(model, placements):
    """The rolling points are on the arcs of the ratio's radii (to 1e-9 m) on both sheaves."""
    pl = placements(3000.0)
    centres = model.contact.centres
    for k in range(2):
        on = pl.piece == k
        assert on.sum() > 5
        np.testing.assert_allclose(np.linalg.norm(pl.u[on] - centres[k], axis=1), pl.r[k], rtol=0, atol=1e-9)


def test_link_directions_are_the_directions_of_the_half_axes():
    """Closed polygon of unequal links on a circle: the fixed point ``tau`` is the unit direction of the links the
    halves make (``u+_{p+1} - u-_p``), differs from the chords of the rolling points where the joint angles at a
    link's ends differ, and equals them for equal links (a regular polygon)."""
    rng = np.random.default_rng(4)
    R, h = (0.004, 0.004), 0.0012
    angles = np.cumsum(rng.uniform(0.1, 0.2, 40))
    angles *= 2 * np.pi / angles[-1]
    U = 0.05 * np.column_stack([np.cos(angles), np.sin(angles)])
    tau = rolling_link_directions(U, R, h, delta=1e-6)
    u = half_centres(U, tau, R, h, delta=1e-6)
    x = np.roll(u[1], -1, 0) - u[0]
    np.testing.assert_allclose(x / np.linalg.norm(x, axis=1, keepdims=True), tau, rtol=0, atol=1e-14)
    chords = np.roll(U, -1, 0) - U
    chords /= np.linalg.norm(chords, axis=1, keepdims=True)
    assert np.abs(tau - chords).max() > 1e-4
    L = np.linalg.norm(x, axis=1) - 2 * h
    np.testing.assert_allclose(rolling_spacing(tau, L, R, delta=1e-6), np.linalg.norm(np.roll(U, -1, 0) - U, axis=1),
                               rtol=1e-12)
    regular = 0.05 * np.column_stack([np.cos(np.linspace(0, 2 * np.pi, 41)[:-1]),
                                      np.sin(np.linspace(0, 2 * np.pi, 41)[:-1])])
    chords = np.roll(regular, -1, 0) - regular
    np.testing.assert_allclose(rolling_link_directions(regular, R, h), chords / np.linalg.norm(chords, axis=1,
                                                                                               keepdims=True),
                               rtol=0, atol=1e-14)


def test_rolling_faces_pressed_through_their_radius_are_refused_by_key(model):
    """A pin 1e4 times too short presses the rolling faces by ``T / (l k_roll)`` more than their radius at the wedge
    tension: no placement exists (the link directions' fixed point diverges), so building the model (`describe`,
    found by the input fuzz test) names `cvt.chain.pin_length` instead of failing numerically; the same tension on
    the preset's pins is placed."""
    from cvtfem.errors import InputError

    l = load_scene("chain-A5").cvt.chain.pin_length
    short = load_scene("chain-A5", {"cvt": {"chain": {"pin_length": 1e-4 * l}}})
    with pytest.raises(InputError, match=r"cvt\.chain\.pin_length"):
        chain_loop(short)
    assert model._placement(RATIO, 4000.0).delta < np.min(model.family.chain.roll_radius)


def test_a_chain_that_cannot_close_on_the_path_is_refused_by_key():
    """Links 1e4 times too soft stretch by ``T / c_link`` ~ 3 cm at the wedge tension: the stretched chain cannot
    close on the path at the start ratio, so building the model (`describe`, found by the input fuzz test) names
    `cvt.chain` with the placement's reason, as an input error, not a numerical failure."""
    from cvtfem.errors import InputError

    c = load_scene("variant-e").cvt.chain.link_stiffness
    with pytest.raises(InputError, match=r"cvt\.chain.*does not close on the path"):
        chain_loop(load_scene("variant-e", {"cvt": {"chain": {"link_stiffness": 1e-4 * c}}}))
