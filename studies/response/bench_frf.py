"""FRF benchmark (issue 15): a ~10,000-DOF CVT sheave shaft, 2,000 frequency lines x 50 speeds.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/response/bench_frf.py [--repeat 3]
    # -> out/studies/response/bench.txt

The ``cvt_sheave_shaft`` preset with every shaft segment split into ``SPLIT`` elements (sheaves, bearings and
their nodes scaled alike).  Input: a unit x force at the fixed sheave; outputs: x, y there and the x, y forces
of both bearings.  Timed (median of ``--repeat`` runs): modal superposition with 40 modes on the basis of modes
at rest (one eigen-solve for all speeds) over the full grid; the complex-mode basis (right and left modes per
speed) on a few speeds; direct sparse solves on a subset of lines (per-line cost x 100,000 lines = estimate).
"""
from __future__ import annotations

import argparse
import copy
import statistics
import time
import tomllib
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from cvtfem.analysis.bench_campbell import machine
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


def _median(fn, repeat: int) -> tuple[float, list[float], object]:
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), times, out


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
    t = time.perf_counter()
    scene = scene_from_dict(big_sheave_shaft())
    m = build_model(scene)
    log(f"model: {m.n_dof} DOF, {len(m.beam.nodes)} elements, build {time.perf_counter() - t:.2f} s")
    n, sheave = m.n_dof, 4 * SPLIT
    f = np.zeros(n)
    f[6 * sheave] = 1.0
    D, V = m.bearing_force_map()
    xy = displacement([6 * sheave, 6 * sheave + 1], n)
    out = OutputMap(sp.vstack([xy.D, D]).tocsr(), sp.vstack([xy.V, V]).tocsr(),
                    ("u1", "u2", "b0x", "b0y", "b1x", "b1y"))
    w = np.linspace(0.0, 2 * np.pi * 5000.0, N_FREQ)
    speeds = np.linspace(0.0, 6000.0, N_SPEED) * np.pi / 30

    def rest() -> np.ndarray:
        basis = ModalBasis(m.M, m.K, m.C, m.G, f, N_MODES, modes="rest")
        return np.stack([basis.frf(out, w, s) for s in speeds]), basis

    med, times, (H_rest, basis) = _median(rest, args.repeat)
    log(f"modal, basis of {N_MODES} modes at rest + static correction ({basis.reduced(0.0)[0].shape[1]} vectors, "
        f"highest {basis.wmax() / 2 / np.pi:.0f} Hz): {N_SPEED} speeds x {N_FREQ} lines x {len(out.names)} outputs "
        f"median {med:.2f} s ({', '.join(f'{x:.2f}' for x in times)}); target < 60 s")

    few = speeds[[0, N_SPEED // 2, -1]]
    cbasis = ModalBasis(m.M, m.K, m.C, m.G, f, N_MODES, modes="complex")

    def complex_modes() -> list[np.ndarray]:
        cbasis._reduced.clear()
        return [cbasis.frf(out, w, s) for s in few]

    med_c, times_c, H_cplx = _median(complex_modes, args.repeat)
    log(f"modal, complex right + left modes ({N_MODES} each) per speed: {len(few)} speeds x {N_FREQ} lines median "
        f"{med_c:.2f} s ({med_c / len(few):.2f} s per speed; {N_SPEED} speeds ~ {med_c / len(few) * N_SPEED:.0f} s)")

    lines_sub = w[1::100]  # 20 lines
    med_d, times_d, H_dir = _median(lambda: [frf_direct(m.M, m.K, m.C, m.G, f, out, lines_sub, s) for s in few],
                                    args.repeat)
    per = med_d / (len(few) * len(lines_sub))
    log(f"direct, one sparse LU per line: {len(few)} speeds x {len(lines_sub)} lines median {med_d:.2f} s "
        f"({per * 1e3:.1f} ms per line; {N_SPEED} x {N_FREQ} lines ~ {per * N_SPEED * N_FREQ:.0f} s)")

    for name, H in (("rest basis", [H_rest[[0, N_SPEED // 2, -1][i]][1::100] for i in range(3)]),
                    ("complex basis", [h[1::100] for h in H_cplx])):
        errs = []
        for i in range(3):
            Hd = H_dir[i]
            errs.append(np.abs(H[i][:, 0] - Hd[:, 0]).max(axis=1) / np.abs(Hd[:, 0]).max(axis=1))
        e = np.max(errs, axis=0)
        log(f"  {name} vs direct, u1 per line (rel. to the line's largest output): max {e.max():.2e}, "
            f"median {np.median(e):.2e} over {len(lines_sub)} lines up to {lines_sub[-1] / 2 / np.pi:.0f} Hz")
    (OUT / "bench.txt").write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT / 'bench.txt'}")


if __name__ == "__main__":
    main()
