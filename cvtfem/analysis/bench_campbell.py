"""Campbell benchmark (``cvtfem bench campbell``): wall time of speed sweeps, median of repeats.

Two cases (issue 3): the Friswell 5.9.1 rotor, 51 speeds x 12 modes; a
uniform shaft of about 10,000 DOF with two disks and damped anisotropic
bearings, 50 speeds x 20 modes (sparse shift-invert), with peak memory.
"""
from __future__ import annotations

import resource
import time
from collections.abc import Callable

import numpy as np

from cvtfem.analysis.timing import machine, wall_times


def large_shaft_scene(n_elements: int = 1666) -> dict:
    """Scene dict of a 3 m, 80 mm steel shaft with ``6 (n_elements + 1)`` DOF."""
    n = n_elements
    return {"material": [{"name": "steel", "E": 2.11e11, "G": 8.12e10, "rho": 7810.0}],
            "shaft": [{"length": 3.0 / n, "outer_diameter": 0.08, "material": "steel", "repeat": n}],
            "disk": [{"node": n // 3, "mass": 40.0, "Id": 0.3, "Ip": 0.6},
                     {"node": 2 * n // 3, "mass": 60.0, "Id": 0.5, "Ip": 0.9}],
            "bearing": [{"node": 0, "kxx": 5e7, "kyy": 4e7, "cxx": 1e3, "cyy": 1e3},
                        {"node": n, "kxx": 5e7, "kyy": 4e7, "cxx": 1e3, "cyy": 1e3}]}


def _median_time(fn: Callable[[], object], repeat: int) -> tuple[float, list[float]]:
    times = wall_times(fn, repeat)
    return float(np.median(times)), times.tolist()


def run(repeat: int = 5, large: bool = True, log: Callable[[str], None] = print) -> dict[str, float]:
    """Run both cases; returns the medians (s) and peak memory (MiB)."""
    from cvtfem.machines.rotor import build_model
    from cvtfem.modal import ModalProblem, campbell
    from cvtfem.scene.loader import load_scene, scene_from_dict

    log(f"machine: {machine()}")
    out = {}
    m = build_model(load_scene("friswell_5_9_1"))
    speeds = np.linspace(0, 4000 * np.pi / 30, 51)

    def friswell() -> object:
        return campbell(ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind), speeds, 12)

    med, times = _median_time(friswell, repeat)
    out["friswell_s"] = med
    log(f"friswell 5.9.1, {m.n_dof} DOF, 51 speeds x 12 modes (dense, blocks): median {med:.3f} s "
        f"over {repeat} runs ({', '.join(f'{t:.3f}' for t in times)}); target < 0.5 s")
    if large:
        t0 = time.perf_counter()
        big = build_model(scene_from_dict(large_shaft_scene()))
        t_build = time.perf_counter() - t0
        rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        problem = ModalProblem(big.M, big.K, big.C, big.G, big.dof_kind)
        t0 = time.perf_counter()
        res = campbell(problem, np.linspace(0, 3000 * np.pi / 30, 50), 20)
        out["large_s"] = time.perf_counter() - t0
        out["large_peak_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        log(f"large shaft, {big.n_dof} DOF (build {t_build:.2f} s), 50 speeds x 20 modes ({problem.method}): "
            f"{out['large_s']:.1f} s, peak RSS {out['large_peak_mib']:.0f} MiB (before the sweep {rss0:.0f} MiB); "
            f"target < 60 s; lowest wd at top speed {res.wd[-1, :4].round(2).tolist()} rad/s")
    return out
