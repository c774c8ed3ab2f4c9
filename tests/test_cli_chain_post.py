"""``cvtfem history`` and ``cvtfem revolution`` on results files with closed-form answers: a run at constant
powers, and the chain-S2 pins marching along their placement one pitch per output row (a steady field)."""
from dataclasses import replace

import numpy as np
import pytest

from cvtfem.analysis.chain_results import pin_positions
from cvtfem.cli import main
from cvtfem.elements.chain.placement import place_on_path
from cvtfem.io.results import ResultsWriter, read_results
from cvtfem.machines.cvt import chain_loop
from cvtfem.outputs import OutputSpec
from cvtfem.post import chain_revolution as cr
from cvtfem.post import spectrogram as sg
from cvtfem.post.history import energy_residual, history, nonfinite_series
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def marching(tmp_path_factory):
    """chain-S2 pins on the path of ratio 0.45, row j with pin p where pin p + j started (n + 1 rows: one
    revolution of every element); link tension and contact force of each link/pin follow it (a steady field)."""
    scene = load_scene("chain-S2")
    model = chain_loop(scene)
    fam = model.family
    n = fam.n
    pl = place_on_path(fam.geom.L, 0.45, model.contact.centres[0, 0])
    tension = 1500 + 700 * np.cos(2 * np.pi * np.arange(n) / n) + 50 * np.arange(n) % 3
    normal = np.zeros((n, 2))
    normal[pl.piece == 0, 0] = 400.0
    normal[pl.piece == 1, 1] = 900.0
    specs = [s for s in model.output_specs if s.name in ("chain.coordinates", "chain.link_tension",
                                                          "contact.normal_force")]
    path = tmp_path_factory.mktemp("march") / "march.h5"
    with ResultsWriter(path, scene.to_toml(), "run", specs) as w:
        for j in range(n + 1):
            roll = (np.arange(n) + j) % n
            q = model._placed(replace(pl, u=pl.u[roll]), np.zeros(n))
            w.append(1e-4 * j, {"chain.coordinates": q, "chain.link_tension": tension[roll],
                                "contact.normal_force": normal[roll].ravel()})
    return path, n


def test_a_followed_link_sees_the_field_the_whole_chain_shows_at_an_instant(marching, tmp_path):
    """The CLI's revolution of link 5 against the API's distribution at t = 0: both are linear interpolations of the
    same samples (the link's positions over time are the links' positions at t = 0), equal to round-off."""
    path, n = marching
    follow = tmp_path / "follow.csv"
    names = ("chain.link_tension", "contact.normal_force")
    assert main(["revolution", str(path), "--follow", "5", "--quantity", names[0], "--quantity", names[1],
                 "--average", "0", "--csv", str(follow), "--png", str(tmp_path / "follow.png")]) == 0
    F = np.genfromtxt(follow, delimiter=",", skip_header=1)
    results = read_results(path)
    u, L = pin_positions(results)
    s_pin, s_link, _ = cr.loop_position(u[0], L)
    for col, name in zip((0, 2), names):
        s, y = F[:, col], F[:, col + 1]
        assert s[-1] - s[0] == pytest.approx(1.0, abs=1e-12)          # one whole revolution
        at = cr.distribution(cr.chain_series(results.series, results.units, name, u, L), s_pin[None], s_link[None],
                             0, pitches=0)
        expected = np.interp(s % 1.0, at.s_raw, at.y_raw[:, 0], period=1.0)
        np.testing.assert_allclose(y, expected, rtol=1e-9, atol=1e-9 * abs(expected).max())
    assert (tmp_path / "follow.png").stat().st_size > 10_000


@pytest.mark.parametrize("preset", ["chain-S2", "chain-A5"])
def test_chain_frequencies_of_a_chain_gliding_along_its_placement(tmp_path, preset):
    """Pins gliding along the polygon of their placement (ratio 0.45), a tenth of a pitch per 10 us row:
    f_link = 10 kHz and f_chain = f_link / n, read from the pins' travel alone (no speed or contact radius is
    stored); to the polygon's corner cutting, which shortens the path per pitch by at most (p / r)^2 / 8.  A5's
    pin is the mean of its two halves, placed rolling on each other."""
    scene = load_scene(preset)
    model = chain_loop(scene)
    n = model.family.n
    pl = place_on_path(model.family.geom.L, 0.45, model.contact.centres[0, 0])
    u0 = np.vstack([pl.u, pl.u[:1]])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(u0, axis=0), axis=1))])
    pitch = arc[-1] / n
    spec = [s for s in model.output_specs if s.name == "chain.coordinates"]
    path = tmp_path / "glide.h5"
    with ResultsWriter(path, scene.to_toml(), "run", spec) as w:
        for j in range(25):
            at = (arc[:-1] + 0.1 * j * pitch) % arc[-1]
            u = np.column_stack([np.interp(at, arc, u0[:, k]) for k in (0, 1)])
            w.append(1e-5 * j, {"chain.coordinates": model._placed(replace(pl, u=u), np.zeros(n))})
    freqs = sg.chain_frequencies(read_results(path), n, arc[-1], 0.1746)
    r_min = np.min([np.linalg.norm(pl.u - c, axis=1).min() for c in model.contact.centres])
    np.testing.assert_allclose(freqs.f_link, 1e4, rtol=(pitch / r_min) ** 2 / 8)
    np.testing.assert_allclose(freqs.f_chain * n, freqs.f_link, rtol=1e-15)


