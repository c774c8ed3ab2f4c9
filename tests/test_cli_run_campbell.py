"""``cvtfem runcampbell`` and ``cvtfem jacobian`` on a short run of the chain on elastic shafts that records its
states (``output.state = true``)."""
from __future__ import annotations

import csv

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.analysis.run_campbell import block_modes, structure_block
from cvtfem.analysis.stored_state import stored_model, stored_states
from cvtfem.cli import main
from cvtfem.commands.spectrogram import chain_of
from cvtfem.io.results import read_results
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """0.1 ms of chain-S2 on elastic shafts (chapter-2 regime), every 10 us, with the full state."""
    scene = load_scene("chain-S2,regime-chapter2,shafts-elastic").replace({"output": {"step": 1e-5, "state": True}})
    path = tmp_path_factory.mktemp("rc") / "run.h5"
    run_scene(scene, until=1e-4, results=path, show_progress=False)
    return path


@pytest.fixture(scope="module")
def campbell_csv(stored, tmp_path_factory):
    """``cvtfem runcampbell`` of the stored run, 10 modes at every stored time: (PNG, CSV)."""
    folder = tmp_path_factory.mktemp("rc_out")
    png, out = folder / "c.png", folder / "c.csv"
    assert main(["runcampbell", str(stored), "--modes", "10", "--png", str(png), "--csv", str(out)]) == 0
    return png, out


def _read(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def test_runcampbell_tracks_continuously_and_draws_the_run_lines(stored, campbell_csv):
    """From stored state to stored state (10 us apart) each tracked mode below 2.5 kHz keeps a MAC above 0.9 with
    its predecessor and moves by less than half the gap to the nearest other curve (continuous curves); the first
    row's modes are J11's at the first stored state; the lines in the CSV are k f_chain with f_chain the pins'
    mean speed over the loop's length (here from the stored velocities; the command differentiates the stored
    positions: 1e-3), and k/3 f_link with f_link = n_pins f_chain."""
    png, out = campbell_csv
    assert png.stat().st_size > 10_000
    header, rows = _read(out)
    assert len(rows) == 11
    col = {name: i for i, name in enumerate(header)}
    hz = np.array([[float(r[col[f"mode{j}_Hz"]]) for j in range(10)] for r in rows])
    mac = np.array([[float(r[col[f"mode{j}_mac"]]) for j in range(10)] for r in rows])
    low = hz[0] < 2.5e3
    assert low.sum() >= 5
    assert mac[:, low].min() > 0.9
    step = np.abs(np.diff(hz, axis=0))[:, low]
    gap = np.abs(hz[:-1, :, None] - hz[:-1, None, :]) + np.diag(np.full(10, np.inf))
    assert np.all(step < 0.5 * gap.min(axis=2)[:, low])          # no curve steps half-way to a neighbour
    results = read_results(stored)
    model = stored_model(results)
    t, x = stored_states(results, model)
    s = model.structure
    first = block_modes(structure_block(model, t[0], x[0]), s.dof_kind, s.M.diagonal())
    np.testing.assert_allclose(np.sort(hz[0]), np.sort(first.wd[:10] / (2 * np.pi)), rtol=1e-5)
    n_pins, _, _ = chain_of(results)
    f_chain = []                                       # the pins' mean speed over the loop, from the stored states
    for row in x:
        q, v = model.split(row)[:2]
        u, w = model.pin_positions(q[:model.family.size]), model.pin_positions(v[:model.family.size])
        f_chain.append(np.linalg.norm(w, axis=1).mean() / np.linalg.norm(np.roll(u, -1, axis=0) - u, axis=1).sum())
    f_chain = np.array(f_chain)
    got = np.array([[float(row[col[f"{k}_f_chain_Hz"]]) for k in (1, 2, 3)] for row in rows])
    np.testing.assert_allclose(got, np.outer(f_chain, [1, 2, 3]), rtol=1e-3)
    np.testing.assert_allclose([float(row[col["f_link_Hz"]]) for row in rows], n_pins * f_chain, rtol=1e-3)
    np.testing.assert_allclose([float(row[col["1/3_f_link_Hz"]]) for row in rows], n_pins * f_chain / 3, rtol=1e-3)


def test_jacobian_spectrum_of_a_stored_state(stored, tmp_path):
    """The full Jacobian's eigenvalues at the stored row nearest each time: one per state, their sum the trace of
    the Jacobian (an independent check of the eigensolve), the rows the nearest stored ones."""
    png, out = tmp_path / "j.png", tmp_path / "j.csv"
    assert main(["jacobian", str(stored), "--at", "0,0.000052", "--png", str(png), "--csv", str(out)]) == 0
    assert png.stat().st_size > 10_000
    data = np.genfromtxt(out, delimiter=",", skip_header=1)
    results = read_results(stored)
    model = stored_model(results)
    t, x = stored_states(results, model)
    for ti, row in ((0.0, 0), (5e-5, 5)):
        lam = data[np.isclose(data[:, 0], ti, rtol=0.0, atol=1e-12)]
        assert len(lam) == model.size
        trace = model.jac(t[row], x[row]).diagonal().sum()
        assert lam[:, 1].sum() == pytest.approx(trace, rel=1e-8, abs=1e-6 * np.abs(lam[:, 1]).max())
        assert abs(lam[:, 2].sum()) < 1e-6 * np.abs(lam[:, 2]).max()          # conjugate pairs


@pytest.mark.parametrize("argv, where", [
    (["runcampbell", "{r}", "--points", "1"], "--points"),
    (["runcampbell", "{r}", "--start", "1.0"], "--start/--end"),
    (["runcampbell", "{r}", "--chain-orders", "a"], "--chain-orders"),
    (["jacobian", "{r}", "--at", "0.5"], "--at"),
    (["jacobian", "{r}", "--at", "x"], "--at"),
])
def test_bad_options_are_named(stored, argv, where, capsys):
    assert main([a.format(r=stored) for a in argv]) == 2
    assert f"`{where}`" in capsys.readouterr().err


def test_a_run_without_states_is_refused_with_the_fix(tmp_path, capsys):
    scene = load_scene("band-4dof")
    path = tmp_path / "band.h5"
    run_scene(scene, until=2e-3, results=path, show_progress=False)
    assert main(["jacobian", str(path), "--at", "0"]) == 2
    assert "output.state = true" in capsys.readouterr().err


def test_spectrogram_draws_the_tracked_modes_of_the_same_run(stored, campbell_csv, tmp_path, capsys):
    """`cvtfem spectrogram --campbell` reads back the tracked modes of `cvtfem runcampbell --csv` (times and Hz as
    written) and draws them; a file that is not such a CSV is refused by name."""
    from cvtfem.commands.spectrogram import campbell_modes

    table = campbell_csv[1]
    t, f = campbell_modes(str(table))
    header, rows = _read(table)
    assert f.shape == (11, 10)
    np.testing.assert_allclose(t, [float(r[0]) for r in rows])
    np.testing.assert_allclose(f[:, 2], [float(r[header.index("mode2_Hz")]) for r in rows])
    png = tmp_path / "s.png"
    assert main(["spectrogram", str(stored), "--series", "driving.support_force", "--window", "8e-5", "--fmax",
                 "5e4", "--overlap", "0.9", "--campbell", str(table), "--png", str(png)]) == 0
    assert png.stat().st_size > 10_000
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n")
    assert main(["spectrogram", str(stored), "--series", "driving.support_force", "--window", "8e-5", "--fmax", "5e4",
                 "--campbell", str(bad), "--png", str(png)]) == 2
    assert "`--campbell`" in capsys.readouterr().err
