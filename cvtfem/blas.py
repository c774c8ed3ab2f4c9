"""Reproducible linear algebra: one BLAS thread where a result's bits must not depend on the machine's
thread count, and a fixed ARPACK start vector.

OpenBLAS solves a complex LU system (``zgetrs``, in scipy's Radau) to different last bits with one
and with two threads, even for 4 unknowns; an adaptive integrator amplifies them into other steps and
1e-8 relative differences of a run.  Time integration and the harmonic-balance Newton iteration
therefore run on one BLAS thread (their systems are small or sparse: threads did not pay there either).
"""
from __future__ import annotations

import numpy as np
from threadpoolctl import threadpool_limits

__all__ = ["single_thread_blas", "arpack_start"]


def single_thread_blas():
    """Context limiting every loaded BLAS library to one thread (about 0.3 ms to enter)."""
    return threadpool_limits(limits=1, user_api="blas")


def arpack_start(n: int) -> np.ndarray:
    """ARPACK's start vector for an ``n``-dimensional problem: seeded pseudo-random (scipy's default is a new
    random vector in every process, so eigen-solves of large models differed from run to run; a constant
    vector would be orthogonal to the modes of a symmetric structure and miss them)."""
    return np.random.default_rng(0).standard_normal(n)
