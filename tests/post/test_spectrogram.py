"""Spectrograms (cvtfem.post.spectrogram): lines and chirps where they belong, PSD scaling by Parseval, the
average over f / f_chain, bad arguments named, and the `cvtfem spectrogram` command on a synthetic run."""
import numpy as np
import pytest
import scipy.signal

from cvtfem.cli import main
from cvtfem.commands.spectrogram import chain_of
from cvtfem.errors import InputError
from cvtfem.io.results import ResultsWriter, read_results
from cvtfem.outputs import OutputSpec
from cvtfem.post import spectrogram as sg
from cvtfem.scene.loader import load_scene


def sampled(duration, fs):
    return np.arange(int(round(duration * fs))) / fs


def test_two_lines_sit_at_their_frequencies_and_parseval_holds():
    """3 sin(2 pi 700 t) + sin(2 pi 2300 t) + 5 at 50 kHz, 20 ms Hann windows (50 Hz resolution): the two
    largest PSD values of every window sit at 700 and 2300 Hz to one bin, and the PSD integrates to the
    mean square of the detrended signal, 3^2/2 + 1^2/2 = 5, to 1e-4 in every window (one-sided density
    scaling)."""
    t = sampled(0.2, 50e3)
    y = 3 * np.sin(2 * np.pi * 700 * t) + np.sin(2 * np.pi * 2300 * t + 0.4) + 5.0
    spec = sg.compute_spectrogram(t, y, 0.02, overlap=0.5, unit="N")
    assert spec.df == pytest.approx(50.0) and spec.f[-1] == pytest.approx(25e3)
    np.testing.assert_allclose(spec.peak_frequencies(), 700.0, atol=spec.df)
    high = spec.f > 1500
    np.testing.assert_allclose(spec.f[high][np.argmax(spec.psd[high], axis=0)], 2300.0, atol=spec.df)
    np.testing.assert_allclose(spec.mean_square(), 5.0, rtol=1e-4)
    assert spec.t[0] == pytest.approx(0.01) and spec.t[1] - spec.t[0] == pytest.approx(0.01)


def test_white_noise_psd_is_flat_at_the_variance_over_nyquist():
    """Gaussian noise of standard deviation 2 sampled at 10 kHz: the mean PSD is sigma^2 / (fs / 2) = 8e-4 N^2/Hz
    across the band (one-sided), and its integral the variance 4 to 2 % (statistical: 2 s of samples)."""
    rng = np.random.default_rng(7)
    t = sampled(2.0, 10e3)
    spec = sg.compute_spectrogram(t, 2.0 * rng.standard_normal(t.size), 0.05, overlap=0.5)
    assert spec.mean_square().mean() == pytest.approx(4.0, rel=0.02)
    inner = (spec.f > 100) & (spec.f < 4900)
    assert spec.psd[inner].mean() == pytest.approx(4.0 / 5e3, rel=0.02)


def test_fmax_keeps_the_band_below_it():
    t = sampled(0.1, 20e3)
    spec = sg.compute_spectrogram(t, np.sin(2 * np.pi * 1000 * t), 0.01, fmax=5000.0)
    assert spec.f[-1] == pytest.approx(5000.0) and spec.psd.shape == (spec.f.size, spec.t.size)


def test_chirp_peak_follows_the_instantaneous_frequency():
    """Linear chirp 500 -> 4500 Hz in 1 s at 20 kHz, 20 ms windows: in every window the peak is at the chirp's
    instantaneous frequency at the window centre to one bin (50 Hz)."""
    t = sampled(1.0, 20e3)
    y = scipy.signal.chirp(t, 500.0, 1.0, 4500.0, method="linear")
    spec = sg.compute_spectrogram(t, y, 0.02, overlap=0.5, fmax=5000.0)
    np.testing.assert_allclose(spec.peak_frequencies(), 500.0 + 4000.0 * spec.t, atol=spec.df)


