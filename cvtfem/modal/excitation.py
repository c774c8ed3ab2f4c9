"""Excitation line spectra of a running CVT: pin entry of a (randomised) chain, torque-ripple orders, user lines.

Every source is a set of lines ``w = order x Omega`` (rad/s; shaft orders) or ``w = const`` with a complex force
amplitude: the force is ``Re(a e^{i w t})`` (one-sided amplitude, as in :mod:`cvtfem.modal.forced`).

Pin entry.  A chain of N links with lengths ``l_j`` (chain length ``L = sum l_j``) runs at ``v``; pin j enters the
wrap arc at ``t_j = s_j / v`` with ``s_j = l_0 + ... + l_{j-1}``, once per chain revolution ``T = L / v``.  An
impulse ``J`` (N s) per entry is the periodic force ``J sum_j sum_m delta(t - t_j - m T)`` with the Fourier series
``J f_chain sum_k S_k e^{2 pi i k f_chain t}``, ``f_chain = v / L`` and the pattern's own spectrum

    S_k = sum_j exp(-2 pi i k s_j / L)                     (k = chain order),

so the one-sided line amplitudes are ``2 J f_chain S_k`` at ``k f_chain``.  A uniform chain (``s_j = j L / N``)
has ``S_k = N`` at multiples of N (``k f_chain = f_link``) and 0 elsewhere; a randomised one spreads the same
power (Parseval: ``sum_{k<P} |S_k|^2 = P N`` for pins on a grid of P points per revolution) over sidebands
at every ``k f_chain``.  On a shaft with pitch radius r, ``v = Omega r`` and line k has the shaft order
``2 pi r k / L``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.link_pattern import link_lengths as draw_link_lengths
from cvtfem.errors import InputError


@dataclass(frozen=True)
class Lines:
    """Excitation lines with one force distribution.

    Attributes
    ----------
    label : str
    orders : array (l,)
        Shaft orders (``w = order x Omega``), or 0 for the fixed-frequency lines.
    freqs : array (l,), rad/s
        Fixed frequencies (added to ``order x Omega``): 0 for order lines.
    amplitude : complex array (l,)
        Line amplitudes: per unit shaft speed (rad/s) when ``scale`` is "speed" (pin entry: ``2 J S_k r / L``, the
        entry rate grows with the speed), else as they are (N or N m).
    scale : str
        "speed" or "const".
    force : complex array (n,)
        Generalised force distribution per unit amplitude (N or N m per unit).
    """

    label: str
    orders: np.ndarray
    freqs: np.ndarray
    amplitude: np.ndarray
    scale: str
    force: np.ndarray

    def frequencies(self, speed: float) -> np.ndarray:
        """Line frequencies at shaft speed ``speed`` (rad/s), rad/s."""
        return self.orders * speed + self.freqs

    def amplitudes(self, speed: float) -> np.ndarray:
        """Line amplitudes at shaft speed ``speed`` (rad/s)."""
        return self.amplitude * (speed if self.scale == "speed" else 1.0)


def chain_pattern(n_links: int, pitch_short: float, pitch_long: float, long_fraction: float, seed: int) -> np.ndarray:
    """Link lengths (m) of a chain: ``round(long_fraction n_links)`` long links placed at random by ``seed``
    (:func:`cvtfem.elements.link_pattern.link_lengths`; uniform for ``long_fraction`` 0 or equal pitches)."""
    return draw_link_lengths(n_links, pitch_short, pitch_long, long_fraction, np.random.default_rng(seed))


def pin_positions(link_lengths) -> np.ndarray:
    """Arc positions ``s_j`` of the pins along the chain (m): 0, l_0, l_0 + l_1, ..."""
    lengths = np.asarray(link_lengths, dtype=float)
    if lengths.ndim != 1 or len(lengths) < 1 or not np.all(np.isfinite(lengths)) or np.any(lengths <= 0):
        raise InputError("link_lengths", lengths.tolist()[:5], "must be one or more link lengths > 0 m")
    return np.concatenate([[0.0], np.cumsum(lengths)[:-1]])


def pattern_spectrum(link_lengths, k) -> np.ndarray:
    """``S_k = sum_j exp(-2 pi i k s_j / L)`` of a link pattern at the chain orders ``k`` (complex, (len(k),))."""
    s = pin_positions(link_lengths)
    L = float(np.sum(link_lengths))
    k = np.atleast_1d(np.asarray(k, dtype=float))
    return np.exp(-2j * np.pi * np.outer(k, s) / L).sum(axis=1)


def pin_entry_lines(link_lengths, radius: float, impulse: float, n_link_harmonics: int) -> tuple[np.ndarray, ...]:
    """Pin-entry lines on a shaft whose chain runs at pitch radius ``radius``.

    Parameters
    ----------
    link_lengths : array (N,), m
    radius : float, m
        Pitch radius of the chain on the analysed shaft (chain speed ``v = Omega radius``).
    impulse : float, N s
        Impulse of one pin entry along the force distribution.
    n_link_harmonics : int
        Lines up to ``n_link_harmonics x f_link`` (chain orders ``k = 1 .. n_link_harmonics N``).

    Returns
    -------
    k : int array (K,), chain orders
    shaft_orders : array (K,), ``2 pi radius k / L``
    amplitude : complex array (K,)
        One-sided force amplitude per unit shaft speed (N per rad/s): ``2 J S_k radius / L`` (the line amplitude
        at speed Omega is ``Omega`` times it, since ``f_chain = Omega radius / L``).
    """
    if not (radius > 0 and np.isfinite(radius)):
        raise InputError("radius", radius, "must be a pitch radius > 0 m")
    if not (impulse > 0 and np.isfinite(impulse)):
        raise InputError("impulse", impulse, "must be a finite impulse > 0 N s")
    if int(n_link_harmonics) != n_link_harmonics or n_link_harmonics < 1:
        raise InputError("n_link_harmonics", n_link_harmonics, "must be an integer >= 1")
    L = float(np.sum(link_lengths))
    k = np.arange(1, int(n_link_harmonics) * len(np.atleast_1d(link_lengths)) + 1)
    S = pattern_spectrum(link_lengths, k)
    return k, 2 * np.pi * radius * k / L, 2 * impulse * S * radius / L


def a_weighting_db(freq_hz) -> np.ndarray:
    """A-weighting (dB) of IEC 61672-1 at the frequencies ``freq_hz`` (Hz), 0 dB at 1 kHz.

    ``R_A = 12194^2 f^4 / ((f^2 + 20.6^2) sqrt((f^2 + 107.7^2)(f^2 + 737.9^2)) (f^2 + 12194^2))``,
    ``A = 20 log10(R_A) + 2.00`` dB (the standard's normalisation constant); -inf at 0 Hz.
    """
    f2 = np.asarray(freq_hz, dtype=float) ** 2
    with np.errstate(divide="ignore"):
        ra = 12194.0**2 * f2**2 / ((f2 + 20.6**2) * np.sqrt((f2 + 107.7**2) * (f2 + 737.9**2)) * (f2 + 12194.0**2))
        return 20 * np.log10(ra) + 2.00
