"""Pin-entry line spectra of uniform and randomised link patterns; A-weighting (IEC 61672-1)."""
import numpy as np
import pytest

from cvtfem.elements.link_pattern import link_lengths
from cvtfem.errors import InputError
from cvtfem.modal.excitation import a_weighting_db, pattern_spectrum, pin_entry_lines, pin_positions

N, SHORT, LONG = 84, 0.008, 0.010  # 42 long and 42 short links: L = 756 mm, all pins on a 1 mm grid
GRID = 756


def random_chain(seed=3):
    return link_lengths(N, SHORT, LONG, 0.5, np.random.default_rng(seed))


def uniform_chain():
    return np.full(N, (42 * SHORT + 42 * LONG) / N)  # 9 mm: the same chain length and pin count


def test_uniform_chain_has_lines_only_at_multiples_of_f_link():
    """S_k = N at k = N, 2N, 3N (f_link and harmonics) and zero to round-off at every other chain order."""
    k, orders, amp = pin_entry_lines(uniform_chain(), 0.06, 1e-3, 3)
    on = k % N == 0
    assert k[-1] == 3 * N and on.sum() == 3
    S = pattern_spectrum(uniform_chain(), k)
    assert np.allclose(np.abs(S[on]), N, rtol=1e-12)
    assert np.abs(S[~on]).max() < 1e-11 * N
    # shaft orders 2 pi r k / L: f_link is the order 2 pi r / pitch
    assert orders[on][0] == pytest.approx(2 * np.pi * 0.06 / 0.009, rel=1e-12)
    assert np.allclose(amp, 2 * 1e-3 * S * 0.06 / 0.756, rtol=1e-12)


def test_randomised_chain_spreads_the_same_power_over_sidebands():
    """Parseval: with every pin on a grid of P points per revolution, sum_{k<P} |S_k|^2 = P N for any pattern, so a
    randomised chain has the uniform chain's total power; its f_link line is weaker and the sidebands carry the rest."""
    k = np.arange(GRID)
    for lengths in (uniform_chain(), random_chain(3), random_chain(11)):
        assert np.sum(np.abs(pattern_spectrum(lengths, k)) ** 2) == pytest.approx(GRID * N, rel=1e-12)
    Sr, Su = pattern_spectrum(random_chain(), k), pattern_spectrum(uniform_chain(), k)
    assert abs(Sr[N]) < 0.5 * abs(Su[N])
    side = (k % N != 0)
    assert np.sum(np.abs(Sr[side]) ** 2) > 0.5 * GRID * N and np.sum(np.abs(Su[side]) ** 2) < 1e-18 * GRID * N


def test_lines_match_the_fft_of_a_time_sampled_impulse_train():
    """Impulses J at the pin entry times t_j = s_j / v sampled on a grid of P points per revolution (J / dt in one
    sample): the FFT's bins k = 1 .. 3N, doubled (one-sided), equal the line amplitudes at shaft speed v / r."""
    lengths, r, J, v = random_chain(), 0.06, 2e-3, 12.0
    T = lengths.sum() / v
    dt = T / GRID
    x = np.zeros(GRID)
    np.add.at(x, np.rint(pin_positions(lengths) / v / dt).astype(int), J / dt)
    c = np.fft.fft(x) / GRID  # Fourier coefficients of the periodic force
    k, _, amp = pin_entry_lines(lengths, r, J, 3)
    omega = v / r
    assert np.allclose(amp * omega, 2 * c[k], rtol=0, atol=1e-12 * np.abs(c).max())
    assert np.abs(amp * omega).max() > 0.1 * J / T


def test_bad_patterns_and_arguments():
    for bad in ([], [0.01, -0.01], [np.nan]):
        with pytest.raises(InputError, match="link_lengths"):
            pattern_spectrum(bad, [1])
    with pytest.raises(InputError, match="radius"):
        pin_entry_lines(uniform_chain(), 0.0, 1e-3, 1)
    with pytest.raises(InputError, match="n_link_harmonics"):
        pin_entry_lines(uniform_chain(), 0.06, 1e-3, 0)


def test_a_weighting_iec_61672_values():
    """0 dB at 1 kHz; the standard's table (to 0.1 dB, at the exact base-10 frequencies 1000 x 10^(n/10) Hz of the
    nominal bands): -19.1 dB at 100 Hz, -2.5 dB at 10 kHz, -39.4 at 31.5, -1.9 at 630, +1.0 at 4000, -6.6 at
    16000 Hz."""
    assert a_weighting_db(1000.0) == pytest.approx(0.0, abs=1e-3)
    for n, a in ((-10, -19.1), (10, -2.5), (-15, -39.4), (-2, -1.9), (6, 1.0), (12, -6.6)):
        assert a_weighting_db(1000.0 * 10 ** (n / 10)) == pytest.approx(a, abs=0.05), n
    assert a_weighting_db(0.0) == -np.inf
