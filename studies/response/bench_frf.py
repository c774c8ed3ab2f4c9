"""FRF benchmark (issue 15): a ~10,000-DOF CVT sheave shaft, 2,000 frequency lines x 50 speeds, 40 modes.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/response/bench_frf.py [--repeat 3]
    # -> out/studies/response/bench.txt

The ``cvt_sheave_shaft`` preset with every shaft segment split into ``SPLIT`` elements (sheaves, bearings and
their nodes scaled alike).  Input: a unit x force at the fixed sheave; outputs: x, y there and the x, y forces
of both bearings.  Timed (median of ``--repeat`` runs, :mod:`cvtfem.analysis.timing`), modal superposition with
40 modes + residual vectors:

* before: the complex basis per speed (right and left modes, two ARPACK solves per speed), timed on 3 speeds and
  scaled to 50;
* after: one basis for the sweep (``modes="sweep"``: right and left modes at the ends and the middle, 6 ARPACK
  solves), the full grid;
* the basis at rest (one eigen-solve, approximate for a spinning rotor), the full grid;
* direct sparse solves on a subset of lines (per-line cost x 100,000 lines = estimate).

Accuracy of each modal route against the direct solves at 20 lines x 3 speeds that are not basis speeds.
"""
from __future__ import annotations

import argparse
import copy
import tomllib
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from cvtfem.analysis.timing import machine, wall_times
from cvtfem.machines.rotor import build_model
from cvtfem.modal.forced import ModalBasis, OutputMap, displacement, frf_direct
from cvtfem.scene.loader import preset_text, scene_from_dict

OUT = Path("out/studies/response")
SPLIT = 166  # 10 segments x 166 = 1660 elements, 9,972 DOF
N_FREQ, N_SPEED, N_MODES = 2000, 50, 40


def big_sheave_shaft(split: int = SPLIT) -> dict:
    """The cvt_sheave_shaft preset with each element split in ``split``."""
    data = copy.deepcopy(tomllib.loads(preset_text("cvt_sheave_shaft")))
    for s in data["shaft"]:
        s["length"] /= split
        s["repeat"] *= split
    for part in data["disk"] + data["bearing"]:
        part["node"] *= split
    return data


def _timed(fn, repeat: int) -> tuple[float, np.ndarray, object]:
    """Median wall time (s) of ``repeat`` calls, the times, and the last result."""
    box = []
    times = wall_times(lambda: box.append(fn()), repeat)
    return float(np.median(times)), times, box[-1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    lines: list[str] = []

    def log(text: str) -> None:
        print(text, flush=True)
        lines.append(text)

    log(f"machine: {machine()}")
    scene = scene_from_dict(big_sheave_shaft())
    m = build_model(scene)
    log(f"model: {m.n_dof} DOF, {len(m.beam.nodes)} elements")
    n, sheave = m.n_dof, 4 * SPLIT
    f = np.zeros(n)
    f[6 * sheave] = 1.0
    D, V = m.bearing_force_map()
    xy = displacement([6 * sheave, 6 * sheave + 1], n)
    out = OutputMap(sp.vstack([xy.D, D]).tocsr(), sp.vstack([xy.V, V]).tocsr(),
                    ("u1", "u2", "b0x", "b0y", "b1x", "b1y"))
    w = np.linspace(0.0, 2 * np.pi * 5000.0, N_FREQ)
    speeds = np.linspace(0.0, 6000.0, N_SPEED) * np.pi / 30
    check = [7, 24, 44]  # speeds compared with direct solves: none is a basis speed of the sweep basis
    sub = w[1::100]  # 20 lines
    grid = len(out.names)

    def complex_modes() -> list[np.ndarray]:
        basis = ModalBasis(m.M, m.K, m.C, m.G, f, N_MODES, modes="complex")
        return [basis.frf(out, w, speeds[i]) for i in check]

    med, times, H_c = _timed(complex_modes, args.repeat)
    log(f"before: complex basis per speed (right + left modes, {N_MODES} each): {len(check)} speeds x {N_FREQ} "
        f"lines median {med:.2f} s ({', '.join(f'{x:.2f}' for x in times)}), {med / len(check):.2f} s per speed: "
        f"{N_SPEED} speeds ~ {med / len(check) * N_SPEED:.0f} s")

    def sweep() -> tuple[list[np.ndarray], ModalBasis]:
        basis = ModalBasis(m.M, m.K, m.C, m.G, f, N_MODES, modes="sweep",
                           basis_speeds=(speeds[0], speeds[-1] / 2, speeds[-1]))
        return [basis.frf(out, w, s) for s in speeds], basis

    med_s, times_s, (H_s, basis) = _timed(sweep, args.repeat)
    log(f"after: one sweep basis (right + left modes at 0, 3000, 6000 rpm: {basis.reduced(0.0)[0].shape[1]} vectors) "
        f"{N_SPEED} speeds x {N_FREQ} lines x {grid} outputs median {med_s:.2f} s "
        f"({', '.join(f'{x:.2f}' for x in times_s)}); target < 60 s")

    def rest() -> list[np.ndarray]:
        basis = ModalBasis(m.M, m.K, m.C, m.G, f, N_MODES, modes="rest")
        return [basis.frf(out, w, s) for s in speeds]

    med_r, times_r, H_r = _timed(rest, args.repeat)
    log(f"basis at rest (one eigen-solve): {N_SPEED} speeds x {N_FREQ} lines median {med_r:.2f} s "
        f"({', '.join(f'{x:.2f}' for x in times_r)})")

    med_d, times_d, H_d = _timed(lambda: [frf_direct(m.M, m.K, m.C, m.G, f, out, sub, speeds[i]) for i in check],
                                 args.repeat)
    per = med_d / (len(check) * len(sub))
    log(f"direct, one sparse LU per line: {len(check)} speeds x {len(sub)} lines median {med_d:.2f} s "
        f"({per * 1e3:.1f} ms per line; {N_SPEED} x {N_FREQ} lines ~ {per * N_SPEED * N_FREQ:.0f} s)")

    for name, H in (("complex basis", [h[1::100] for h in H_c]), ("sweep basis", [H_s[i][1::100] for i in check]),
                    ("rest basis", [H_r[i][1::100] for i in check])):
        err = []
        for k in range(len(check)):
            dH, Hd = np.abs(H[k][:, :, 0] - H_d[k][:, :, 0]), np.abs(H_d[k][:, :, 0])
            # per line, each kind (displacements u1, u2; bearing forces) relative to its largest output
            err.append(np.maximum(dH[:, :2].max(axis=1) / Hd[:, :2].max(axis=1),
                                  dH[:, 2:].max(axis=1) / Hd[:, 2:].max(axis=1)))
        e = np.max(err, axis=0)
        log(f"  {name} vs direct (per line, displacements and bearing forces each relative to their largest): "
            f"max {e.max():.2e}, median {np.median(e):.2e} over {len(sub)} lines up to {sub[-1] / 2 / np.pi:.0f} Hz "
            f"at {', '.join(f'{speeds[i] * 30 / np.pi:.0f}' for i in check)} rpm")
    (OUT / "bench.txt").write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT / 'bench.txt'}")


if __name__ == "__main__":
    main()
