"""Stationary runs with the loops on: the ratio loop's integral started at zero (the source) or seeded.

Run:  .venv/bin/python studies/chain/seeded_loop.py RESULTS.h5 [RESULTS.h5 ...] [--labels a,b] [--every 0.005]
      [--tail 0.2] [--png out/studies/chain/seeded_loop_a.png]
The results files come from ``cvtfem run`` (e.g. ``cvtfem run studies/chain/variant-a-seeded.toml --until 0.05``
and the same scene with ``ratio_loop_start = "zero"``).  Per file: the ratio's and input speed's deviation from
the targets (2.4, 3500 rpm) at every ``--every`` s and their largest value over the run's second half, the driving
clamping force F1 and the ratio loop's integral F11 (from F1, the estimate's F1a and the stored ratio estimate), the
drift of the ratio over the second half (1/s, linear fit), the run's energy balance (residual of input work +
clamping work = output work + dissipated work + change of stored energy, of the input work) and whether any series
holds a NaN; with ``--fit-from T0`` the loop integral's exponential approach from T0 on (its time constant and end
value: the chain's own clamping ratio at zero ratio error).  The acceptance of issue 14 over the run's last ``--tail`` share (default 20 %): the largest deviation of
the ratio (2 %) and of the input speed (1 %) and their trends (linear fits, %/s), the driven speed's deviation (the
input speed is not held by a loop: w1 = ratio x w2), the efficiency over the tail from the work integrals (steady and
kinetic-energy corrected; plausibility band 95-99.5 %), the tight and slack span tensions against the torque over the
driving contact radius, and the pin axial forces on the sheaves.  ``--png`` draws ratio, input speed, driven speed
(with the acceptance bands) and F1/F2 over time, one line per file.
"""
from __future__ import annotations

import argparse
import math
import os
import tomllib

import numpy as np

from cvtfem.control.clamping import Clamping
from cvtfem.io.results import read_results
from cvtfem.machines.cvt import band_params
from cvtfem.post.history import energy_residual, windowed_efficiency
from cvtfem.scene.loader import scene_from_dict

RPM = 30 / math.pi


def series(path):
    """Time s, ratio, input speed rpm, F1 N, the loop's integral F11 N, the energy balance's residual (of the input
    work), whether a series holds a NaN, the regime's targets (ratio, rpm) and F2 N."""
    r = read_results(path)
    s, t = r.series, r.time
    w1 = np.asarray(s["driving.speed"]).reshape(-1)
    ratio = np.asarray(s["ratio"]).reshape(-1)
    F1 = np.asarray(s["driving.clamping_force"]).reshape(-1)
    scene = scene_from_dict(tomllib.loads(r.scene_toml), source=str(path))
    rg, c = scene.cvt.regime, scene.cvt.control
    F1a = Clamping(band_params(scene), rg.clamping_safety, rg.clamping_split, rg.min_clamping_force).forces(
        rg.torque, rg.ratio)[0]
    # the loop's integral from F1 = F1a + c_f0 (i_estimate - i_d) + F11 (exact while the sum is not saturated)
    F11 = F1 - F1a - c.c_f0 * (np.asarray(s["control.ratio_estimate"]).reshape(-1) - rg.ratio)
    W = np.asarray(s["work"])          # cumulative works (input, output, dissipated, clamping), J
    E = np.asarray(s["energy"]).reshape(-1)
    residual = energy_residual(r)[-1]     # the run's balance, as `cvtfem history` prints it
    nan = any(np.isnan(np.asarray(v, float)).any() for v in s.values() if np.asarray(v).dtype.kind == "f")
    w2 = np.asarray(s["driven.speed"]).reshape(-1)
    d = dict(t=t, ratio=ratio, rpm=w1 * RPM, rpm2=w2 * RPM, F1=F1, F11=F11, residual=float(residual), nan=nan,
             target=(rg.ratio, rg.input_speed * RPM), torque=rg.torque, W=W, E=E, F1a=F1a, gains=(c.c_f0, c.c_f1),
             F2=float(np.asarray(s["driven.clamping_force"]).reshape(-1)[0]))
    for key, name in (("spans", "chain.span_tension"), ("pin_axial", "chain.pin_axial_force"),
                      ("radius", "contact.radius"), ("normal", "contact.normal_force")):
        if name in s:
            d[key] = np.asarray(s[name])
    if "chain.pin_half_axial_force" in s:   # A5: each pin half's, half-major (half -, half +); to pin-major
        f = np.asarray(s["chain.pin_half_axial_force"])
        d["pin_axial"] = f.reshape(len(f), 2, -1).transpose(0, 2, 1).reshape(len(f), -1)
    return d


