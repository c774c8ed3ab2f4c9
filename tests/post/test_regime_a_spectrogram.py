"""Regime A (4000 rpm, 150 N m, ratio 0.45) of chain S2 on rigid shafts with a uniform chain: the support-force
spectrogram's pin-entry line sits at f_link (issue 14's plausibility; the study
studies/chain/regime-a/regime_a_spectrogram.py runs it longer, with the randomised chain)."""
from pathlib import Path

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.commands.spectrogram import chain_of
from cvtfem.io.results import read_results
from cvtfem.post import spectrogram as sg
from cvtfem.scene.loader import load_scene

STUDY = Path(__file__).resolve().parents[2] / "studies" / "chain" / "regime-a"


@pytest.mark.slow
def test_uniform_chain_in_regime_a_has_its_line_at_f_link(tmp_path):
    """15 ms of the uniform chain (~80 s at load 15 on 2 cores): from 5 ms on (one 10 ms window, 100 Hz bins) the
    strongest line of the driving shaft's x1 reaction above 500 Hz is f_link = omega_1 r_1 / l_link (within a bin),
    more than 30 dB above the median level of 0.5-5 kHz; averaged over f / f_chain the intensity peaks at
    n_pins = 84 within a bin of 1.2 orders (100 Hz / f_chain)."""
    path = tmp_path / "a.h5"
    run_scene(load_scene(STUDY / "chain-S2-A-uniform.toml"), until=0.015, results=path, show_progress=False)
    res = read_results(path)
    freqs = sg.chain_frequencies(res, *chain_of(res))
    t, y, _ = sg.select_signal(res, "driving.support_force", "0", 0.005)
    spec = sg.compute_spectrogram(t, y, 0.01, fmax=5000.0)
    mean = spec.psd.mean(axis=1)
    band = spec.f > 500
    f_link = float(np.mean(freqs.f_link[res.time >= 0.005]))
    assert spec.f[band][np.argmax(mean[band])] == pytest.approx(f_link, abs=spec.df)
    assert 10 * np.log10(mean[band].max() / np.median(mean[band])) > 30.0
    intensity = sg.order_intensity(spec, freqs)
    high = intensity.order > 10
    assert intensity.order[high][np.nanargmax(intensity.psd[high])] == pytest.approx(
        84.0, abs=spec.df / freqs.f_chain.min())
