"""Worked example of docs/response.md: the CVT sheave shaft's unbalance response and link-order map.

    .venv/bin/python studies/response/cvt_example.py     # -> out/studies/response/

Link orders for a chain at contact radius r = 60 mm with links of l = 9 mm (as `cvtfem campbell --chain
0.06,0.7,0.009`): f_link = Omega r / l, order 2 pi r / l = 41.89, and its thirds 13.96, 27.93.  Prints, per
order, the peaks of the order response next to the Campbell crossings of lateral modes.
"""
from pathlib import Path

import numpy as np
from scipy.signal import find_peaks

from cvtfem.analysis.response import Unbalance, scene_response
from cvtfem.post.response import plot_bode, plot_order_map
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/response")


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    link = 2 * np.pi * 0.06 / 0.009
    orders = (link / 3, 2 * link / 3, link)
    speeds = np.linspace(0.0, 6000.0, 241) * np.pi / 30
    res = scene_response(load_scene("cvt_sheave_shaft"), [Unbalance(4, 1e-5, 0.0), Unbalance(7, 1e-5, np.pi / 2)],
                         speeds, 4, orders=orders, n_freqs=400, n_modes=12)
    plot_bode(res, OUT / "cvt_bode.png", "CVT sheave shaft: unbalance 10 g mm on each sheave")
    plot_order_map(res, OUT / "cvt_orders.png", "CVT sheave shaft, link orders")
    step = (speeds[1] - speeds[0]) * 30 / np.pi
    print(f"speed step {step:.1f} rpm")
    print("| order | peaks of the order response (rpm) | lateral Campbell crossings (rpm) |")
    print("|---|---|---|")
    for j, k in enumerate(orders):
        peaks = speeds[find_peaks(res.order_amplitude[:, j])[0]] * 30 / np.pi
        cross = [c["speed_rad_s"] * 30 / np.pi for c in res.campbell.crossings
                 if c["order"] == f"{k:g}x" and c["whirl"] in ("forward", "backward")]
        print(f"| {k:.2f} | {', '.join(f'{p:.0f}' for p in peaks)} | {', '.join(f'{c:.0f}' for c in cross)} |")
    fr = scene_response(load_scene("friswell_5_9_1"), [Unbalance(2, 1e-4, 0.0)],
                        np.linspace(0.0, 4000.0, 401) * np.pi / 30, 2)
    plot_bode(fr, OUT / "friswell_bode.png", "Friswell 5.9.1 (undamped): unbalance 1e-4 kg m at node 2")
    peaks = fr.speeds[find_peaks(fr.major)[0]] * 30 / np.pi
    print(f"Friswell 5.9.1 unbalance response peaks (rpm): {', '.join(f'{p:.0f}' for p in peaks)}")
    print(f"wrote {OUT}/cvt_bode.png, cvt_orders.png, friswell_bode.png")


if __name__ == "__main__":
    main()
