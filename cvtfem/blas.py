"""One BLAS thread where a result's bits must not depend on the machine's thread count.

OpenBLAS solves a complex LU system (``zgetrs``, in scipy's Radau) to different last bits with one
and with two threads, even for 4 unknowns; an adaptive integrator amplifies them into other steps and
1e-8 relative differences of a run.  Time integration and the harmonic-balance Newton iteration
therefore run on one BLAS thread (their systems are small or sparse: threads did not pay there either).
"""
from __future__ import annotations

from threadpoolctl import threadpool_limits

__all__ = ["single_thread_blas"]


def single_thread_blas():
    """Context limiting every loaded BLAS library to one thread (about 0.3 ms to enter)."""
    return threadpool_limits(limits=1, user_api="blas")
