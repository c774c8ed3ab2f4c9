"""Transmissions on elastic shafts and the A5 chain as drawn: each sheave face where its contacts see it (the
model's own map of a pin end into the sheave's frame), the shafts through their beam nodes, every pin half its
own axis, and the per-half and per-half-end colours on the right axes."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.chain.sheave_contact import face_profile
from cvtfem.machines.cvt import chain_loop
from cvtfem.render import transmission as tr
from cvtfem.scene.loader import load_scene

W1 = 3500 * np.pi / 30


def _perturbed(model, seed: int):
    """A state of ``model``: its chain at a placement (A5) or slightly off the origin, every structure coordinate
    displaced at random (translations ~0.1 mm, tilts ~1 mrad, the spin angles ~1 rad)."""
    rng = np.random.default_rng(seed)
    n2, nc, s = model.n2, model._idx[0], model.structure
    if tr.halves(model):
        model, x = model.placed(2.4, W1)
        q = x[:n2].copy()
    else:
        model = replace(model, z_ref=np.array([[1.4977, 1.4977], [1.4885, 1.4885]]))
        q = 1e-3 * rng.standard_normal(n2)
    kind = s.dof_kind
    scale = np.where(kind < 3, 1e-4, np.where(kind < 5, 1e-3, 1.0))
    q[nc:] = scale * rng.standard_normal(s.n)
    return model, q


def _forward(o, a, th, x):
    """The contacts' map of world points ``x`` (m, 3) into the frame of a sheave: ``o + (I - theta x)(x - o - a)``."""
    d = x - o - a
    return o + d - np.cross(th, d)