@pytest.mark.parametrize("args, option, allowed", [
    (["--at", "1.0"], "--at", "within the run"),
    (["--follow", "84"], "--follow", "index 0..83"),
    (["--follow", "0", "--start", "-1"], "--start", "within the run"),
    (["--at", "0", "--quantity", "chain.nonsense"], "--quantity", "chain.link_tension"),
    (["--at", "0", "--average", "-1"], "--average", ">= 0"),
])
def test_revolution_bad_input_one_line(marching, args, option, allowed, capsys):
    assert main(["revolution", str(marching[0]), *args]) == 2
    err = capsys.readouterr().err
    assert option in err and allowed in err and "Traceback" not in err


def constant_power_run(path, P_in=100.0, P_out=95.0, dE=2.0):
    """A made-up band run over 1 s: constant input and output power (W), stored energy rising at ``dE`` W."""
    scene = load_scene("band-4dof")
    specs = [OutputSpec("driving.speed", "rad/s", ""), OutputSpec("driven.speed", "rad/s", ""),
             OutputSpec("ratio", "-", ""), OutputSpec("work", "J", "", 4), OutputSpec("energy", "J", ""),
             OutputSpec("driving.clamping_force", "N", ""), OutputSpec("driven.clamping_force", "N", ""),
             OutputSpec("band.slip_speed", "m/s", "", 2)]
    with ResultsWriter(path, scene.to_toml(), "run", specs) as w:
        for t in np.linspace(0.0, 1.0, 201):
            w.append(t, {"driving.speed": 300.0, "driven.speed": 125.0, "ratio": 2.4,
                         "work": [P_in * t, P_out * t, (P_in - P_out - dE) * t, 0.0], "energy": 5.0 + dE * t,
                         "driving.clamping_force": 2e4, "driven.clamping_force": 1.8e4,
                         "band.slip_speed": [0.01, 0.02 + 0.01 * t]})
    return path


def test_history_efficiencies_of_constant_powers(tmp_path):
    """Steady efficiency P_out / P_in; corrected (P_out + dE/dt) / P_in: the stored energy is not a loss."""
    cols = history(read_results(constant_power_run(tmp_path / "run.h5")), window=0.1)
    late = cols["time"] >= 0.1
    np.testing.assert_allclose(cols["efficiency"][late], 0.95, rtol=1e-12)
    np.testing.assert_allclose(cols["efficiency_kinetic"][late], 0.97, rtol=1e-12)
    np.testing.assert_allclose(cols["slip_driven"], 0.02 + 0.01 * cols["time"], rtol=1e-12)
    assert np.isnan(cols["efficiency"][0])                       # no input work yet


def test_energy_residual_and_nonfinite_series(tmp_path):
    """The made-up run closes its balance (input = output + dissipated + dE) to round-off; 1 J of input work
    booked nowhere shows as 1 J over the input work, and a NaN is named by its series."""
    results = read_results(constant_power_run(tmp_path / "run.h5"))
    r = energy_residual(results)
    assert np.isnan(r[0]) and np.abs(r[1:]).max() < 1e-14
    results.series["work"][:, 0] += 1.0
    np.testing.assert_allclose(energy_residual(results), 1.0 / results.series["work"][:, 0], rtol=1e-12)
    assert nonfinite_series(results) == []
    results.series["ratio"][7] = np.nan
    assert nonfinite_series(results) == ["ratio"]


def test_history_cli_writes_png_and_csv(tmp_path, capsys):
    path = constant_power_run(tmp_path / "run.h5")
    assert main(["history", str(path), "--window", "0.2", "--png", str(tmp_path / "h.png"),
                 "--csv", str(tmp_path / "h.csv")]) == 0
    out = capsys.readouterr().out
    assert "efficiency over the last 0.2 s: 0.9500 (kinetic-energy corrected 0.9700)" in out
    assert "energy balance over the run: residual " in out and "non-finite values: none" in out
    table = np.genfromtxt(tmp_path / "h.csv", delimiter=",", names=True)
    assert table["ratio"][-1] == 2.4 and table["n1_rpm"][0] == pytest.approx(300 * 30 / np.pi)
    assert main(["history", str(path), "--window", "0"]) == 2
    assert "--window" in capsys.readouterr().err


def test_revolution_refuses_a_band_run(tmp_path, capsys):
    path = constant_power_run(tmp_path / "run.h5")
    assert main(["revolution", str(path), "--at", "0.5"]) == 2
    assert "must be a run of a discrete chain" in capsys.readouterr().err