def test_order_intensity_peaks_at_the_orders_of_a_chain_speeding_up():
    """A chain whose f_chain rises from 10 to 40 Hz excites the lines 84 f_chain (pin entry) and 28 f_chain with
    amplitudes 1 and 0.5: averaged over f / f_chain the intensity peaks at 84 and 28 to one grid step of the
    fastest window, with their power ratio (1 / 0.25, 6 dB) to 1 dB; the spectrogram's own peaks move with
    time (1 kHz band) while the averaged peaks stay put."""
    fs, T = 20e3, 2.0
    t = sampled(T, fs)
    fc = 10.0 + 15.0 * t
    phase = 2 * np.pi * (10.0 * t + 7.5 * t ** 2)          # integral of f_chain
    y = np.sin(84 * phase) + 0.5 * np.sin(28 * phase + 1.0)
    spec = sg.compute_spectrogram(t, y, 0.05, overlap=0.5, fmax=5000.0)
    freqs = sg.ChainFrequencies(t, fc, 84)
    inten = sg.order_intensity(spec, freqs)
    step = spec.df / fc.max()
    assert inten.order[np.nanargmax(inten.psd)] == pytest.approx(84.0, abs=2 * step)
    low = inten.order < 50
    assert inten.order[low][np.nanargmax(inten.psd[low])] == pytest.approx(28.0, abs=2 * step)
    j84, j28 = (np.argmin(abs(inten.order - k)) for k in (84, 28))
    peak = lambda j: inten.psd[max(j - 3, 0):j + 4].max()  # noqa: E731
    assert 10 * np.log10(peak(j84) / peak(j28)) == pytest.approx(6.02, abs=1.0)
    assert spec.peak_frequencies()[-1] - spec.peak_frequencies()[0] > 1000.0


def test_excitation_lines_are_named_in_lowest_terms():
    freqs = sg.ChainFrequencies(np.array([0.0, 1.0]), np.array([10.0, 10.0]), 84)
    lines = dict(sg.excitation_lines(freqs, 2000.0, chain_orders=(1, 2)))
    assert list(lines) == ["1 f_chain", "2 f_chain", "1/3 f_link", "2/3 f_link", "f_link", "4/3 f_link",
                           "5/3 f_link", "2 f_link", "7/3 f_link"]   # 7/3 x 840 = 1960 <= 2000 Hz
    np.testing.assert_allclose(lines["f_link"], 840.0)
    np.testing.assert_allclose(lines["2/3 f_link"], 560.0)


@pytest.mark.parametrize("kwargs, where", [
    ({"window": 0.5}, "window"),                  # longer than the 0.1 s signal
    ({"window": 1e-4}, "window"),                 # under 8 samples
    ({"window": 0.01, "fmax": 6000.0}, "fmax"),   # above the 5 kHz Nyquist frequency
    ({"window": 0.01, "fmax": -1.0}, "fmax"),
    ({"window": 0.01, "overlap": 1.0}, "overlap"),
])
def test_bad_arguments_are_named(kwargs, where):
    t = sampled(0.1, 10e3)
    with pytest.raises(InputError, match=f"`{where}`"):
        sg.compute_spectrogram(t, np.sin(t), **kwargs)


def test_non_uniform_sampling_is_refused():
    t = np.concatenate([sampled(0.01, 1e4), [0.0105]])
    with pytest.raises(InputError, match="uniformly sampled"):
        sg.compute_spectrogram(t, np.ones_like(t), 0.005)


# ----- a synthetic run file: the chain-S2 scene, its chain at 3500 rpm on r1 = 36.7 mm, a force with lines ------
W1, R1, FS = 366.5, 0.0367, 50e3


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """0.1 s of a made-up run of the chain-S2 scene sampled at 20 us: driving speed W1, 10 of 84 pins on the
    driving sheave at R1, and a support force ``[5000 + 300 sin(2 pi f_link t) + 100 sin(2 pi f_link t / 3),
    50 sin(2 pi 3000 t)]`` N."""
    scene = load_scene("chain-S2")
    f_link = W1 * R1 / 0.756 * 84
    specs = [OutputSpec("driving.speed", "rad/s", "w1"), OutputSpec("contact.radius", "m", "r", 168),
             OutputSpec("driving.support_force", "N", "R", 2)]
    radius = np.zeros((84, 2))
    radius[:10, 0] = R1
    path = tmp_path_factory.mktemp("run") / "run.h5"
    with ResultsWriter(path, scene.to_toml(), "run", specs) as w:
        for t in sampled(0.1, FS):
            R = [5000 + 300 * np.sin(2 * np.pi * f_link * t) + 100 * np.sin(2 * np.pi * f_link / 3 * t),
                 50 * np.sin(2 * np.pi * 3000 * t)]
            w.append(t, {"driving.speed": W1, "contact.radius": radius.ravel(), "driving.support_force": R})
    return path, f_link


