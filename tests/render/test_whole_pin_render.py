"""The whole-pin chain (A1) as drawn: each pin through its two ends and bent axis, each sheave (fixed or
movable) where the contact model puts it."""
import numpy as np
import pytest

from cvtfem.machines.cvt import chain_loop
from cvtfem.render import transmission as tr
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def a1():
    return chain_loop(load_scene("chain-A1"))


def test_pins_are_drawn_through_their_two_ends_and_end_slopes(a1):
    """The drawn axis runs from the far to the near end of ChainA1.to_raw (1e-12) and leaves them with its end
    slopes (one-sided second-order differences of the drawn axis, 1e-6): a bent pin is drawn bent."""
    chain = a1.family.chain
    n, l = a1.family.n, chain.l
    rng = np.random.default_rng(14)
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    q = chain.rest_state(0.05 * np.column_stack([np.cos(angle), np.sin(angle)]))
    q += 1e-4 * rng.standard_normal(q.size)
    far, near, slope_far, slope_near = chain.to_raw(q)
    h = 1e-4
    pts = tr.pin_axis_points(a1, q, [-1.0, -1 + h, -1 + 2 * h, 1 - 2 * h, 1 - h, 1.0])
    np.testing.assert_allclose(pts[:, 0], far, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pts[:, -1], near, rtol=0, atol=1e-12)
    d_far = (-3 * pts[:, 0, :2] + 4 * pts[:, 1, :2] - pts[:, 2, :2]) / (2 * h) * 2 / l
    d_near = (3 * pts[:, 5, :2] - 4 * pts[:, 4, :2] + pts[:, 3, :2]) / (2 * h) * 2 / l
    np.testing.assert_allclose(d_far, slope_far, rtol=0, atol=1e-6 * np.abs(slope_far).max())
    np.testing.assert_allclose(d_near, slope_near, rtol=0, atol=1e-6 * np.abs(slope_near).max())
    assert np.abs(slope_far - slope_near).max() > 1e-4          # the drawn pins are bent


def test_fixed_and_movable_sheaves(a1):
    z = np.array([1.5e-3, 2.5e-3])
    s = tr.sheave_positions(a1, z)
    for k in range(2):
        movable = (a1.movable_side[k] + 1) // 2                   # side index 0: x3 < 0, 1: x3 > 0
        assert s[k, movable] == z[k] and s[k, 1 - movable] == a1.fixed_z[k]
    assert a1.movable_side == (1, -1)


def test_colour_kinds_of_the_whole_pin_chain(a1):
    kinds = {s.name: tr.colour_kind(a1, s) for s in a1.output_specs}
    assert kinds["chain.twist"] == kinds["chain.shear"] == kinds["chain.link_tension"] == "link"
    assert kinds["chain.pin_axial_force"] == kinds["chain.pin_tilt_twist"] == "pin"
    assert kinds["contact.normal_force"] == "end" and kinds["chain.pin_moment_far"] is None
    n = a1.family.n
    per_end_shaft = np.arange(4 * n, dtype=float)            # value 4 p + 2 end + shaft
    v, kind = tr.colour_values(a1, "contact.normal_force", per_end_shaft)
    assert kind == "end" and v.shape == (n, 2)
    np.testing.assert_array_equal(v[:, 0], 8 * np.arange(n) + 1)     # far end: shafts 0 and 1 summed
    np.testing.assert_array_equal(v[:, 1], 8 * np.arange(n) + 5)     # near end


@pytest.mark.slow
def test_drawn_pin_ends_penetrate_their_sheaves_by_the_model_penetration(a1, tmp_path):
    """In the quasi-static start state every pin end on an arc lies beyond the drawn face on its side (the
    movable or the fixed sheave) by the penetration of the contact model (1e-9), on both sides of both shafts;
    the PNG of the state is written."""
    x, _ = a1.start()
    frame = tr.chain_frame(a1, *tr.chain_state(a1, x))
    delta = a1.outputs(0.0, x)["contact.penetration"].reshape(a1.family.n, 2, 2)   # pin, end (far, near), shaft
    contact, checked = a1.contact, 0
    for k in range(2):
        face = contact.faces[k]
        flat = type(face)(face.profile, face.gamma, face.R, face.y, 0.0)
        for j, side in enumerate((-1.0, 1.0)):
            end = frame.pin_axes[:, 0 if side < 0 else -1]
            r = np.hypot(*(end[:, :2] - contact.centres[k]).T)
            on = np.flatnonzero((r < contact.r_outer) & (delta[:, j, k] > 0))
            np.testing.assert_allclose(side * end[on, 2] - (frame.sheaves[k, j] - flat.z0(r[on])),
                                       delta[on, j, k], rtol=1e-9, atol=1e-15)
            checked += on.size
    assert checked > 40
    png = tr.render_transmission(a1, x, tmp_path / "a1.png", color_by="contact.normal_force")
    assert png.stat().st_size > 10_000
