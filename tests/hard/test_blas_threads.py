"""A run's bits do not depend on how many BLAS threads the machine gives it, nor on the process.

OpenBLAS solves a complex LU system (``zgetrs``, in scipy's Radau) to different last bits with one
and with two threads, even for 4 unknowns; an adaptive integrator turns those into different steps
and 1e-8 relative differences in the results.  A user's 8-core laptop, a CI runner, a dask worker
(whose nanny sets ``OPENBLAS_NUM_THREADS=1`` for the whole parent process) and the checkpoint
resume of a killed run must all give the same numbers, so the integration runs on one BLAS thread.
"""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np

from cvtfem.io.results import read_results
from tests.hard.test_resume import IMPLICIT_SCENE


def _run(tmp_path, method: str, threads: int):
    scene = tmp_path / f"{method}.toml"
    scene.write_text(IMPLICIT_SCENE.format(method=method, interval=0.0), encoding="utf-8")   # no checkpoints
    path = tmp_path / f"{method}-{threads}.h5"
    env = {**os.environ, "OPENBLAS_NUM_THREADS": str(threads)}
    proc = subprocess.run([sys.executable, "-m", "cvtfem.cli", "run", str(scene), "--until", "0.05",
                           "--results", str(path)], capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return read_results(path)


def test_radau_run_is_bitwise_the_same_on_one_and_two_blas_threads(tmp_path):
    one, two = _run(tmp_path, "Radau", 1), _run(tmp_path, "Radau", 2)
    assert one.stats["solver_nfev"] == two.stats["solver_nfev"]
    assert np.array_equal(one.time, two.time)
    for name in one.series:
        assert np.array_equal(one.series[name], two.series[name], equal_nan=True), name


def test_sparse_eigen_solve_is_bitwise_the_same_in_two_processes():
    """ARPACK's default start vector is random per process: two runs of the same sparse solve differed in the
    last bits (three processes, three results); the seeded start vector (cvtfem.blas.arpack_start) fixes them."""
    code = ("import numpy as np; from cvtfem.machines.rotor import build_model; "
            "from cvtfem.scene.loader import load_scene; from cvtfem.modal import ModalProblem; "
            "m = build_model(load_scene('cvt_sheave_shaft')); "
            "r = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method='sparse').solve(300.0, 6); "
            "print(np.ascontiguousarray(r.wd).tobytes().hex())")
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300) for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr
    assert runs[0].stdout == runs[1].stdout
