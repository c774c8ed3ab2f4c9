"""The chain transmission as drawn: the drawn faces and pin ends are the model's contact geometry."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.machines.cvt import chain_loop
from cvtfem.render import transmission as tr
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def running():
    model = chain_loop(load_scene("chain-S2"))
    x0, _ = model.start()
    return model, x0


def test_drawn_pin_ends_penetrate_the_drawn_faces_by_the_model_penetration(running):
    """The drawn face is x3 = z + s(r) of the band models' Sheave (s = -z0 of the face through the axis), and
    each pin end lies beyond it by exactly the penetration the contact model reports."""
    model, x = running
    q, z = tr.chain_state(model, x)
    frame = tr.chain_frame(model, q, z)
    u, u3 = frame.pin_axes[:, -1, :2], frame.pin_axes[:, -1, 2]
    np.testing.assert_array_equal(frame.pin_axes[:, 0, 2], -u3)          # the mirror end
    delta = model.outputs(0.0, x)["contact.penetration"].reshape(-1, 2)
    contact = model.contact
    checked = 0
    for k in range(2):
        c, face = contact.centres[k], contact.faces[k]
        flat = type(face)(face.profile, face.gamma, face.R, face.y, 0.0)   # w = 0: the face through the axis

        def s(r):
            return -flat.z0(r)
        np.testing.assert_array_equal(frame.sheaves[k], z[k])
        pts = frame.faces[k, 0].reshape(3, -1).T                          # the face at x3 < 0
        np.testing.assert_allclose(pts[:, 2], -(z[k] + s(np.hypot(pts[:, 0] - c[0], pts[:, 1] - c[1]))),
                                   rtol=1e-12, atol=1e-15)
        r_pin = np.hypot(*(u - c).T)
        on = np.flatnonzero((r_pin < contact.r_outer) & (delta[:, k] > 0))
        np.testing.assert_allclose(u3[on] - (z[k] + s(r_pin[on])), delta[on, k], rtol=1e-9, atol=1e-15)
        checked += on.size
    assert checked > 20      # both arcs


def test_axial_exaggeration_about_a_reference(running):
    model, x = running
    q, z = tr.chain_state(model, x)
    q2 = q.copy()
    q2[2 * model.family.n:3 * model.family.n] += 1e-5            # every pin end 10 um further out
    frame = tr.chain_frame(model, q2, z + 2e-6, reference=(q, z), axial_scale=50.0)
    plain = tr.chain_frame(model, q, z)
    np.testing.assert_allclose(frame.pin_axes[:, -1, 2] - plain.pin_axes[:, -1, 2], 5e-4, rtol=1e-9)
    np.testing.assert_allclose(frame.pin_axes[:, 0, 2] - plain.pin_axes[:, 0, 2], -5e-4, rtol=1e-9)
    np.testing.assert_allclose(frame.sheaves - plain.sheaves, 1e-4, rtol=1e-9)
    np.testing.assert_array_equal(frame.pin_axes[..., :2], plain.pin_axes[..., :2])   # in-plane: as they are


def test_links_are_ribbons_between_their_pins(running):
    model, x = running
    frame = tr.chain_frame(model, *tr.chain_state(model, x))
    u, u3 = frame.pin_axes[:, -1, :2], frame.pin_axes[:, -1, 2]
    pins, links = tr.chain_meshes(frame)
    n = len(u)
    assert links.n_cells == n and pins.n_cells == n
    corners = np.asarray(links.points).reshape(n, 4, 3)
    np.testing.assert_array_equal(corners[:, 0, :2], u)
    np.testing.assert_array_equal(corners[:, 2, :2], np.roll(u, -1, axis=0))
    np.testing.assert_allclose(corners[:, 1, 2], tr.PACK_FRACTION * u3, rtol=1e-12)
    np.testing.assert_allclose(corners[:, 0, 2], -tr.PACK_FRACTION * u3, rtol=1e-12)


def test_colours_per_link_and_per_pin(running):
    model, x = running
    out = model.outputs(0.0, x)
    v, kind = tr.colour_values(model, "contact.normal_force", out["contact.normal_force"])
    assert kind == "pin" and v.shape == (model.family.n,)
    np.testing.assert_allclose(v.sum(), out["contact.normal_force"].sum())
    assert tr.colour_values(model, "chain.link_tension", out["chain.link_tension"])[1] == "link"
    assert tr.colour_values(model, "chain.pin_axial_force", out["chain.pin_axial_force"])[1] == "pin"
    kinds = {s.name: tr.colour_kind(model, s) for s in model.output_specs}
    assert kinds["chain.joint_rate"] == "pin" and kinds["chain.link_tension_elastic"] == "link"
    assert kinds["contact.normal_force"] == "end" and kinds["contact.friction_force"] is None
    with pytest.raises(InputError, match="--color"):
        tr.check_colour(model, "driving.speed")


def test_png_through_the_cli(cli, tmp_path):
    from PIL import Image

    png = tmp_path / "t.png"
    res = cli("render", "chain-S2", "--png", str(png), "--color", "contact.normal_force", timeout=300)
    assert res.returncode == 0, res.stderr
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert img.shape == (800, 1400, 3)
    coloured = np.abs(img - img.mean(axis=2, keepdims=True)).sum(axis=2) > 60     # not grey/white: the colour map
    assert coloured.mean() > 0.01
    bad = cli("render", "chain-S2", "--png", str(png), "--mode", "1")
    assert bad.returncode == 2 and "`--mode`" in bad.stderr


def test_s3_pins_are_drawn_bent_by_their_parabola():
    """S3: the drawn axis ends at the pin's ends (``u``, ``-+u3``; 1e-15), its mid-point is displaced by
    ``-l/2 u'_p`` and its second derivative over ``xi`` is ``l u'_p`` (1.96b; the central difference over +-0.5, exact
    for a parabola, 1e-12)."""
    model = chain_loop(load_scene("chain-S3-refined"))
    fam = model.family
    n, l = fam.n, fam.geom.l
    rng = np.random.default_rng(3)
    q = 1e-3 * rng.standard_normal(fam.size)
    u, u3, up = fam.split(q)
    h = 0.5
    xi = np.array([-1.0, -h, 0.0, h, 1.0])
    pts = tr.pin_axis_points(model, q, xi)
    np.testing.assert_allclose(pts[:, 0, :2], u, rtol=0, atol=1e-15)
    np.testing.assert_allclose(pts[:, -1, :2], u, rtol=0, atol=1e-15)
    np.testing.assert_allclose(pts[:, [0, -1], 2], np.column_stack([-u3, u3]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(pts[:, 2, :2], u - l / 2 * up, rtol=0, atol=1e-15)
    second = (pts[:, 1, :2] - 2 * pts[:, 2, :2] + pts[:, 3, :2]) / h ** 2
    np.testing.assert_allclose(second, l * up, rtol=0, atol=1e-12 * np.abs(l * up).max())
    assert n == len(pts)