def test_chain_frequencies_of_a_run_follow_the_spec(run_file):
    """The chain of the stored scene (84 pins, mean pitch 9 mm); f_chain = omega_1 r_1 / l_chain = 17.79 Hz,
    f_link = 84 f_chain."""
    path, f_link = run_file
    res = read_results(path)
    n_pins, length, L = chain_of(res)
    assert (n_pins, length, L) == (84, pytest.approx(0.756), load_scene("chain-S2").cvt.geometry.centre_distance)
    freqs = sg.chain_frequencies(res, n_pins, length, L)
    np.testing.assert_allclose(freqs.f_chain, W1 * R1 / 0.756, rtol=1e-12)
    np.testing.assert_allclose(freqs.f_link, f_link, rtol=1e-12)


def test_command_writes_both_figures_and_tables(capsys, run_file, tmp_path):
    path, f_link = run_file
    out = {k: tmp_path / f"s.{k}" for k in ("png", "csv")}
    ipng, icsv = tmp_path / "i.png", tmp_path / "i.csv"
    assert main(["spectrogram", str(path), "--series", "driving.support_force", "--window", "0.01", "--png",
                 str(out["png"]), "--csv", str(out["csv"]), "--intensity-png", str(ipng), "--intensity-csv",
                 str(icsv)]) == 0
    assert all(p.stat().st_size > 0 for p in (out["png"], out["csv"], ipng, icsv))
    table = np.loadtxt(out["csv"], delimiter=",", skiprows=1)
    f, db = table[:, 0], table[:, 1:]
    assert f[-1] == pytest.approx(5000.0) and db.shape[1] == 37             # 0.1 s, 10 ms windows, 75 % overlap
    mean = db.mean(axis=1)
    assert f[np.argmax(mean[1:]) + 1] == pytest.approx(f_link, abs=100.0)
    inten = np.loadtxt(icsv, delimiter=",", skiprows=1)
    assert inten[np.nanargmax(inten[:, 1]), 0] == pytest.approx(84.0, abs=6.0)   # 100 Hz bins / 17.8 Hz
    assert "strongest lines" in capsys.readouterr().out


@pytest.mark.parametrize("args, where", [
    (["--series", "no.such"], "--series"),
    (["--series", "driving.support_force", "--component", "2"], "--component"),
    (["--series", "driving.support_force", "--fmax", "30000"], "--fmax"),
    (["--series", "driving.support_force", "--window", "1"], "--window"),
    (["--series", "driving.support_force", "--start", "0.2"], "--start"),
    (["--series", "driving.support_force", "--intensity-png", "x.jpg"], "--intensity-png"),
    (["--series", "driving.support_force", "--f-chain", "-1"], "--f-chain"),
])
def test_command_names_the_bad_argument(capsys, run_file, args, where):
    assert main(["spectrogram", str(run_file[0]), *args]) == 2
    err = capsys.readouterr().err
    assert f"`{where}`" in err, err


def test_command_takes_a_given_chain_frequency(capsys, run_file, tmp_path):
    """--f-chain replaces omega_1 r_1 / l_chain: with half the run's chain frequency the f_link line of the signal
    sits at order 168 of the intensity."""
    path, f_link = run_file
    icsv = tmp_path / "i.csv"
    assert main(["spectrogram", str(path), "--series", "driving.support_force", "--window", "0.01", "--f-chain",
                 str(f_link / 168), "--intensity-csv", str(icsv)]) == 0
    inten = np.loadtxt(icsv, delimiter=",", skiprows=1)
    assert inten[np.nanargmax(inten[:, 1]), 0] == pytest.approx(168.0, abs=12.0)    # 100 Hz bins / 8.9 Hz
    assert f"f_chain {f_link / 168:.5g}" in capsys.readouterr().out


def test_line_labels_fit_along_the_edge():
    """More excitation lines than label slots: the whole multiples are labelled, thinned to the slots, in order;
    few lines keep every label."""
    from cvtfem.post.spectrogram_plot import LABEL_GAP, _labelled

    ends = [(sg._link_label(k), k / 3 * 1000.0) for k in range(1, 75)]
    kept = _labelled(ends)
    assert len(kept) <= int(1 / LABEL_GAP) and all("/3" not in name for name, _ in kept)
    assert [f for _, f in kept] == sorted(f for _, f in kept) and kept[0][0] == "f_link"
    assert _labelled(ends[:10]) == ends[:10]