def integral_fit(d, t0):
    """Fit ``F11 = F11* + A exp(-(t - t0) / T)`` to the loop's integral from ``t0`` on (scipy ``curve_fit``): the
    settling time T (s; the creep-limited loop predicts ``c_f0 / c_f1``), the integral's end value F11* (N) and the
    chain's own clamping ratio ``(F1a + F11*) / F2`` at zero ratio error, and the rms misfit (N)."""
    from scipy.optimize import curve_fit

    sel = d["t"] >= t0
    t, F11 = d["t"][sel], d["F11"][sel]

    def model(tt, Fs, A, T):
        return Fs + A * np.exp(-(tt - t0) / T)

    (Fs, A, T), _ = curve_fit(model, t, F11, p0=(F11[-1], F11[0] - F11[-1], 0.1))
    return dict(T=float(T), F11_end=float(Fs), ratio=float((d["F1a"] + Fs) / d["F2"]),
                rms=float(np.sqrt(np.mean((model(t, Fs, A, T) - F11) ** 2))))


def tail_figures(d, share):
    """Acceptance figures over the run's last ``share`` of its time: deviations (largest, mean, linear trend in %/s)
    of ratio, input and driven speed from their targets; efficiency over the tail (steady, kinetic-energy corrected);
    mean span tensions against ``M1 / r1`` (r1 the mean driving contact radius); pin axial forces on each pulley
    (median and largest magnitude over the pins, or pin halves, touching its sheaves, samples of the tail; the
    contact forces are element-major with the shaft last)."""
    t, (i_d, n_d) = d["t"], d["target"]
    tail = t >= t[-1] * (1 - share)
    out = {"t0": float(t[tail][0]), "t1": float(t[-1])}
    for key, y, ref in (("ratio", d["ratio"], i_d), ("input", d["rpm"], n_d), ("driven", d["rpm2"], n_d / i_d)):
        dev = 100 * (y[tail] / ref - 1)
        out[key] = (float(np.abs(dev).max()), float(dev.mean()), float(np.polyfit(t[tail], dev, 1)[0]))
    out["inside_from"] = {}
    for key, y, ref, tol in (("ratio", d["ratio"], i_d, 0.02), ("input", d["rpm"], n_d, 0.01)):
        out_of_band = np.flatnonzero(np.abs(y / ref - 1) > tol)
        out["inside_from"][key] = float(t[out_of_band[-1] + 1]) if out_of_band.size and out_of_band[-1] + 1 < len(t) \
            else (float(t[0]) if not out_of_band.size else np.inf)
    span = float(t[-1] - out["t0"])
    out["efficiency"] = (float(windowed_efficiency(t, d["W"], span)[-1]),
                         float(windowed_efficiency(t, d["W"], span, d["E"])[-1]))
    if "spans" in d and "radius" in d:
        r = d["radius"][tail].reshape(tail.sum(), -1, 2)[..., 0]
        r1 = float(r[r > 0].mean())
        tight, slack = d["spans"][tail].mean(axis=0)
        out["spans"] = (float(tight), float(slack), r1, d["torque"] / r1)
    if "pin_axial" in d and "normal" in d:
        f = np.abs(d["pin_axial"][tail])
        n_pins = f.shape[1]                                                     # pins, or pin halves
        on = d["normal"][tail].reshape(len(f), n_pins, -1, 2).max(axis=2) > 0    # (rows, pins, shaft): touching
        F = (d["F1"][tail].mean(), d["F2"])
        out["pin_axial"] = [(float(np.median(f[on[..., k]])), float(f[on[..., k]].max()),
                             float(on[..., k].sum(axis=1).mean()), float((f * on[..., k]).sum(axis=1).mean()), F[k])
                            for k in (0, 1)]
    return out


