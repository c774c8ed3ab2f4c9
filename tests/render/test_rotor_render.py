"""Renderings: files exist and show something; VTU round-trip; interpolated axis matches nodal DOFs."""
import numpy as np
import pytest

from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem
from cvtfem.render import rotor as r
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def rotor():
    model = build_model(load_scene("friswell_5_9_1"))
    modes = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind).solve(400.0, 4)
    return model, modes


def test_centerline_interpolates_nodal_displacements(rotor):
    model, modes = rotor
    shape = modes.shapes[:, 3]
    pts, elem = r.centerline(model, shape, phase=0.3, scale=2.0)
    d = 2.0 * np.real(shape * np.exp(0.3j))
    first = np.flatnonzero(np.diff(np.concatenate([[-1], elem])))      # first sample of each element = its node
    nodes = model.beam.nodes[:, 0]
    np.testing.assert_allclose(pts[first, 2], d[6 * nodes], atol=1e-14)      # u1 is "up"
    np.testing.assert_allclose(pts[first, 1], d[6 * nodes + 1], atol=1e-14)  # u2
    np.testing.assert_allclose(pts[first, 0], model.z[nodes])


def test_png_renderings(rotor, tmp_path):
    from PIL import Image

    model, modes = rotor
    geo = r.render_rotor(model, tmp_path / "rotor.png", size=(400, 240))
    mode = r.render_mode(model, modes, 1, tmp_path / "mode.png", size=(400, 240))
    a, b = (np.asarray(Image.open(p).convert("L"), dtype=float) for p in (geo, mode))
    assert a.shape == (240, 400) and (a < 250).mean() > 0.02 and (b < 250).mean() > 0.02
    assert np.abs(a - b).mean() > 1.0


def test_gif_and_vtu(rotor, tmp_path):
    import meshio
    from PIL import Image

    model, modes = rotor
    gif = r.write_mode_gif(model, modes, 0, tmp_path / "m.gif", frames=3, size=(240, 160))
    assert Image.open(gif).n_frames == 3
    vtu = r.write_mode_vtu(model, modes, tmp_path / "m.vtu")
    mesh = meshio.read(vtu)
    x = modes.shapes[:, 2].reshape(-1, 6)
    np.testing.assert_allclose(mesh.point_data["mode_2_real"][:, 2], x[:, 0].real)
    np.testing.assert_allclose(mesh.point_data["mode_2_imag"][:, 1], x[:, 1].imag)
