"""Computed order tracking (cvtfem.post.spectrogram.order_spectrum): lines at fixed multiples of a varying chain
frequency stay at their order, a signal repeating once per revolution has lines at whole orders only."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.post import spectrogram as sg


def _ramp(duration=0.3, fs=50e3, f0=20.0, f1=30.0):
    """Times, f_chain rising linearly f0 -> f1 (Hz) and the chain's revolutions theta(t) in closed form."""
    t = np.arange(int(duration * fs)) / fs
    fc = f0 + (f1 - f0) * t / duration
    theta = f0 * t + 0.5 * (f1 - f0) * t ** 2 / duration
    return t, sg.ChainFrequencies(t, fc, 84), theta


def test_a_line_at_a_fixed_order_stays_at_its_order_while_the_speed_ramps():
    """``sin(2 pi 84 theta(t))`` while f_chain ramps 20 -> 30 Hz (the line sweeps 1680 -> 2520 Hz): the order
    spectrum peaks at 84 to one bin (1 / revolutions) and holds the signal's mean square 1/2 (Parseval) to 2 %,
    with the revolutions analysed equal to the closed-form 7.5."""
    t, freqs, theta = _ramp()
    spec = sg.order_spectrum(t, np.sin(2 * np.pi * 84 * theta), freqs)
    assert spec.revolutions == pytest.approx(theta[-1], abs=2e-3)
    bin_ = 1.0 / spec.revolutions
    assert spec.order[np.argmax(spec.psd)] == pytest.approx(84.0, abs=bin_)
    assert spec.psd.sum() * (spec.order[1] - spec.order[0]) == pytest.approx(0.5, rel=0.02)


def test_a_signal_repeating_every_revolution_has_lines_at_whole_orders():
    """A random pattern repeating once per chain revolution (the randomised chain's support force, idealised)
    stands more than 30 dB above the half-orders at every order 1..40; a random pattern repeating every 1/84 of
    a revolution (the uniform chain) has no such bands below order 84 (the contrast is noise, below 10 dB in
    mean), but its line at 84."""
    t, freqs, theta = _ramp()
    rng = np.random.default_rng(3)
    harmonics = rng.normal(size=(40, 2))
    k = np.arange(1, 41)[:, None]
    periodic = (harmonics[:, :1] * np.cos(2 * np.pi * k * theta) + harmonics[:, 1:] * np.sin(2 * np.pi * k * theta))
    spec = sg.order_spectrum(t, periodic.sum(axis=0), freqs)
    assert spec.band_contrast(np.arange(1, 41)).min() > 30.0
    uniform = np.sin(2 * np.pi * 84 * theta) + 0.05 * rng.normal(size=t.size)
    spec = sg.order_spectrum(t, uniform, freqs)
    assert abs(spec.band_contrast(np.arange(1, 41)).mean()) < 10.0
    assert spec.order[np.argmax(spec.psd)] == pytest.approx(84.0, abs=1.0 / spec.revolutions)


def test_less_than_one_revolution_is_refused():
    t, freqs, _ = _ramp(duration=0.02)
    with pytest.raises(InputError, match="chain revolution"):
        sg.order_spectrum(t, np.sin(t), freqs)