def report(label, d, every, share, fit_from):
    """Print the table of one run."""
    t, (i_d, n_d) = d["t"], d["target"]
    dev_i, dev_n = d["ratio"] / i_d - 1, d["rpm"] / n_d - 1
    half = t >= t[-1] / 2
    rate = np.polyfit(t[half], d["ratio"][half], 1)[0] if half.sum() > 2 else np.nan
    print(f"{label}: {t[-1] * 1e3:.1f} ms, F2 {d['F2']:.0f} N; energy balance residual {d['residual']:.2e} of the "
          f"input work; NaN: {d['nan']}")
    print("   t ms   ratio  dev %    rpm   dev %      F1 N   F1/F2     F11 N")
    for tk in np.arange(0.0, t[-1] + 1e-12, every):
        k = int(np.argmin(np.abs(t - tk)))
        print(f"  {1e3 * t[k]:5.1f}  {d['ratio'][k]:.4f} {100 * dev_i[k]:+5.2f}  {d['rpm'][k]:6.1f} "
              f"{100 * dev_n[k]:+5.2f}"
              f"  {d['F1'][k]:8.0f}  {d['F1'][k] / d['F2']:.4f}  {d['F11'][k]:8.0f}")
    print(f"  second half: largest |ratio dev| {100 * np.abs(dev_i[half]).max():.2f} %, |speed dev| "
          f"{100 * np.abs(dev_n[half]).max():.2f} %; ratio drift {rate:+.3f} 1/s (towards the target if its sign is "
          f"opposite to the mean deviation {100 * dev_i[half].mean():+.2f} %)")
    f = tail_figures(d, share)
    print(f"  last {share:.0%} ({1e3 * f['t0']:.1f}-{1e3 * f['t1']:.1f} ms): largest |dev|, mean dev, trend")
    for key, name, tol in (("ratio", "ratio", 2.0), ("input", "input speed", 1.0), ("driven", "driven speed", None)):
        big, mean, trend = f[key]
        verdict = "" if tol is None else (f"  {'within' if big <= tol else 'OUTSIDE'} {tol:g} % (within it from "
                                          f"{1e3 * f['inside_from'][key]:.1f} ms on)")
        print(f"    {name:13s} {big:5.2f} %  {mean:+5.2f} %  {trend:+7.2f} %/s{verdict}")
    print(f"    efficiency over the tail {100 * f['efficiency'][0]:.2f} % (kinetic-energy corrected "
          f"{100 * f['efficiency'][1]:.2f} %; plausibility band 95-99.5 %)")
    if "spans" in f:
        tight, slack, r1, ref = f["spans"]
        print(f"    spans: tight {tight:.0f} N, slack {slack:.0f} N, difference {tight - slack:.0f} N against "
              f"M1 / r1 = {ref:.0f} N (r1 {1e3 * r1:.2f} mm)")
    if fit_from is not None and d["t"][-1] > fit_from + 0.05:
        g = integral_fit(d, fit_from)
        c_f0, c_f1 = d["gains"]
        print(f"  integral from {1e3 * fit_from:.0f} ms: F11 -> {g['F11_end']:.0f} N with T = {g['T']:.3f} s "
              f"(c_f0 / c_f1 = {c_f0 / c_f1:.3f} s; rms misfit {g['rms']:.1f} N): the chain's clamping ratio at "
              f"zero ratio error F1/F2 = {g['ratio']:.4f}")
    if "pin_axial" in f:
        for name, (med, big, count, total, clamp) in zip(("driving", "driven"), f["pin_axial"]):
            print(f"    pin axial force on the {name} sheaves: median {med:.0f} N, largest {big:.0f} N; "
                  f"{count:.1f} pins (or halves) touching, their sum {total:.0f} N against the clamping force "
                  f"{clamp:.0f} N")


def plot(runs, path):
    """Ratio, input and driven speed (acceptance bands) and F1/F2 over time, one line per run."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(4, 1, figsize=(8, 11), sharex=True)
    for k, (label, d) in enumerate(runs.items()):
        i_d, n_d = d["target"]
        ax[0].plot(1e3 * d["t"], d["ratio"], c=f"C{k}", lw=0.8, label=label)
        ax[1].plot(1e3 * d["t"], d["rpm"], c=f"C{k}", lw=0.8, label=label)
        ax[2].plot(1e3 * d["t"], d["rpm2"], c=f"C{k}", lw=0.8, label=label)
        ax[3].plot(1e3 * d["t"], d["F1"] / d["F2"], c=f"C{k}", lw=0.8, label=label)
    for a, y, tol, what in ((ax[0], i_d, 0.02, "acceptance"), (ax[1], n_d, 0.01, "acceptance"),
                            (ax[2], n_d / i_d, 0.01, "no criterion")):
        a.axhline(y, c="k", lw=0.6)
        a.axhspan(y * (1 - tol), y * (1 + tol), color="0.9", zorder=0, label=f"+-{tol:.0%} ({what})")
    ax[0].set_ylabel("speed ratio w1 / w2")
    ax[1].set_ylabel("input speed, rpm")
    ax[2].set_ylabel("driven speed, rpm")
    ax[3].set_ylabel("clamping force ratio F1 / F2")
    ax[3].set_xlabel("t, ms")
    for a in ax:
        a.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=90)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+")
    ap.add_argument("--labels", default="", help="comma-separated, one per file (default: file names)")
    ap.add_argument("--every", type=float, default=0.005, help="table step, s")
    ap.add_argument("--tail", type=float, default=0.2, help="share of the run the acceptance is judged on")
    ap.add_argument("--fit-from", type=float, default=None,
                    help="fit the loop integral's exponential approach from this time on, s")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    labels = a.labels.split(",") if a.labels else [os.path.basename(p) for p in a.results]
    runs = {lab: series(p) for lab, p in zip(labels, a.results)}
    for lab, d in runs.items():
        report(lab, d, a.every, a.tail, a.fit_from)
    if a.png:
        plot(runs, a.png)
        print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
