"""Spectrograms of a run's time series (support forces) and their time-averaged intensity over f / f_chain.

Spec: low-order-models-control-regimes §3.4 (``f_link = v / l_link``, ``f_chain = v / l_chain``,
``v = omega_1 r_1``; a discrete chain's ``v`` is read from its pins' own travel, see
:func:`chain_frequencies`) and §7.2 (the acoustic experiment: spectrograms up to 5 kHz, the average over
``f / f_chain`` column by column).  Windowed FFT by :func:`scipy.signal.spectrogram`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.signal

from cvtfem.errors import InputError
from cvtfem.io.results import Results

#: Largest relative deviation of an output step from the median step that counts as uniform sampling.
STEP_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Spectrogram:
    """One-sided power spectral density of a signal in time windows.

    Attributes
    ----------
    t : (nt,) s
        Window centres.
    f : (nf,) Hz
        Frequencies, ``0 .. fmax``.
    psd : (nf, nt) unit^2/Hz
        Power spectral density (Hann window, mean removed per window): ``sum(psd[:, j]) df`` is the
        mean square of window ``j`` over all frequencies up to Nyquist when ``fmax`` is Nyquist.
    unit : str
        Unit of the signal.
    window : float, s
        Window length (the frequency resolution is ``1 / window``).
    """

    t: np.ndarray
    f: np.ndarray
    psd: np.ndarray
    unit: str
    window: float

    @property
    def df(self) -> float:
        """Frequency step, Hz."""
        return float(self.f[1] - self.f[0])

    def db(self, ref: float = 1.0) -> np.ndarray:
        """``10 log10(psd / ref^2)``, dB re ``ref^2`` per Hz (floored at 1e-30 of the largest value)."""
        floor = 1e-30 * max(float(self.psd.max()), 1e-300)
        return 10.0 * np.log10(np.maximum(self.psd, floor) / ref ** 2)

    def mean_square(self) -> np.ndarray:
        """Per window the integral of the PSD over the frequencies kept, unit^2 (Parseval)."""
        return self.psd.sum(axis=0) * self.df

    def peak_frequencies(self) -> np.ndarray:
        """Per window the frequency of the largest PSD value above 0 Hz, Hz."""
        return self.f[1 + np.argmax(self.psd[1:], axis=0)]


def compute_spectrogram(t, y, window: float, overlap: float = 0.75, fmax: float | None = None,
                        unit: str = "") -> Spectrogram:
    """Windowed FFT of ``y(t)`` (uniform sampling) with a Hann window of ``window`` seconds.

    Parameters
    ----------
    t, y : (n,) s, unit
        Sampled signal; ``t`` uniformly spaced.
    window : float, s
        Window length; at least 8 samples and at most the signal's duration.
    overlap : float
        Overlapping share of consecutive windows, ``0 <= overlap < 1``.
    fmax : float, Hz, optional
        Highest frequency kept, at most the Nyquist frequency ``1 / (2 dt)`` (default: Nyquist).
    """
    t, y = np.asarray(t, float), np.asarray(y, float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 2:
        raise InputError("y", y.shape, f"must be a 1-D signal of the length of `t` ({t.size}), at least 2 samples")
    if not np.isfinite(y).all():
        raise InputError("y", int(np.count_nonzero(~np.isfinite(y))), "must be finite (count of NaN/inf samples)")
    dt = uniform_step(t)
    nyquist = 0.5 / dt
    if not (isinstance(window, (int, float)) and 8 * dt <= window <= t[-1] - t[0] + dt):
        raise InputError("window", window, f"must be between 8 samples ({8 * dt:.4g} s) and the signal's duration "
                         f"({t[-1] - t[0] + dt:.4g} s)", "run longer or choose a shorter window")
    if not 0.0 <= overlap < 1.0:
        raise InputError("overlap", overlap, "must be a share with 0 <= overlap < 1")
    if fmax is None:
        fmax = nyquist
    if not 0.0 < fmax <= nyquist * (1 + 1e-12):
        raise InputError("fmax", fmax, f"must lie in 0 < fmax <= {nyquist:.6g} Hz, the Nyquist frequency of the "
                         f"output step {dt:.4g} s", "sample the run more finely (output.step)")
    nperseg = int(round(window / dt))
    noverlap = min(int(round(overlap * nperseg)), nperseg - 1)
    f, tw, psd = scipy.signal.spectrogram(y, fs=1.0 / dt, window="hann", nperseg=nperseg, noverlap=noverlap,
                                          detrend="constant", scaling="density", mode="psd")
    keep = f <= fmax * (1 + 1e-12)
    return Spectrogram(t[0] + tw, f[keep], psd[keep], unit, nperseg * dt)


def uniform_step(t: np.ndarray) -> float:
    """The sampling step of ``t`` (s); InputError unless every step equals it to :data:`STEP_TOLERANCE`."""
    steps = np.diff(t)
    dt = float(np.median(steps))
    if not dt > 0 or np.abs(steps - dt).max() > STEP_TOLERANCE * dt:
        bad = int(np.argmax(np.abs(steps - dt)))
        raise InputError("t", f"step {steps[bad]:.6g} s at t = {t[bad]:.6g} s",
                         f"must be uniformly sampled (median step {dt:.6g} s)")
    return dt


def select_signal(results: Results, series: str, component: str = "0", start: float = 0.0
                  ) -> tuple[np.ndarray, np.ndarray, str]:
    """``(t, y, label)`` of one component of a stored series from ``start`` (s) on.

    ``component`` is a column index (``"0"``, ``"1"``, ...) or ``"norm"`` (the Euclidean norm of all columns,
    e.g. the magnitude of a force vector).
    """
    if series not in results.series:
        names = ", ".join(sorted(results.series))
        raise InputError("series", series, f"must be a series of the results file {results.path}", f"one of {names}")
    data = results.series[series]
    if component == "norm":
        y = np.linalg.norm(data, axis=1)
    else:
        try:
            j = int(component)
        except ValueError:
            j = -1
        if not 0 <= j < data.shape[1]:
            raise InputError("component", component, f"must be 'norm' or a column index 0..{data.shape[1] - 1} of "
                             f"`{series}`")
        y = data[:, j]
    late = results.time >= start - 1e-12
    if not np.count_nonzero(late) >= 2:
        raise InputError("start", start, f"must leave samples: the run ends at {results.time[-1]:.6g} s")
    return results.time[late], y[late], f"{series}[{component}]"


@dataclass(frozen=True)
class ChainFrequencies:
    """Excitation frequencies of a running chain over time: ``f_chain = v / l_chain``, ``f_link = v / l_link``
    with ``v`` the chain speed (spec §3.4; ``l_link`` the mean pitch ``l_chain / n_pins``).

    Attributes
    ----------
    t : (n,) s
    f_chain : (n,) Hz
    n_pins : int
    """

    t: np.ndarray
    f_chain: np.ndarray
    n_pins: int

    @property
    def f_link(self) -> np.ndarray:
        """Mean pin-entry frequency ``n_pins f_chain``, Hz."""
        return self.n_pins * self.f_chain

    def at(self, t) -> np.ndarray:
        """``f_chain`` at times ``t`` (linear interpolation), Hz."""
        return np.interp(t, self.t, self.f_chain)


def chain_frequencies(results: Results, n_pins: int, chain_length: float, centre_distance: float) -> ChainFrequencies:
    """:class:`ChainFrequencies` of a CVT run of a chain of ``n_pins`` pins and length ``chain_length`` (m) on pulleys
    ``centre_distance`` (m) apart.

    A discrete chain whose run stored ``chain.coordinates`` often enough: ``f_chain`` is the rate at which its pins
    travel round the loop (:func:`loop_rate`), whatever the contact model.  Otherwise ``v = omega_1 r_1`` with
    ``omega_1`` from ``driving.speed`` and ``r_1`` the mean contact radius of the pins on the driving sheaves
    (``contact.radius``) or the band path's radius at ``band.span_angle`` (band models).  The contact radius is the
    pitch radius only where the contact sits on the pin axis (H1): the refined contact H2 touches the sheave below
    the axis, and ``omega_1 r_1`` then under-reads ``f_link`` by about 4 % (variant (b), regime A: 3981 Hz against
    the support force's line at 4170 Hz over 10-30 ms; the loop rate 4133 Hz, and within 0.1 % of the line over
    30-60 ms).
    """
    rate = loop_rate(results) if "chain.coordinates" in results.series else None
    if rate is not None:
        return ChainFrequencies(results.time, rate, int(n_pins))
    if "driving.speed" not in results.series:
        raise InputError("RESULTS", str(results.path), "must hold `driving.speed` for the chain frequencies")
    w1 = results.series["driving.speed"][:, 0]
    if "contact.radius" in results.series:
        r = results.series["contact.radius"].reshape(len(results.time), -1, 2)[:, :, 0]   # pin-major, driving first
        on = r > 0
        r1 = np.where(on, r, 0.0).sum(axis=1) / np.maximum(on.sum(axis=1), 1)
    elif "band.span_angle" in results.series:
        from cvtfem.elements.band.geometry import radii

        phi = results.series["band.span_angle"][:, 0]
        r1 = np.array([radii(p, chain_length, centre_distance)[0][0] for p in phi])
    else:
        raise InputError("RESULTS", str(results.path), "must hold `contact.radius` or `band.span_angle` for the "
                         "contact radius of the driving pulley")
    return ChainFrequencies(results.time, w1 * r1 / chain_length, int(n_pins))


def loop_rate(results: Results) -> np.ndarray | None:
    """Revolutions per second (rows,) of a discrete chain, Hz: its pins' mean speed over the length of the closed
    pin polyline, the speeds by central differences of the pin positions the stored ``chain.coordinates`` map to
    (:func:`cvtfem.analysis.chain_results.pin_positions`).  ``None`` where the output step is too coarse for that:
    a pin moving more than half the mean pitch ``p`` per step (the central difference's chord then spans more
    than a pitch; up to that it under-reads a pin's path on a pulley of radius ``r`` by at most ``(p/r)^2 / 24``,
    0.4 % for the reference chain's 9 mm pitch on 30 mm)."""
    from cvtfem.analysis.chain_results import pin_positions   # rebuilds the chain model: imported when needed

    if len(results.time) < 2:
        return None
    u, _ = pin_positions(results)                                        # (rows, n, 2) m
    links = np.linalg.norm(np.roll(u, -1, axis=1) - u, axis=2)           # (rows, n) m
    step = np.linalg.norm(np.diff(u, axis=0), axis=2)                    # (rows - 1, n) m
    if step.max() > 0.5 * links.mean():
        return None
    speed = np.linalg.norm(np.gradient(u, results.time, axis=0), axis=2).mean(axis=1)
    return speed / links.sum(axis=1)


def excitation_lines(freqs: ChainFrequencies, fmax: float, chain_orders=(1, 2, 3)) -> list[tuple[str, np.ndarray]]:
    """``(label, f(t))`` of the lines ``k f_chain`` for ``chain_orders`` and ``k/3 f_link`` for every ``k``
    whose line starts below ``fmax`` (Hz)."""
    lines = [(f"{k} f_chain", k * freqs.f_chain) for k in chain_orders]
    k_max = int(math.floor(3 * fmax / max(float(freqs.f_link.min()), 1e-300)))
    lines += [(_link_label(k), k / 3 * freqs.f_link) for k in range(1, k_max + 1)]
    return lines


def _link_label(k: int) -> str:
    """``k/3 f_link`` in lowest terms: ``1/3 f_link``, ``2/3 f_link``, ``f_link``, ``4/3 f_link``, ``2 f_link``."""
    if k % 3:
        return f"{k}/3 f_link"
    return "f_link" if k == 3 else f"{k // 3} f_link"


@dataclass(frozen=True)
class OrderIntensity:
    """Time-averaged PSD over the normalised frequency ``f / f_chain`` (spec §7.2, [C] post-processing).

    Attributes
    ----------
    order : (m,) -
        ``f / f_chain`` grid.
    psd : (m,) unit^2/Hz
        Mean over the windows of each window's PSD at ``order f_chain(t_j)`` (windows whose range does
        not reach an order are left out of its mean).
    n_pins : int
    """

    order: np.ndarray
    psd: np.ndarray
    n_pins: int

    def db(self, ref: float = 1.0) -> np.ndarray:
        """``10 log10(psd / ref^2)``, dB."""
        return 10.0 * np.log10(np.maximum(self.psd, 1e-30 * max(float(np.nanmax(self.psd)), 1e-300)) / ref ** 2)


def order_intensity(spec: Spectrogram, freqs: ChainFrequencies) -> OrderIntensity:
    """Average the windows of ``spec`` on a common ``f / f_chain`` grid: rescale each window's frequencies by
    ``f_chain`` at its centre, interpolate linearly onto the grid (step ``df / max f_chain``), average."""
    fc = freqs.at(spec.t)
    if not (fc > 0).all():
        raise InputError("f_chain", float(fc.min()), "must be positive in every window (the chain must run)")
    grid = np.arange(0.0, spec.f[-1] / fc.min(), spec.df / fc.max())
    cols = np.array([np.interp(grid, spec.f / c, spec.psd[:, j], right=np.nan) for j, c in enumerate(fc)])
    counted = np.isfinite(cols).sum(axis=0)
    mean = np.where(counted > 0, np.nansum(cols, axis=0) / np.maximum(counted, 1), np.nan)
    return OrderIntensity(grid, mean, freqs.n_pins)


def write_spectrogram_csv(spec: Spectrogram, path: str | Path) -> None:
    """The spectrogram as CSV in dB: a header ``f_Hz, t=<s>...`` and one row per frequency."""
    header = "f_Hz," + ",".join(f"t={t:.6g}" for t in spec.t)
    np.savetxt(path, np.column_stack([spec.f, spec.db()]), delimiter=",", header=header, comments="",
               fmt="%.6g")


def write_intensity_csv(intensity: OrderIntensity, path: str | Path) -> None:
    """The order intensity as CSV: ``f_over_f_chain, psd, dB``."""
    np.savetxt(path, np.column_stack([intensity.order, intensity.psd, intensity.db()]), delimiter=",",
               header="f_over_f_chain,psd,dB", comments="", fmt="%.6g")


@dataclass(frozen=True)
class OrderSpectrum:
    """One-sided PSD of a signal resampled uniformly in chain revolutions (computed order tracking).

    Attributes
    ----------
    order : (m,) -
        Cycles per chain revolution (``f / f_chain`` at every instant).
    psd : (m,) unit^2 per order
    revolutions : float
        Chain revolutions analysed (the order resolution is ``1 / revolutions``).
    """

    order: np.ndarray
    psd: np.ndarray
    revolutions: float

    def db(self) -> np.ndarray:
        """``10 log10(psd)``, dB re 1 unit^2 per order (floored at 1e-30 of the largest value)."""
        return 10.0 * np.log10(np.maximum(self.psd, 1e-30 * max(float(self.psd.max()), 1e-300)))

    def band_contrast(self, orders) -> np.ndarray:
        """Per order ``k`` of ``orders`` the level (dB) at ``k`` less the mean level at ``k - 1/2`` and
        ``k + 1/2`` (interpolated): how far lines at whole multiples of ``f_chain`` stand out."""
        db = self.db()
        k = np.asarray(orders, float)
        at = np.interp(k, self.order, db)
        between = 0.5 * (np.interp(k - 0.5, self.order, db) + np.interp(k + 0.5, self.order, db))
        return at - between


def order_spectrum(t, y, freqs: ChainFrequencies, samples_per_revolution: int = 1024) -> OrderSpectrum:
    """Resample ``y(t)`` at equal steps of the chain's revolutions ``theta(t) = int f_chain dt`` (trapezoidal rule on
    ``freqs``), then take one Hann-windowed periodogram over all of it: a line at a fixed multiple ``k`` of a
    varying ``f_chain`` stays at order ``k`` (it smears over ``k df`` in a spectrogram)."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    fc = freqs.at(t)
    if not (fc > 0).all():
        raise InputError("f_chain", float(fc.min()), "must be positive over the signal (the chain must run)")
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (fc[1:] + fc[:-1]) * np.diff(t))])
    if not theta[-1] >= 1.0:
        raise InputError("t", float(t[-1] - t[0]), f"must span at least one chain revolution (it spans "
                         f"{theta[-1]:.3g})", "analyse a longer stretch of the run")
    n = int(theta[-1] * samples_per_revolution)
    grid = np.arange(n) / samples_per_revolution
    f, psd = scipy.signal.periodogram(np.interp(grid, theta, y), fs=samples_per_revolution, window="hann",
                                      detrend="constant", scaling="density")
    return OrderSpectrum(f, psd, float(n / samples_per_revolution))
