"""Campbell diagrams: modes over a speed range, MAC tracking, excitation orders, crossings.

An excitation line is a frequency proportional to the spin speed,
``w_exc = factor * Omega`` (rad/s): shaft orders ``k Omega``; for a CVT with
chain speed ``v = Omega r`` the chain orders ``k f_chain`` and link orders
``k/3 f_link`` (spec §11, §12.7) with ``f = v / l`` (Hz, so
``factor = 2 pi r k / l``).  A crossing of a tracked mode's damped frequency
with a line is a critical speed.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from cvtfem.errors import InputError
from cvtfem.modal.eigen import ModalProblem, Modes
from cvtfem.modal.whirl import mac


def shaft_orders(k: tuple[float, ...] = (1.0,)) -> tuple[tuple[str, float], ...]:
    """Lines ``k Omega``: ``(("1x", 1.0), ...)``."""
    return tuple((f"{kk:g}x", float(kk)) for kk in k)


def chain_orders(radius: float, chain_length: float, link_length: float, k_chain: int = 3,
                 k_link: int = 3) -> tuple[tuple[str, float], ...]:
    """CVT excitation lines for a chain running at ``v = Omega * radius`` (spec §11).

    Parameters
    ----------
    radius : float, m
        Contact (pitch) radius on the analysed shaft.
    chain_length, link_length : float, m
    k_chain, k_link : int
        Lines ``k f_chain`` for k = 1..k_chain and ``k/3 f_link`` for k = 1..k_link.
    """
    for name, v in (("radius", radius), ("chain_length", chain_length), ("link_length", link_length)):
        if not v > 0:
            raise InputError(name, v, "must be > 0 m")
    lines = [(f"{k} f_chain", 2 * np.pi * radius * k / chain_length) for k in range(1, k_chain + 1)]
    lines += [(f"{k}/3 f_link", 2 * np.pi * radius * k / (3 * link_length)) for k in range(1, k_link + 1)]
    return tuple(lines)


@dataclass(frozen=True)
class Campbell:
    """Tracked modes over speeds.

    Attributes
    ----------
    speeds : array (s,), rad/s
    wd, wn, damping_ratio : arrays (s, k)
        Tracked mode ``j`` is column ``j`` (identity kept by MAC across speeds).
    whirl : array of str (s, k)
    modes : tuple of Modes
        Per speed, ascending in wd (untracked order).
    orders : tuple of (label, factor)
    crossings : tuple of dict
        ``{"mode", "whirl", "order", "speed_rad_s", "frequency_rad_s", "damping_ratio"}``; modes damped above
        :data:`CRITICALLY_DAMPED` have none.
    jumps : tuple of dict
        ``{"mode", "speed_rad_s", "mac"}`` where tracking lost a mode (MAC with the previous speed below
        :data:`MAC_JUMP`): the curve there may join another mode.
    """

    speeds: np.ndarray
    wd: np.ndarray
    wn: np.ndarray
    damping_ratio: np.ndarray
    whirl: np.ndarray
    modes: tuple[Modes, ...]
    orders: tuple[tuple[str, float], ...]
    crossings: tuple[dict[str, object], ...]
    jumps: tuple[dict[str, object], ...] = ()

    def to_dict(self) -> dict[str, object]:
        """JSON-ready data: per-speed mode lists, tracked curves, orders, crossings."""
        return {"speeds_rad_s": self.speeds.tolist(),
                "per_speed": [m.to_dict() for m in self.modes],
                "tracked": {"wd_rad_s": self.wd.tolist(), "wn_rad_s": self.wn.tolist(),
                            "damping_ratio": self.damping_ratio.tolist(), "whirl": self.whirl.tolist()},
                "orders": [{"label": lab, "factor": f} for lab, f in self.orders],
                "crossings": list(self.crossings), "tracking_jumps": list(self.jumps)}

    def write_csv(self, path: Path) -> None:
        """One row per (speed, tracked mode): speed, mode, wd, wn, zeta, whirl."""
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["speed_rad_s", "mode", "wd_rad_s", "wn_rad_s", "damping_ratio", "whirl"])
            for i, s in enumerate(self.speeds):
                for j in range(self.wd.shape[1]):
                    w.writerow([f"{s:.9g}", j, f"{self.wd[i, j]:.9g}", f"{self.wn[i, j]:.9g}",
                                f"{self.damping_ratio[i, j]:.6g}", self.whirl[i, j]])


#: A tracked mode whose MAC with its predecessor falls below this is flagged as a jump (a new mode took
#: its place between two speeds: refine the speed grid there).
MAC_JUMP = 0.5
#: Modes damped above this ratio have no crossing: API 684 treats an amplification factor
#: ``1 / (2 zeta)`` below 2.5 (zeta > 0.2) as critically damped, with no separation margin to keep.
CRITICALLY_DAMPED = 0.2


def track(modes: list[Modes], n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """Column permutations that follow mode identity across speeds by MAC.

    A mode whose frequency, extrapolated linearly from the two speeds before, passes through zero (a backward
    wave at its critical speed: a flexible sheave's, a disc's) comes back as the complex conjugate of its shape,
    seen with the positive frequency of the opposite sense: for that mode the MAC is also taken with the conjugate.

    Parameters
    ----------
    modes : list of Modes
        Each with at least ``n_modes`` modes, ascending in wd.

    Returns
    -------
    index : int array (s, n_modes)
        ``index[i, j]``: which mode at speed ``i`` is tracked mode ``j``.
    match : array (s, n_modes)
        MAC of tracked mode ``j`` at speed ``i`` with itself at speed ``i - 1`` (1 at the first speed).
    """
    index = np.zeros((len(modes), n_modes), dtype=int)
    match = np.ones((len(modes), n_modes))
    index[0] = np.arange(n_modes)
    ref = modes[0].shapes[:, :n_modes]
    for i in range(1, len(modes)):
        cand = modes[i].shapes
        m = mac(ref, cand)
        if i >= 2:
            wd = [modes[k].wd[index[k]] for k in (i - 2, i - 1)]
            through = np.flatnonzero(2 * wd[1] - wd[0] < 0.0)        # heading through zero frequency
            if through.size:
                m[through] = np.maximum(m[through], mac(ref[:, through].conj(), cand))
        rows, col = linear_sum_assignment(1.0 - m)
        index[i], match[i] = col, m[rows, col]
        ref = cand[:, col]
    return index, match


def crossings(speeds: np.ndarray, wd: np.ndarray, whirl: np.ndarray, zeta: np.ndarray,
              orders: tuple[tuple[str, float], ...]) -> tuple[dict[str, object], ...]:
    """Speeds where tracked curves cross excitation lines (linear interpolation), for modes damped at most
    :data:`CRITICALLY_DAMPED` at both ends of the bracketing interval."""
    out = []
    for label, factor in orders:
        d = wd - factor * speeds[:, None]
        for j in range(wd.shape[1]):
            hits = np.flatnonzero(np.sign(d[:-1, j]) * np.sign(d[1:, j]) < 0)
            for i in hits:
                if max(zeta[i, j], zeta[i + 1, j]) > CRITICALLY_DAMPED:
                    continue
                t = d[i, j] / (d[i, j] - d[i + 1, j])
                s = speeds[i] + t * (speeds[i + 1] - speeds[i])
                out.append({"mode": j, "whirl": str(whirl[i, j]), "order": label, "speed_rad_s": float(s),
                            "frequency_rad_s": float(factor * s),
                            "damping_ratio": float(zeta[i, j] + t * (zeta[i + 1, j] - zeta[i, j]))})
    return tuple(sorted(out, key=lambda c: c["speed_rad_s"]))


def campbell(problem: ModalProblem, speeds: np.ndarray, n_modes: int,
             orders: tuple[tuple[str, float], ...] = shaft_orders(), extra: int = 4) -> Campbell:
    """Solve at every speed, track modes by MAC and find the critical speeds.

    Parameters
    ----------
    problem : ModalProblem
    speeds : array (s,), rad/s
        Increasing spin speeds.
    n_modes : int
        Tracked modes (the lowest ``n_modes`` at the first speed).
    orders : tuple of (label, factor)
        Excitation lines ``w = factor * Omega``.
    extra : int
        Additional modes solved per speed so that curves can re-order.
    """
    speeds = np.asarray(speeds, dtype=float)
    if speeds.ndim != 1 or len(speeds) < 1 or np.any(np.diff(speeds) <= 0):
        raise InputError("speeds", speeds.tolist()[:5], "must be one or more increasing speeds")
    modes = [problem.solve(s, n_modes + extra, min_modes=n_modes) for s in speeds]
    idx, match = track(modes, n_modes)

    def tracked(attr: str) -> np.ndarray:      # a speed may return more modes than another (min_modes only bounds)
        return np.array([np.asarray(getattr(m, attr))[i] for m, i in zip(modes, idx)])
    wd, wn, zeta, whirl = (tracked(a) for a in ("wd", "wn", "damping_ratio", "whirl"))
    trimmed = tuple(Modes(m.speed, m.eigenvalues[:n_modes], m.shapes[:, :n_modes], m.whirl[:n_modes],
                          m.whirl_ratio[:n_modes]) for m in modes)
    jumps = tuple({"mode": int(j), "speed_rad_s": float(speeds[i]), "mac": float(match[i, j])}
                  for i, j in zip(*np.nonzero(match < MAC_JUMP)))
    return Campbell(speeds, wd, wn, zeta, whirl, trimmed, tuple(orders), crossings(speeds, wd, whirl, zeta, orders),
                    jumps)
