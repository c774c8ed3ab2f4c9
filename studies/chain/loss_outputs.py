"""Pin-sheave friction loss of a chain run from its stored outputs alone (session 12, "the inclined pin face"): works
for every chain model, the pin halves of variant (e) too, where ``loss_decomposition.py`` (whole pins, full state)
does not.

Run:  .venv/bin/python studies/chain/loss_outputs.py RESULTS.h5 [RESULTS.h5 ...] [--from 0.02] [--to 0.03]

Over the rows in the window, per shaft (driving, driven): the friction loss ``-int P_fr dt / (W_in(to) - W_in(from))``
(%, trapezoidal in the stored ``contact.friction_power``), the mean slip speed of the pin ends touching
(``contact.slip_speed`` where ``contact.normal_force > 0``, as ``cvtfem history``), the share of those ends sliding
faster than ``v0``, the friction used ``sum |F_fr| / (f0 sum N)``, and with a refined contact the mean offset
``|x_*|`` of the contact point from the pin axis and the share of contacts off the pin's end face (``|x_*| >
width_n / 2``); and the efficiency over the window, steady and kinetic-energy corrected.  Units: %, m/s, mm.
"""
from __future__ import annotations

import argparse
import tomllib

import numpy as np

from cvtfem.io.results import read_results
from cvtfem.machines.cvt import pin_section
from cvtfem.scene.loader import scene_from_dict


def window_losses(path, t_from: float, t_to: float) -> dict:
    """The figures of the module docstring for the results file ``path`` over ``[t_from, t_to]`` s."""
    res = read_results(path)
    scene = scene_from_dict(tomllib.loads(res.scene_toml), str(path))
    t, s = res.time, res.series
    rows = (t >= t_from - 1e-12) & (t <= t_to + 1e-12)
    tw = t[rows]
    W, E = np.asarray(s["work"])[rows], np.asarray(s["energy"]).reshape(-1)[rows]
    d_in, d_out = W[-1, 0] - W[0, 0], W[-1, 1] - W[0, 1]
    Pf = np.asarray(s["contact.friction_power"])[rows]
    loss = -np.trapezoid(Pf, tw, axis=0) / d_in
    N = np.asarray(s["contact.normal_force"])[rows].reshape(len(tw), -1, 2)
    on = N > 0
    slip = np.asarray(s["contact.slip_speed"])[rows].reshape(N.shape)
    F = np.linalg.norm(np.asarray(s["contact.friction_force"])[rows].reshape(len(tw), -1, 2, 3), axis=-1)
    fr = scene.cvt.friction
    out = {"file": str(path), "rows": int(rows.sum()), "t": (float(tw[0]), float(tw[-1])), "loss": 100 * loss,
           "slip": (slip * on).sum(axis=(0, 1)) / on.sum(axis=(0, 1)),
           "above_v0": 100 * ((slip > fr.v0) & on).sum(axis=(0, 1)) / on.sum(axis=(0, 1)),
           "used": (F * on).sum(axis=(0, 1)) / (fr.f0 * (N * on).sum(axis=(0, 1))),
           "efficiency": d_out / d_in, "efficiency_kinetic": 1 - (d_in - d_out - (E[-1] - E[0])) / d_in,
           "ratio": float(np.mean(np.asarray(s["ratio"])[rows]))}
    if "contact.face_offset" in s:
        x = np.asarray(s["contact.face_offset"])[rows].reshape(N.shape)
        h = 0.5 * pin_section(scene).width_n
        out.update(offset=1e3 * (x * on).sum(axis=(0, 1)) / on.sum(axis=(0, 1)),
                   off_face=100 * ((x > h) & on).sum(axis=(0, 1)) / on.sum(axis=(0, 1)), half_height=1e3 * h)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="+")
    ap.add_argument("--from", dest="t_from", type=float, default=0.02)
    ap.add_argument("--to", dest="t_to", type=float, default=0.03)
    a = ap.parse_args(argv)
    print("run: rows, window ms; loss % driving/driven/total; mean slip m/s; ends > v0 %; friction used; |x_*| mm; "
          "off the face %; efficiency steady / kinetic-energy corrected; mean ratio")
    for path in a.results:
        r = window_losses(path, a.t_from, a.t_to)
        face = (f"; |x_*| {r['offset'][0]:.2f} / {r['offset'][1]:.2f} mm, off the face (> {r['half_height']:.2f} mm) "
                f"{r['off_face'][0]:.1f} / {r['off_face'][1]:.1f} %") if "offset" in r else ""
        print(f"{r['file']}: {r['rows']} rows, {1e3 * r['t'][0]:.1f}-{1e3 * r['t'][1]:.1f} ms; loss {r['loss'][0]:.2f} / "
              f"{r['loss'][1]:.2f} / {r['loss'].sum():.2f} %; slip {r['slip'][0]:.3f} / {r['slip'][1]:.3f} m/s; "
              f"> v0 {r['above_v0'][0]:.0f} / {r['above_v0'][1]:.0f} %; used {r['used'][0]:.2f} / {r['used'][1]:.2f}"
              f"{face}; efficiency {r['efficiency']:.4f} / {r['efficiency_kinetic']:.4f}; ratio {r['ratio']:.4f}")


if __name__ == "__main__":
    main()
