"""Renderings of a chain-CVT results file: the drawn chain is the stored coordinates through the rebuilt model,
the row choice and the window, clear refusals, the GIF's frames and the VTU time series read back by meshio."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.io.results import ResultsWriter
from cvtfem.outputs import OutputSpec
from cvtfem.render import transmission as tr
from cvtfem.render.run_frames import window_limits, write_animation
from cvtfem.commands.render import open_run
from cvtfem.render.vtk_series import read_pvd, write_vtu_series
from cvtfem.scene.loader import load_scene

STEP = 1e-5


@pytest.fixture(scope="module")
def s2_file(tmp_path_factory):
    """5e-5 s of chain-S2 from its quasi-static start, a row every 1e-5 s (6 rows)."""
    from cvtfem.analysis.run import run_scene

    path = tmp_path_factory.mktemp("run") / "s2.h5"
    scene = load_scene("chain-S2", {"solver": {"t_end": 5 * STEP}, "output": {"step": STEP}})
    run_scene(scene, results=path, show_progress=False)
    return path


@pytest.fixture(scope="module")
def run(s2_file):
    return open_run(s2_file)


def test_drawn_pins_are_the_stored_coordinates_through_the_model(run):
    """At a row after the start, the drawn pin ends are the model's pins of the stored q (in-plane position, both
    ends at -+u3) to 1e-12, the sheaves sit at the stored positions, and every pin end on an arc lies beyond the
    drawn face by the penetration the run stored for that row (1e-9): geometry and stored contact agree."""
    model, row = run.model, 3
    q = run.results.series["chain.coordinates"][row]
    frame = run.frame(row)
    u, u3, _ = model.family.split(q)
    for end, sign in ((0, -1.0), (-1, 1.0)):
        np.testing.assert_allclose(frame.pin_axes[:, end, :2], model.pin_positions(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(frame.pin_axes[:, end, 2], sign * u3, rtol=0, atol=1e-12)
    z = [run.results.series[f"{s}.sheave_position"][row, 0] for s in ("driving", "driven")]
    np.testing.assert_array_equal(frame.sheaves, np.column_stack([z, z]))
    delta = run.results.series["contact.penetration"][row].reshape(-1, 2)
    contact, checked = model.contact, 0
    for k in range(2):
        face = contact.faces[k]
        flat = type(face)(face.profile, face.gamma, face.R, face.y, 0.0)
        r = np.hypot(*(frame.pin_axes[:, -1, :2] - contact.centres[k]).T)
        on = np.flatnonzero((r < contact.r_outer) & (delta[:, k] > 0))
        np.testing.assert_allclose(frame.pin_axes[on, -1, 2] - (z[k] - flat.z0(r[on])), delta[on, k], rtol=1e-9,
                                   atol=1e-15)
        checked += on.size
    assert checked > 20
    assert np.ptp(run.results.series["chain.coordinates"][:, :2 * model.family.n], axis=0).max() > 1e-4   # it runs


def test_nearest_row(run):
    t = run.time
    assert t.size == 6
    np.testing.assert_allclose(t, STEP * np.arange(6), atol=1e-15)
    for query in np.concatenate([np.linspace(t[0], t[-1], 37), t, 0.5 * (t[1:] + t[:-1]) + 1e-12]):
        i = run.row_at(query)
        assert abs(t[i] - query) == np.min(np.abs(t - query))
    assert run.row_at(t[-1]) == t.size - 1


@pytest.mark.parametrize("value", [-1e-6, 1.0, float("nan"), float("inf")])
def test_bad_time_is_refused_with_the_range(run, value):
    with pytest.raises(InputError, match=r"`--time`.*must be a time in \[0, 5e-05\] s"):
        run.row_at(value)


@pytest.mark.parametrize("window", [(2e-5, 1e-5), (-1e-5, 2e-5), (0.0, 1.0), (2e-5, 2e-5), (1.1e-5, 1.9e-5)])
def test_bad_window_is_refused(run, window):
    with pytest.raises(InputError, match="`--window`"):
        run.rows_in(*window)


def test_typed_times_find_their_rows(run):
    """Times typed as 1e-5 s find the rows stored at k * 1e-5 s whatever their last bit."""
    for k in range(6):
        assert run.row_at(k * 1e-5) == k
        assert run.row_at(float(f"{k}e-5")) == k
    np.testing.assert_array_equal(run.rows_in(1e-5, 3e-5), [1, 2, 3])


def test_window_rows_and_frames(run):
    np.testing.assert_array_equal(run.rows_in(1e-5, 4e-5), [1, 2, 3, 4])
    np.testing.assert_array_equal(run.rows_in(0.0, 4e-5, frames=3), [0, 2, 4])
    np.testing.assert_array_equal(run.rows_in(0.0, 5e-5, frames=6), np.arange(6))
    with pytest.raises(InputError, match="`--frames`.*between 2 and the 4 stored rows"):
        run.rows_in(1e-5, 4e-5, frames=5)


def test_colour_limits_span_the_window(run):
    rows = run.rows_in(0.0, 5e-5)
    T = run.results.series["chain.link_tension"]
    assert window_limits(run, rows, "chain.link_tension") == (T.min(), T.max())
    N = run.results.series["contact.normal_force"].reshape(6, -1, 2).sum(axis=2)
    assert window_limits(run, rows, "contact.normal_force") == (N.min(), N.max())
    with pytest.raises(InputError, match="`--color`.*stored in the results file"):
        run.check_colour("ratio")


def _band_file(path):
    with ResultsWriter(path, load_scene("band-4dof").to_toml(), "run", [OutputSpec("ratio", "-", "")]) as w:
        w.append(0.0, {"ratio": 2.0})
    return path


def test_a_results_file_that_is_not_a_chain_cvt_is_refused(tmp_path):
    with pytest.raises(InputError, match=r"`RESULTS`.*must be the results file of a chain-CVT run.*'band-4dof'"):
        open_run(_band_file(tmp_path / "band.h5"))


def test_a_chain_file_without_its_geometry_is_refused(tmp_path):
    path = tmp_path / "c.h5"
    with ResultsWriter(path, load_scene("chain-S2").to_toml(), "run", [OutputSpec("ratio", "-", "")]) as w:
        w.append(0.0, {"ratio": 2.4})
    with pytest.raises(InputError, match="lacks the series chain.coordinates, driving.sheave_position"):
        open_run(path)


def test_gif_has_one_frame_per_row(run, tmp_path):
    from PIL import Image

    path = write_animation(run, run.rows_in(1e-5, 3e-5), tmp_path / "w.gif", "chain.pin_axial_force",
                           axial_scale=100.0, size=(320, 200))
    with Image.open(path) as img:
        assert img.n_frames == 3
        frames = []
        for k in range(3):
            img.seek(k)
            frames.append(np.asarray(img.convert("RGB")).astype(int))
    assert all(np.abs(f - f.mean(axis=2, keepdims=True)).sum(axis=2).max() > 60 for f in frames)   # colour map


def test_mp4_without_imageio_ffmpeg_names_the_package(run, tmp_path):
    import importlib.util

    if importlib.util.find_spec("imageio_ffmpeg") is not None:
        pytest.skip("imageio-ffmpeg is installed")
    with pytest.raises(InputError, match="`--mp4`.*needs the Python package imageio-ffmpeg"):
        write_animation(run, [0, 1], tmp_path / "w.mp4", option="--mp4")


def test_vtu_series_reads_back_with_times_and_values(run, tmp_path):
    import meshio

    rows = run.rows_in(1e-5, 4e-5)
    chain_pvd, sheave_pvd = write_vtu_series(run, rows, tmp_path / "vtu", axial_scale=1.0)
    times, files = read_pvd(chain_pvd)
    np.testing.assert_array_equal(times, run.time[rows])
    assert np.array_equal(read_pvd(sheave_pvd)[0], times)
    n = run.model.family.n
    s = run.results.series
    for row, f in zip(rows, files):
        mesh = meshio.read(f)
        frame = run.frame(row)
        m = tr.PIN_POINTS
        np.testing.assert_allclose(mesh.points[:n * m], frame.pin_axes.reshape(-1, 3), rtol=0, atol=1e-12)
        (lines,) = mesh.cells                       # meshio reads the two line blocks back as one
        n_pin_cells = n * (m - 1)
        assert lines.type == "line" and len(lines.data) == n_pin_cells + n
        mid = mesh.points[lines.data[n_pin_cells:]]                   # links join the pins' mid-points
        np.testing.assert_allclose(mid[:, 0, :2], frame.pin_axes[:, (m - 1) // 2, :2], rtol=0, atol=1e-12)
        np.testing.assert_allclose(mid[:, 1, :2], np.roll(frame.pin_axes[:, (m - 1) // 2, :2], -1, axis=0),
                                   rtol=0, atol=1e-12)
        T = mesh.cell_data["chain.link_tension"][0]
        np.testing.assert_allclose(T[n_pin_cells:], s["chain.link_tension"][row], rtol=1e-15)
        assert np.isnan(T[:n_pin_cells]).all()
        F = s["chain.pin_axial_force"][row]
        np.testing.assert_allclose(mesh.point_data["chain.pin_axial_force"][:n * m], np.repeat(F, m), rtol=1e-15)
        np.testing.assert_allclose(mesh.cell_data["contact.normal_force"][0][:n_pin_cells],
                                   np.repeat(s["contact.normal_force"][row].reshape(-1, 2).sum(axis=1), m - 1))
    sheaves = meshio.read(read_pvd(sheave_pvd)[1][-1])
    z = run.frame(rows[-1]).sheaves
    near = sheaves.cell_data["side"][0] > 0
    assert near.sum() == 0.5 * len(near)
    face, c = run.model.contact.faces[0], run.model.contact.centres[0]
    flat = type(face)(face.profile, face.gamma, face.R, face.y, 0.0)
    pts = sheaves.points[np.unique(sheaves.cells[0].data[(sheaves.cell_data["shaft"][0] == 0) & near])]
    np.testing.assert_allclose(pts[:, 2], z[0, 1] - flat.z0(np.hypot(*(pts[:, :2] - c).T)), rtol=1e-12)
    with pytest.raises(InputError, match="`--vtu`.*must not hold a series already"):
        write_vtu_series(run, rows, tmp_path / "vtu")


def test_bad_options_through_the_cli(cli, s2_file, tmp_path):
    """Refused before any drawing, naming the option, the value and the stored range."""
    png, gif = tmp_path / "t.png", tmp_path / "w.gif"
    bad = cli("render", str(s2_file), "--time", "1", "--png", str(png))
    assert bad.returncode == 2 and "`--time`" in bad.stderr and "1.0" in bad.stderr and "[0, 5e-05] s" in bad.stderr
    bad = cli("render", str(s2_file), "--window", "3e-5", "1e-5", "--gif", str(gif))
    assert bad.returncode == 2 and "`--window`" in bad.stderr and "[0, 5e-05] s" in bad.stderr
    assert not png.exists() and not gif.exists()


@pytest.mark.slow
def test_png_gif_and_vtu_through_the_cli(cli, s2_file, tmp_path):
    """One command writes the still (the row nearest --time, said on stdout), the GIF and the VTU series."""
    from PIL import Image

    png, gif, vtu = tmp_path / "t.png", tmp_path / "w.gif", tmp_path / "vtu"
    res = cli("render", str(s2_file), "--time", "2.6e-5", "--png", str(png), "--color", "contact.normal_force",
              "--scale", "50", "--window", "0", "4e-5", "--frames", "3", "--gif", str(gif), "--vtu", str(vtu),
              timeout=300)
    assert res.returncode == 0, res.stderr
    assert "t = 3e-05 s, row 3 (nearest to --time 2.6e-05 s)" in res.stdout
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert img.shape == (800, 1400, 3)
    assert (np.abs(img - img.mean(axis=2, keepdims=True)).sum(axis=2) > 60).mean() > 0.01
    with Image.open(gif) as g:
        assert g.n_frames == 3
    np.testing.assert_allclose(read_pvd(vtu / "chain.pvd")[0], [0.0, 2e-5, 4e-5], rtol=0, atol=1e-15)
