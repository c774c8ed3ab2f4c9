"""Loop positions, the per-revolution and along-chain views, and the friction parts on fields with closed forms."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.post import chain_revolution as cr

N_PINS, L, R = 84, 0.17, 0.1


def polygon(theta0):
    """Pins of a regular polygon about (L/2, 0), pin p at angle theta0 + 2 pi p / n (counter-clockwise travel), and
    the loop positions expected from the angles: the share of the turn from the point below the centre, where the
    chord through the bottom crosses x1 = L/2 at the parameter lambda = cos(a) / (cos(a) - cos(b))."""
    ang = theta0 + 2 * np.pi * np.arange(N_PINS) / N_PINS
    u = np.column_stack([L / 2 + R * np.cos(ang), R * np.sin(ang)])
    rel = (ang + np.pi / 2) % (2 * np.pi)              # angle past the bottom point
    a = int(np.argmax(rel))                              # last pin before the bottom
    alpha, beta = ang[a], ang[a] + 2 * np.pi / N_PINS
    lam = np.cos(alpha) / (np.cos(alpha) - np.cos(beta))
    s = ((np.arange(N_PINS) - a - lam) / N_PINS) % 1.0
    return u, s


def field(s):
    return 1000.0 + 400.0 * np.cos(2 * np.pi * s) + 150.0 * np.sin(6 * np.pi * s)


@pytest.mark.parametrize("theta0", [0.0, 0.3, -1.234, 2.9])
def test_loop_position_of_a_regular_polygon(theta0):
    u, s_expected = polygon(theta0)
    s_pin, s_link, length = cr.loop_position(u, L)
    assert length == pytest.approx(2 * N_PINS * R * np.sin(np.pi / N_PINS), rel=1e-14)
    assert np.abs(circular(s_pin - s_expected)).max() < 1e-13
    assert np.abs(circular(s_link - s_expected - 0.5 / N_PINS)).max() < 1e-13


def circular(ds):
    """Differences of loop positions folded into [-1/2, 1/2) (0 and 1 are the same point)."""
    return (ds + 0.5) % 1.0 - 0.5


THETA0 = 0.37


def rotating_run(rows: int, turns: float, kind: str):
    """A rigidly rotating polygon carrying the steady field f(s) on its pins (or link midpoints)."""
    theta = THETA0 + 2 * np.pi * turns * np.arange(rows) / (rows - 1)
    us, ss = zip(*(polygon(th) for th in theta))
    u, s = np.array(us), np.array(ss)
    s_el = s if kind == "pin" else (s + 0.5 / N_PINS) % 1.0
    values = field(s_el)[..., None]
    shaft = np.where(u[..., 0] > L / 2, 0, 1)
    series = cr.ChainSeries("chain.test", values, kind, "N", ("",), shaft)
    pos = [cr.loop_position(x, L) for x in u]
    return series, np.array([p[0] for p in pos]), np.array([p[1] for p in pos])


@pytest.mark.parametrize("kind", ["pin", "link"])
def test_both_views_of_a_steady_field_reproduce_it(kind):
    cs, s_pin, s_link = rotating_run(400, 1.05, kind)
    dist = cr.distribution(cs, s_pin, s_link, 123, pitches=0)
    np.testing.assert_allclose(dist.y_raw[:, 0], field(dist.s_raw), rtol=1e-12)
    rev = cr.revolution(cs, s_pin, s_link, 17, slice(None), pitches=0)
    s_first, s_last = polygon(THETA0)[1][17], polygon(THETA0 + 2 * np.pi * 1.05)[1][17]
    if kind == "link":
        s_first, s_last = (s_first + 0.5 / N_PINS) % 1.0, (s_last + 0.5 / N_PINS) % 1.0
    assert rev.s_raw[0] == pytest.approx(s_first, abs=1e-13)
    assert rev.s_raw[-1] == pytest.approx(1.0 + s_last, abs=1e-13)      # a revolution and 5 %
    np.testing.assert_allclose(rev.y_raw[:, 0], field(rev.s_raw % 1.0), rtol=1e-12)
    # resampled by linear interpolation between pins: error below max|f''| h^2 / 8, h = 1 / n
    bound = (400 * (2 * np.pi) ** 2 + 150 * (6 * np.pi) ** 2) / N_PINS ** 2 / 8
    assert np.abs(dist.y[:, 0] - field(dist.s)).max() < bound
    rev_step = np.diff(rev.s_raw).max()
    assert np.abs(rev.y[:, 0] - field(rev.s % 1.0)).max() < bound * (rev_step * N_PINS) ** 2


def test_moving_average_of_a_harmonic_is_its_sinc_damping():
    """A moving average over w of cos(2 pi k s) multiplies it by sin(pi k w) / (pi k w)."""
    cs, s_pin, s_link = rotating_run(50, 0.2, "pin")
    k, w_pitches = 3, 3.0
    cs = cr.ChainSeries(cs.name, 500 * np.cos(2 * np.pi * k * s_pin)[..., None], "pin", "N", ("",), cs.shaft_of)
    d = cr.distribution(cs, s_pin, s_link, 10, pitches=w_pitches, n_grid=N_PINS * 40)
    w = w_pitches / N_PINS
    expected = 500 * np.sinc(k * w) * np.cos(2 * np.pi * k * d.s)
    assert np.abs(d.y[:, 0] - expected).max() < 0.01 * 500


def test_friction_parts_in_the_frame_of_the_touched_shaft():
    """A pin end on the driving pulley (centre (L, 0)) at angle a, a friction force c e_t + r e_r + x e_3: the parts
    are c, r, x; a pin on the driven pulley (centre (0, 0)) likewise in its own frame."""
    n, rows = 4, 1
    a1, a2 = 0.4, 2.5
    u = np.array([[[L + 0.08 * np.cos(a1), 0.08 * np.sin(a1)], [0.04 * np.cos(a2), 0.04 * np.sin(a2)],
                   [0.05, -0.09], [0.05, 0.09]]])
    F = np.zeros((rows, n, 2, 3))
    N = np.zeros((rows, n, 2))
    for p, k, a, (c, r, x) in ((0, 0, a1, (30.0, -4.0, 7.0)), (1, 1, a2, (-12.0, 2.5, -3.0))):
        e_r = np.array([np.cos(a), np.sin(a)])
        e_t = np.array([-np.sin(a), np.cos(a)])
        F[0, p, k, :2] = c * e_t + r * e_r
        F[0, p, k, 2] = x
        N[0, p, k] = 500.0
    series = {"contact.friction_force": F.reshape(rows, -1), "contact.normal_force": N.reshape(rows, -1)}
    got = {name: cr.chain_series(series, {}, name, u, L).values[0, :, 0] for name in cr.FRICTION_PARTS}
    np.testing.assert_allclose(got["contact.friction_circumferential"], [30.0, -12.0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(got["contact.friction_radial"], [-4.0, 2.5, 0, 0], atol=1e-12)
    np.testing.assert_allclose(got["contact.friction_axial"], [7.0, -3.0, 0, 0], atol=1e-12)
    np.testing.assert_array_equal(cr.chain_series(series, {}, "contact.friction_axial", u, L).shaft_of[0], [0, 1, -1, -1])


def test_a_chain_that_does_not_cross_the_tight_span_is_refused():
    u, _ = polygon(0.1)
    with pytest.raises(InputError, match="crosses the centre line"):
        cr.loop_position(u + [0.0, 0.5], L)                 # lifted above x2 = 0: no tight-span crossing


def test_following_an_element_needs_forward_motion_at_every_step():
    cs, s_pin, s_link = rotating_run(5, 2.0, "pin")        # half a turn per output step: direction undefined
    with pytest.raises(InputError, match="moving forward"):
        cr.revolution(cs, s_pin, s_link, 0, slice(None), pitches=0)
    with pytest.raises(InputError, match="index 0..83"):
        cr.revolution(cs, s_pin, s_link, 84, slice(None), pitches=0)
