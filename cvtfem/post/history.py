"""Regime history of a CVT run (band or chain): speeds, ratio, efficiency (steady and kinetic-energy corrected),
slip and clamping forces against time, as PNG and CSV (issue 14, deliverable 4).

matplotlib is imported inside the functions (``import cvtfem`` must not load it).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from cvtfem.errors import InputError
from cvtfem.post.figures import pyplot, save

RPM = 30 / math.pi
#: Series a CVT run's history needs.
NEEDED = ("driving.speed", "driven.speed", "ratio", "work", "energy", "driving.clamping_force",
          "driven.clamping_force")


def windowed_efficiency(t, work, window: float = 0.05, energy=None):
    """Moving-window efficiency over ``window`` seconds from cumulative works ``(n, 4)`` (J).

    Without ``energy``: the steady form ``dW_out / dW_in``.  With the model energy ``(n,)`` (J): the kinetic-energy
    corrected form ``1 - (dW_in - dW_out - dE) / dW_in`` of spec section 6.2 (the energy stored in the window is
    not counted as a loss).  NaN where no input work was done in the window.
    """
    t = np.asarray(t)
    work = np.asarray(work)
    j = np.searchsorted(t, t - window)
    d_in = work[:, 0] - work[j, 0]
    d_out = work[:, 1] - work[j, 1]
    if energy is not None:
        E = np.asarray(energy).reshape(-1)
        d_out = d_out + (E - E[j])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(d_in > 0, d_out / np.where(d_in > 0, d_in, 1.0), np.nan)


def mean_slip(series) -> np.ndarray | None:
    """Slip speed per shaft (rows, 2) m/s: a band model's slip at the arc middles, or a chain's mean slip speed of
    the pin ends touching each shaft; None if the run has neither."""
    if "band.slip_speed" in series:
        return np.asarray(series["band.slip_speed"])
    if "contact.slip_speed" not in series:
        return None
    slip = np.asarray(series["contact.slip_speed"]).reshape(len(series["contact.slip_speed"]), -1, 2)
    on = np.asarray(series["contact.normal_force"]).reshape(slip.shape) > 0
    with np.errstate(invalid="ignore"):
        return np.where(on.any(axis=1), (slip * on).sum(axis=1) / on.sum(axis=1), np.nan)


def history(results, window: float) -> dict[str, np.ndarray]:
    """Columns of the regime history: time (s), speeds (rpm), ratio, steady and corrected efficiency over
    ``window`` s, slip per shaft (m/s, if stored) and clamping forces (N)."""
    s, t = results.series, results.time
    missing = [k for k in NEEDED if k not in s]
    if missing:
        raise InputError("RESULTS", str(results.path), "must be a CVT run with the series " + ", ".join(missing))
    if not 0.0 < window:
        raise InputError("--window", window, "must be a positive time, s")
    cols = {"time": t, "n1_rpm": s["driving.speed"][:, 0] * RPM, "n2_rpm": s["driven.speed"][:, 0] * RPM,
            "ratio": s["ratio"][:, 0], "efficiency": windowed_efficiency(t, s["work"], window),
            "efficiency_kinetic": windowed_efficiency(t, s["work"], window, energy=s["energy"])}
    slip = mean_slip(s)
    if slip is not None:
        cols.update(slip_driving=slip[:, 0], slip_driven=slip[:, 1])
    cols.update(F1=s["driving.clamping_force"][:, 0], F2=s["driven.clamping_force"][:, 0])
    return cols


def energy_residual(results) -> np.ndarray:
    """Residual of the run's energy balance at each row, relative to the input work so far: ``(W_in + W_clamp -
    W_out - W_diss - (E - E(0))) / W_in`` from the cumulative works ``(input, output, dissipated, clamping)`` (J)
    and the stored energy ``E`` (J); NaN before any input work."""
    W, E = np.asarray(results.series["work"]), np.asarray(results.series["energy"]).reshape(-1)
    r = W[:, 0] + W[:, 3] - W[:, 1] - W[:, 2] - (E - E[0])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(W[:, 0] > 0, r / np.where(W[:, 0] > 0, W[:, 0], 1.0), np.nan)


def nonfinite_series(results) -> list[str]:
    """Names of the stored series that hold a NaN or an infinity."""
    return [k for k, v in results.series.items() if np.asarray(v).dtype.kind == "f" and not np.isfinite(v).all()]


def write_history_csv(cols: dict[str, np.ndarray], path: str | Path) -> Path:
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(out, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols), comments="")
    return out


def plot_history(results, path: str | Path, window: float = 0.05, title: str = "") -> Path:
    """Speeds, ratio (and the loop's smoothed estimate), efficiency over ``window`` s, slip (if stored) and clamping
    forces against time from a run's results, as PNG."""
    plt = pyplot()
    c = history(results, window)
    s = results.series
    panels = 5 if "slip_driving" in c else 4
    fig, ax = plt.subplots(panels, 1, figsize=(8, 2.2 * panels + 0.6), sharex=True)
    t = c["time"]
    ax[0].plot(t, c["n1_rpm"], label="driving n1")
    ax[0].plot(t, c["n2_rpm"], label="driven n2")
    ax[0].set_ylabel("speed, rpm")
    ax[1].plot(t, c["ratio"], label="omega1/omega2")
    if "control.ratio_estimate" in s:
        ax[1].plot(t, s["control.ratio_estimate"][:, 0], "--", label="smoothed estimate")
    ax[1].set_ylabel("ratio")
    ax[2].plot(t, c["efficiency"], label=f"output / input work, {window:g} s window")
    ax[2].plot(t, c["efficiency_kinetic"], "--", label="kinetic-energy corrected")
    ax[2].set_ylabel("efficiency")
    if panels == 5:
        ax[3].plot(t, c["slip_driving"], label="driving pulley")
        ax[3].plot(t, c["slip_driven"], label="driven pulley")
        ax[3].set_ylabel("slip speed, m/s")
    ax[-1].plot(t, c["F1"] / 1e3, label="F1")
    ax[-1].plot(t, c["F2"] / 1e3, label="F2")
    ax[-1].set_ylabel("clamping force, kN")
    ax[-1].set_xlabel("time, s")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(loc="best", fontsize=8)
    fig.suptitle(title or "regime history")
    fig.tight_layout()
    return save(fig, path)