@pytest.mark.parametrize("name", ["chain-S2,shafts-elastic", "variant-b", "variant-zh", "variant-e"])
def test_sheave_poses_are_the_contacts_own(name):
    """For every pin end (or pin-half end) and both shafts, the drawn end carried into its sheave's frame by the
    drawn pose (:func:`sheave_pose`) is the position the model's mapped contact evaluates (1e-12 m), with random
    shaft deflections, sheave tilts and the symmetric chain's axial motion from the pair's mid-plane."""
    model, q = _perturbed(chain_loop(load_scene(name)), 3)
    nc = model._idx[0]
    y = np.concatenate([q, np.zeros(model.n2)])
    ends = np.arange(model.n_ends)
    e, k, j, cols, coef = model._pairs_map(np.repeat(ends, 2), np.tile([0, 1], ends.size))
    Z = (y[cols] * coef).sum(axis=-1)
    X_model = model.mapped_local(Z, k, j, details=True)[1]["X"]
    side = model._sides[k, j]
    if tr.halves(model):
        axis, far_near = 2 * (e // 4) + (e // 2) % 2, e % 2
    elif tr.whole_pin(model):
        axis, far_near = e // 2, e % 2
    else:                                                 # the symmetric chain's end on the sheave's side
        axis, far_near = e, (side > 0).astype(int)
    assert np.array_equal(np.where(far_near == 1, 1, -1), side)     # each end meets the sheave on its side
    pts = tr.pin_axis_points(model, q[:nc], [-1.0, 1.0])
    x_end = pts[axis, far_near]
    X = np.empty_like(x_end)
    for kk in range(2):
        for jj in range(2):
            at = (k == kk) & (j == jj)
            X[at] = _forward(*tr.sheave_pose(model, q[nc:], kk, jj), x_end[at])
    X[:, 2] *= side
    np.testing.assert_allclose(X, X_model, rtol=0, atol=1e-12)
    assert len(X) == 2 * model.n_ends * (2 if not tr.whole_pin(model) else 1)      # every end, both shafts


@pytest.mark.parametrize("name", ["chain-S2,shafts-elastic", "variant-e"])
def test_drawn_faces_are_the_reference_faces_in_their_sheaves_frames(name):
    """Each drawn face carried into its sheave's frame is ``side x3 = z_ref + s(r)`` there (1e-12 m): the drawing
    inverts the contacts' map exactly; the undeformed structure draws the faces at ``z_ref`` on their sides, and
    each shaft's polyline passes through its fixed sheave's pivot as displaced."""
    model, q = _perturbed(chain_loop(load_scene(name)), 5)
    nc, s = model._idx[0], model.structure
    faces = tr.sheave_faces(model, q[nc:])
    shafts = tr.shaft_lines(model, q[nc:])
    rest = tr.sheave_faces(model, np.zeros(s.n))
    for kk in range(2):
        c = model.contact.centres[kk]
        flat = face_profile(model.contact.faces[kk])
        for jj in range(2):
            side = model._sides[kk, jj]
            j = int(side > 0)
            o, a, th = tr.sheave_pose(model, q[nc:], kk, jj)
            X = _forward(o, a, th, faces[kk, j].reshape(3, -1).T)
            r = np.hypot(X[:, 0] - c[0], X[:, 1] - c[1])
            np.testing.assert_allclose(side * X[:, 2], model.face_ref[kk, jj] - flat(r)[0], rtol=0, atol=1e-12)
            assert np.abs(faces[kk, j] - rest[kk, j]).max() > 1e-5          # the deflection moves it
            assert np.all(side * rest[kk, j][2] > 0)
        node = (s.node_of_sheave[kk, 0] - s.offset[kk]) // 6
        o, a, _ = tr.sheave_pose(model, q[nc:], kk, 0)
        if not model.axial_relative:
            np.testing.assert_allclose(shafts[kk][node], o + a, rtol=0, atol=1e-15)
        np.testing.assert_allclose(shafts[kk][node, :2], (o + a)[:2], rtol=0, atol=1e-15)


@pytest.fixture(scope="module")
def e_model():
    model, x = chain_loop(load_scene("variant-e")).placed(2.4, W1)
    return model, x


def test_pin_halves_are_drawn_on_their_own_axes(e_model):
    """A5: axis ``2 p + h`` is half ``h`` of pin ``p`` (ChainA5.axis_points, 1e-12 m), and link ``p`` is a ribbon
    from half - of pin ``p`` to half + of pin ``p + 1`` across the pack."""
    model, x = e_model
    n, nc = model.family.n, model._idx[0]
    rng = np.random.default_rng(7)
    q = x[:nc] + 1e-5 * rng.standard_normal(nc)
    xi = np.array([-1.0, -0.3, 0.5, 1.0])
    pts = tr.pin_axis_points(model, q, xi)
    assert pts.shape == (2 * n, 4, 3)
    pins, half = np.divmod(np.arange(2 * n), 2)
    for i, t in enumerate(xi):
        ref = model.family.chain.axis_points(q, pins, half, np.full(2 * n, t))
        np.testing.assert_allclose(pts[:, i], ref, rtol=0, atol=1e-12)
    frame = tr.chain_frame(model, *tr.chain_state(model, x))
    np.testing.assert_array_equal(frame.link_ends[:, 0], 2 * np.arange(n))
    np.testing.assert_array_equal(frame.link_ends[:, 1], 2 * np.roll(np.arange(n), -1) + 1)
    pack = tr.pin_axis_points(model, x[:nc], [-tr.PACK_FRACTION, tr.PACK_FRACTION])
    np.testing.assert_allclose(frame.link_corners[:, 0], pack[2 * np.arange(n), 0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(frame.link_corners[:, 2], pack[frame.link_ends[:, 1], 1], rtol=0, atol=1e-15)


def test_colours_per_half_per_pin_and_per_half_end(e_model):
    model, _ = e_model
    n = model.family.n
    kinds = {s.name: tr.colour_kind(model, s) for s in model.output_specs}
    assert kinds["chain.pin_half_axial_force"] == kinds["chain.half_pack_slip"] == "half"
    assert kinds["chain.roll_force"] == "pin" and kinds["chain.link_tension"] == "link"
    assert kinds["contact.normal_force"] == "end" and kinds["chain.plate_tension"] == "plate"
    assert kinds["chain.plate_state"] == "plate" and kinds["contact.friction_force"] is None
    per_half = np.arange(2 * n, dtype=float)                       # half - of every pin, then half +
    v, kind = tr.colour_values(model, "chain.pin_half_axial_force", per_half)
    assert kind == "pin"
    np.testing.assert_array_equal(v[0::2], np.arange(n))          # axis 2 p: half - of pin p
    np.testing.assert_array_equal(v[1::2], n + np.arange(n))      # axis 2 p + 1: half + of pin p
    v, kind = tr.colour_values(model, "chain.roll_force", np.arange(n, dtype=float))
    assert kind == "pin" and np.array_equal(v, np.repeat(np.arange(n), 2))
    per_end_shaft = np.arange(8 * n, dtype=float)                  # value 2 (4 p + 2 h + s) + shaft
    v, kind = tr.colour_values(model, "contact.normal_force", per_end_shaft)
    assert kind == "end" and v.shape == (2 * n, 2)
    axis = np.arange(2 * n)[:, None]
    np.testing.assert_array_equal(v, 2 * (2 * axis + np.arange(2)) * 2 + 1)   # both shafts summed


@pytest.fixture(scope="module")
def s2_elastic_file(tmp_path_factory):
    """4e-5 s of chain-S2 on elastic shafts from its quasi-static start, a row every 2e-5 s."""
    from cvtfem.analysis.run import run_scene

    path = tmp_path_factory.mktemp("run") / "s2e.h5"
    scene = load_scene("chain-S2,shafts-elastic", {"solver": {"t_end": 4e-5}, "output": {"step": 2e-5}})
    run_scene(scene, results=path, show_progress=False)
    return path


def test_stored_run_on_elastic_shafts_draws_the_stored_penetrations(s2_elastic_file, monkeypatch):
    """At the last row the drawn pin ends, carried into the drawn sheaves' frames, lie beyond the faces by the
    penetrations the run stored (their mean over a pair's two sheaves, 1e-9 relative): the file's shaft
    coordinates and face reference place the faces where the contacts were, and no start is solved to draw."""
    from cvtfem.commands.render import open_run
    from cvtfem.machines.chain_cvt_elastic import ElasticChainCVT

    def refuse(self, *args, **kwargs):
        raise AssertionError("the rigid start was solved to draw a results file")

    monkeypatch.setattr(ElasticChainCVT, "_rigid_static_state", refuse)
    run = open_run(s2_elastic_file)
    model, row = run.model, len(run.time) - 1
    q_chain, q_s = run.geometry(row)
    frame = run.frame(row)
    stored = run.results.series["contact.penetration"][row].reshape(-1, 2)          # pin, shaft
    checked = 0
    for kk in range(2):
        c, flat = model.contact.centres[kk], face_profile(model.contact.faces[kk])
        delta = []
        for jj in range(2):
            side = model._sides[kk, jj]
            X = _forward(*tr.sheave_pose(model, q_s, kk, jj), frame.pin_axes[:, 0 if side < 0 else -1])
            r = np.hypot(X[:, 0] - c[0], X[:, 1] - c[1])
            delta.append(side * X[:, 2] - (model.face_ref[kk, jj] - flat(r)[0]))
        delta = np.array(delta)
        on = np.flatnonzero((delta > 0).all(axis=0))
        np.testing.assert_allclose(delta[:, on].mean(axis=0), stored[on, kk], rtol=1e-9, atol=1e-15)
        checked += on.size
    assert checked > 20
    shift = run.results.series["driving.sheave_shift"][row]
    np.testing.assert_array_equal(shift, q_s[model.structure.sheave_dofs[0, :, :2]].ravel())


def test_elastic_png_gif_and_vtu_through_the_cli(cli, s2_elastic_file, tmp_path):
    """The still, the animation and the VTU series of a run on elastic shafts; the VTU faces are the drawn ones."""
    import meshio

    from cvtfem.commands.render import open_run
    from cvtfem.render.vtk_series import read_pvd

    png, gif, vtu = tmp_path / "e.png", tmp_path / "e.gif", tmp_path / "vtu"
    res = cli("render", str(s2_elastic_file), "--png", str(png), "--gif", str(gif), "--vtu", str(vtu), "--scale",
              "50", "--color", "contact.normal_force", timeout=300)
    assert res.returncode == 0, res.stderr
    assert png.stat().st_size > 10_000 and gif.stat().st_size > 10_000
    run = open_run(s2_elastic_file)
    times, files = read_pvd(vtu / "sheaves.pvd")
    np.testing.assert_array_equal(times, run.time)
    frame = run.frame(len(times) - 1, 50.0)
    mesh = meshio.read(files[-1])
    drawn = np.concatenate([frame.faces[k, j].reshape(3, -1).T for k in range(2) for j in range(2)]
                           + list(frame.shafts))
    np.testing.assert_allclose(mesh.points, drawn, rtol=0, atol=1e-12)
    quads, lines = mesh.cells                               # the faces, then the shafts through their beam nodes
    assert quads.type == "quad" and lines.type == "line"
    assert len(lines.data) == sum(len(a) - 1 for a in frame.shafts) and len(frame.shafts[0]) > 2
    np.testing.assert_array_equal(mesh.cell_data["side"][1], 0)


def test_a_run_on_elastic_shafts_without_its_structure_is_refused(tmp_path):
    from cvtfem.commands.render import open_run
    from cvtfem.errors import InputError
    from cvtfem.io.results import ResultsWriter
    from cvtfem.outputs import OutputSpec

    path = tmp_path / "e.h5"
    scene = load_scene("chain-S2,shafts-elastic").to_toml()
    with ResultsWriter(path, scene, "run", [OutputSpec("chain.coordinates", "m", "", 3)]) as w:
        w.append(0.0, {"chain.coordinates": np.zeros(3)})
    with pytest.raises(InputError, match="lacks the series driving.shaft_coordinates, driven.shaft_coordinates"):
        open_run(path)


@pytest.mark.slow
def test_variant_e_results_draw_every_pin_half(cli, tmp_path):
    """Variant (e) through the CLI (run, then still and VTU): the VTU chain holds both halves of every pin as the
    stored coordinates place them, links between the attached halves, the per-half axial force on its half."""
    import meshio

    from cvtfem.commands.render import open_run
    from cvtfem.render.vtk_series import read_pvd

    scene = tmp_path / "e.toml"
    scene.write_text('preset = ["variant-e", "regime-stationary"]\n[solver]\nt_end = 4e-5\n[output]\nstep = 2e-5\n')
    h5, png, vtu = tmp_path / "e.h5", tmp_path / "e.png", tmp_path / "vtu"
    res = cli("run", str(scene), "--results", str(h5), timeout=900)
    assert res.returncode == 0, res.stderr
    res = cli("render", str(h5), "--png", str(png), "--vtu", str(vtu), "--color", "chain.pin_half_axial_force",
              timeout=600)
    assert res.returncode == 0, res.stderr
    assert png.stat().st_size > 10_000
    run = open_run(h5)
    n, m, row = run.model.family.n, tr.PIN_POINTS, len(run.time) - 1
    mesh = meshio.read(read_pvd(vtu / "chain.pvd")[1][-1])
    q = run.results.series["chain.coordinates"][row]
    pins, half = np.divmod(np.arange(2 * n), 2)
    for i, xi in ((0, -1.0), (m - 1, 1.0)):
        ends = run.model.family.chain.axis_points(q, pins, half, np.full(2 * n, xi))
        np.testing.assert_allclose(mesh.points[i:2 * n * m:m], ends, rtol=0, atol=1e-12)
    lines, plates = mesh.cells
    assert len(lines.data) == 2 * n * (m - 1) + n and plates.type == "quad"
    frame = run.frame(row)
    T = run.results.series["chain.plate_tension"][row]
    np.testing.assert_array_equal(mesh.cell_data["chain.plate_tension"][-1], T[frame.plate_slots])
    np.testing.assert_allclose(mesh.points[plates.data], tr.plate_corners(frame), rtol=0, atol=1e-12)
    mid = lines.data[2 * n * (m - 1):] - 2 * n * m                  # links join half - of p and half + of p + 1
    np.testing.assert_array_equal(mid, np.column_stack([2 * np.arange(n), 2 * np.roll(np.arange(n), -1) + 1]))
    F = run.results.series["chain.pin_half_axial_force"][row].reshape(2, n)
    np.testing.assert_allclose(mesh.point_data["chain.pin_half_axial_force"][:2 * n * m].reshape(n, 2, m),
                               np.repeat(F.T[:, :, None], m, axis=2), rtol=1e-15)


def test_a5_plates_sit_at_the_pack_plus_their_offsets(e_model):
    """With straight halves at their rest length (the placement's, straightened) every drawn plate of link ``p``
    runs from the centre of half - of pin ``p`` to that of half + of pin ``p + 1`` in the chain plane, at
    ``x3 = q_pack + d^k`` (1.211) on each (1e-15 m); at the placement the drawn plates' tensions of each link sum
    to its link tension."""
    model, x = e_model
    chain, nc = model.family.chain, model._idx[0]
    q = x[:nc].copy()
    u, w, qp = model.family.split(q)                  # views of q
    u[:, 1:] = 0.0
    w[:, 1] = chain.l / 2
    qp += 1e-4 * np.sin(np.arange(qp.size))
    ends, slot, size = tr.plate_stations(model, q)
    e, k = np.divmod(slot, chain.kmax)
    nxt = (e + 1) % chain.n_pins
    assert size == chain.n_pins * chain.kmax and len(slot) == int((chain.plate_w > 0).sum())
    np.testing.assert_allclose(ends[:, 0, :2], u[0, 0, e], rtol=0, atol=1e-15)
    np.testing.assert_allclose(ends[:, 1, :2], u[1, 0, nxt], rtol=0, atol=1e-15)
    np.testing.assert_allclose(ends[:, 0, 2], qp[e] + chain.plate_d[e, k], rtol=0, atol=1e-15)
    np.testing.assert_allclose(ends[:, 1, 2], qp[nxt] + chain.plate_d[e, k], rtol=0, atol=1e-15)
    _links_sum_their_plates(model, x)


def _links_sum_their_plates(model, x):
    out = model.outputs(0.0, x)
    frame = tr.chain_frame(model, *tr.chain_state(model, x))
    T, kind = tr.colour_values(model, "chain.plate_tension", out["chain.plate_tension"])
    assert kind == "plate"
    chain = model.family.chain
    link = frame.plate_slots // chain.kmax if hasattr(chain, "kmax") else chain.plate_link[frame.plate_slots]
    sums = np.bincount(link, T[frame.plate_slots], model.family.n)
    np.testing.assert_allclose(sums, out["chain.link_tension"], rtol=1e-12, atol=1e-9)
    assert np.abs(out["chain.link_tension"]).max() > 100.0


def test_a4_plates_sum_to_their_links(tmp_path):
    """chain-A4 (one output per plate): the drawn plates of each link sum to its tension; a PNG coloured by the
    plate tension is written."""
    model = chain_loop(load_scene("chain-A4"))
    x, _ = model.start()
    kinds = {s.name: tr.colour_kind(model, s) for s in model.output_specs}
    assert kinds["chain.plate_tension"] == kinds["chain.plate_state"] == "plate"
    assert kinds["chain.plate_reduced_moment"] is None
    _links_sum_their_plates(model, x)
    png = tr.render_transmission(model, x, tmp_path / "a4.png", color_by="chain.plate_tension",
                                 view=tr.View(3.0, (0.0, -0.05)))
    assert png.stat().st_size > 10_000


def test_camera_options_through_the_cli(cli, s2_elastic_file, tmp_path):
    """``--zoom`` and ``--look-at`` aim a close-up (a PNG differing from the full view); bad values and a rotor
    scene are refused by name, before anything is drawn."""
    from PIL import Image

    full, close = tmp_path / "full.png", tmp_path / "close.png"
    assert cli("render", str(s2_elastic_file), "--png", str(full), timeout=300).returncode == 0
    res = cli("render", str(s2_elastic_file), "--png", str(close), "--zoom", "4", "--look-at", "0", "-0.05",
              timeout=300)
    assert res.returncode == 0, res.stderr
    a, b = (np.asarray(Image.open(p).convert("L"), float) for p in (full, close))
    assert a.shape == b.shape and np.abs(a - b).mean() > 5.0
    for args, option in ((("--zoom", "0"), "`--zoom`"), (("--zoom", "nan"), "`--zoom`"),
                         (("--look-at", "0", "inf"), "`--look-at`")):
        bad = cli("render", str(s2_elastic_file), "--png", str(tmp_path / "bad.png"), *args)
        assert bad.returncode == 2 and option in bad.stderr
    bad = cli("render", "friswell_5_9_1", "--png", str(tmp_path / "bad.png"), "--zoom", "2")
    assert bad.returncode == 2 and "`--zoom`" in bad.stderr and "chain transmissions" in bad.stderr
    assert not (tmp_path / "bad.png").exists()


def test_a2_half_end_values_sum_on_the_whole_pin_ends():
    """Variant (v) (A2: coupled halves on A1's whole pins, ends ``4 p + 2 half + near``): a per-end-and-shaft output
    colours pin ``p``'s far end with the sum over both halves' far ends and both shafts."""
    model = chain_loop(load_scene("variant-v"))
    n = model.family.n
    assert model.n_ends == 4 * n and tr.whole_pin(model) and not tr.halves(model)
    per_end_shaft = np.arange(8 * n, dtype=float)                  # value 2 (4 p + 2 h + s) + shaft
    v, kind = tr.colour_values(model, "contact.normal_force", per_end_shaft)
    assert kind == "end" and v.shape == (n, 2)
    p, s = np.arange(n)[:, None], np.arange(2)[None, :]
    expected = sum(2 * (4 * p + 2 * h + s) * 2 + 1 for h in (0, 1))            # both halves, both shafts
    np.testing.assert_array_equal(v, expected)


def test_bearings_are_drawn_where_their_forces_act():
    """On elastic shafts each drawn bearing sits at its beam node as displaced: at rest the drawn displacement
    times the bearings' stiffness is the force the structure's bearings carry (exact), and the node lies on its
    shaft's drawn axis; rigid shafts draw none."""
    model, q = _perturbed(chain_loop(load_scene("variant-e")), 9)
    nc, s = model._idx[0], model.structure
    drawn = tr.bearing_points(model, q[nc:])
    rest = tr.bearing_points(model, np.zeros(s.n))
    force = s.bearing_forces(q[nc:], np.zeros(s.n))                     # (2, 2, 3): K_b u + C_b 0
    np.testing.assert_allclose(force, s.bearing_K * (drawn - rest), rtol=1e-9, atol=1e-9 * np.abs(force).max())
    assert np.abs(force).max() > 1.0
    lines = tr.shaft_lines(model, q[nc:])
    for k in range(2):
        assert all(np.any(np.all(lines[k] == b, axis=1)) for b in drawn[k])
    assert tr.bearing_points(chain_loop(load_scene("chain-A5")), np.zeros(2)) is None
