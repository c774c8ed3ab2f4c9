"""Support-force spectrograms of the running chain S2 (stationary regime: 3500 rpm, 200 N m, ratio 2.4), uniform and
randomised chain, 20 us sampling (docs/spectrograms.md).

Run:  .venv/bin/python studies/chain/spectrogram/support_spectrogram.py [--until 0.1] [--out out/studies/spectrogram]
      [--uniform RESULTS.h5] [--random RESULTS.h5] [--window 0.02]

1. Each scene (``chain-S2-uniform.toml``, ``chain-S2-random.toml`` next to this script) runs ``--until`` seconds
   unless its results file is given (a killed run's file is read up to its last flush).
2. From ``--start`` (4 ms: the quasi-static start settles in ~3 ms) the mean bearing reaction of the driving shaft
   is printed against the span balance ``(T_t + T_s - 2 m' v^2) cos(phi)``, ``(T_t - T_s) sin(phi)``.
3. ``cvtfem spectrogram`` writes the spectrogram of the driving shaft's x1 reaction (line of centres) and its
   intensity over f / f_chain (PNG + CSV); the script prints the chain frequencies, the strongest line near
   f_link against ``v / l_link``, the level at f_link / 3 and at f_link against the median level of the band,
   and, from one window over the whole analysed run, how far the levels at k f_chain stand above those half-way
   between (the randomised chain's bands; this needs a window of several chain revolutions).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cvtfem.analysis.run import run_scene
from cvtfem.analysis.timing import machine
from cvtfem.cli import main as cli
from cvtfem.commands.spectrogram import chain_of
from cvtfem.io.results import read_results
from cvtfem.post import spectrogram as sg
from cvtfem.scene.loader import load_scene
from cvtfem.scene.schema.cvt import mean_chain_length

HERE = Path(__file__).resolve().parent


def span_balance(res, start):
    """Mean driving reaction (2,) and the span balance (2,) from ``start`` (s) on, N; with ``v`` (m/s)."""
    late = res.time >= start - 1e-12
    s = {name: res.series[name][late] for name in ("driving.support_force", "chain.span_tension", "contact.radius",
                                                   "driving.speed")}
    radius = s["contact.radius"].reshape(late.sum(), -1, 2)
    r1, r2 = (radius[:, :, k][radius[:, :, k] > 0].mean() for k in (0, 1))
    scene = load_scene_text(res)
    length = mean_chain_length(scene.cvt.chain)
    v = s["driving.speed"].mean() * r1
    phi = np.arcsin((r2 - r1) / scene.cvt.geometry.centre_distance)
    T = s["chain.span_tension"].mean(axis=0)
    expected = np.array([(T.sum() - 2 * scene.cvt.chain.mass / length * v ** 2) * np.cos(phi),
                         (T[0] - T[1]) * np.sin(phi)])
    return s["driving.support_force"].mean(axis=0), expected, T, v


def load_scene_text(res):
    import tomllib

    from cvtfem.scene.loader import scene_from_dict

    return scene_from_dict(tomllib.loads(res.scene_toml), source=str(res.path))


def level_at(spec, f0):
    """Mean-spectrum level (dB) at the bin nearest ``f0`` (Hz) minus the median level of 0..fmax."""
    db = 10 * np.log10(spec.psd.mean(axis=1))
    return float(db[np.argmin(abs(spec.f - f0))] - np.median(db))


def long_window(t, y, f_link, n_pins, fmax=5000.0):
    """One Hann window over all of ``y(t)``: the pin-entry line measured near ``f_link`` (Hz; the largest bin
    within 5 %, refined by a parabola through the log-PSD of it and its neighbours), the chain frequency it
    implies (line / n_pins), and the mean level (dB) at ``k f_chain`` minus the mean level half-way between over
    the orders below ``fmax`` (the randomised chain's bands)."""
    spec = sg.compute_spectrogram(t, y, t[-1] - t[0], overlap=0.0, fmax=fmax)
    m = np.log(spec.psd[:, 0])
    near = np.flatnonzero(abs(spec.f - f_link) < 0.05 * f_link)
    j = near[np.argmax(m[near])]
    line = spec.f[j] + 0.5 * spec.df * (m[j - 1] - m[j + 1]) / (m[j - 1] - 2 * m[j] + m[j + 1])
    fc = line / n_pins
    db = 10 * np.log10(spec.psd[:, 0])
    k = np.arange(1, int(fmax / fc))
    contrast = float(np.mean(np.interp(k * fc, spec.f, db) - np.interp((k + 0.5) * fc, spec.f, db)))
    return line, fc, contrast, spec


def pin_passing(res, start, pitch):
    """Pin-passing rates ``omega_k / (2 asin(pitch / 2 r_k))`` of the two sheaves (chords on the arcs), Hz."""
    late = res.time >= start - 1e-12
    radius = res.series["contact.radius"][late].reshape(late.sum(), -1, 2)
    rates = []
    for k, name in enumerate(("driving.speed", "driven.speed")):
        r = radius[:, :, k][radius[:, :, k] > 0].mean()
        rates.append(res.series[name][late].mean() / (2 * np.arcsin(pitch / (2 * r))))
    return rates


def plot_zoom(spectra, path, band=(1100.0, 1900.0)):
    """Long-window spectra ``{name: (spec, f_chain)}`` in ``band`` (Hz) with ticks at the orders k f_chain of the
    last one."""
    from cvtfem.post.figures import pyplot, save

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.0, 4.0), layout="constrained")
    for (name, (spec, fc)), colour in zip(spectra.items(), ("tab:blue", "tab:red")):
        sel = (spec.f >= band[0]) & (spec.f <= band[1])
        ax.plot(spec.f[sel], 10 * np.log10(spec.psd[sel, 0]), color=colour, lw=0.8,
                label=f"{name} chain ({1e3 * spec.window:.0f} ms window, {spec.df:.1f} Hz bins)")
    fc = list(spectra.values())[-1][1]                  # the randomised chain's, whose bands these are
    for k in range(int(band[0] / fc) + 1, int(band[1] / fc) + 1):
        ax.axvline(k * fc, color="0.75", lw=0.5, zorder=0)
    ax.set_xlim(*band)
    ax.set_xlabel(f"frequency, Hz (grey: k f_chain, f_chain = {fc:.3f} Hz: the randomised chain's pin-entry line / 84)")
    ax.set_ylabel("PSD, dB re 1 N$^2$/Hz")
    ax.set_title("driving shaft support force x1 around f_link, one window over the run", fontsize=10)
    ax.legend(fontsize=8)
    return save(fig, path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--until", type=float, default=0.1)
    ap.add_argument("--start", type=float, default=4e-3)
    ap.add_argument("--window", type=float, default=0.02)
    ap.add_argument("--out", default="out/studies/spectrogram")
    ap.add_argument("--uniform")
    ap.add_argument("--random")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(machine())
    spectra = {}
    for name in ("uniform", "random"):
        path = getattr(args, name)
        if path is None:
            path = out / f"chain-S2-{name}.h5"
            if not path.exists():
                run_scene(load_scene(HERE / f"chain-S2-{name}.toml"), until=args.until, results=path)
        res = read_results(path)
        R, expected, T, v = span_balance(res, args.start)
        freqs = sg.chain_frequencies(res, *chain_of(res))
        late = res.time >= args.start
        pitch = mean_chain_length(load_scene_text(res).cvt.chain) / freqs.n_pins
        print(f"\n{name} chain: {path}, {res.time[-1] * 1e3:.4g} ms ({res.attrs.get('status')}), "
              f"analysed from {args.start * 1e3:.3g} ms")
        print(f"  span tensions {T[0]:.0f} / {T[1]:.0f} N, v = {v:.4f} m/s; mean driving reaction "
              f"({R[0]:.1f}, {R[1]:.1f}) N against the span balance ({expected[0]:.1f}, {expected[1]:.1f}) N: "
              f"{100 * (R[0] / expected[0] - 1):+.2f} %, {100 * (R[1] / expected[1] - 1):+.2f} %")
        print(f"  f_chain = {freqs.f_chain[late].mean():.4f} Hz, f_link = {freqs.f_link[late].mean():.2f} Hz "
              f"(v / l_link = {v / pitch:.2f} Hz)")
        stem = out / f"support-{name}"
        code = cli(["spectrogram", str(path), "--series", "driving.support_force", "--component", "0", "--start",
                    str(args.start), "--window", str(args.window), "--fmax", "5000", "--png", f"{stem}.png",
                    "--csv", f"{stem}.csv", "--intensity-png", f"{stem}-intensity.png", "--intensity-csv",
                    f"{stem}-intensity.csv"])
        assert code == 0
        t, y, _ = sg.select_signal(res, "driving.support_force", "0", args.start)
        spec = sg.compute_spectrogram(t, y, args.window, fmax=5000.0)
        f_link = freqs.f_link[late].mean()
        near = abs(spec.f - f_link) < 0.2 * f_link
        mean = spec.psd.mean(axis=1)
        print(f"  strongest line within 20 % of f_link: {spec.f[near][np.argmax(mean[near])]:.1f} Hz "
              f"(resolution {spec.df:.1f} Hz); above the median level: f_link/3 {level_at(spec, f_link / 3):+.1f} dB, "
              f"f_link {level_at(spec, f_link):+.1f} dB, 2 f_link {level_at(spec, 2 * f_link):+.1f} dB")
        line, fc, contrast, long = long_window(t, y, f_link, freqs.n_pins)
        spectra[name] = (long, fc)
        rates = pin_passing(res, args.start, pitch)
        print(f"  one window of {1e3 * long.window:.1f} ms ({long.window * fc:.2f} chain revolutions, {long.df:.2f} Hz "
              f"bins): pin-entry line at {line:.1f} Hz ({100 * (line / f_link - 1):+.2f} % from v / l_link; pins pass "
              f"the driving sheave at {rates[0]:.1f} Hz, the driven at {rates[1]:.1f} Hz), so f_chain = {fc:.4f} Hz; "
              f"level at k f_chain above half-way between, mean over k f_chain < 5 kHz: {contrast:+.1f} dB")

    print(f"wrote {plot_zoom(spectra, out / 'support-around-f_link.png')}")


if __name__ == "__main__":
    main()
