"""What benchmarks and studies print about their timings: the machine in one line, median wall times."""
from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable

import numpy as np


def machine() -> str:
    """One line describing the machine, its load and the BLAS threading."""
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "default")
    try:
        import threadpoolctl  # noqa: F401

        limit = "solves limited to 1 BLAS thread (threadpoolctl)"
    except ImportError:
        limit = "threadpoolctl absent: BLAS threads not limited"
    return (f"{platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"load {os.getloadavg()[0]:.1f}, python {platform.python_version()}, numpy {np.__version__}, "
            f"OPENBLAS_NUM_THREADS={threads}, {limit}")


def wall_times(fn: Callable[[], object], calls: int, warm_up: bool = False) -> np.ndarray:
    """Wall time of each of ``calls`` calls of ``fn`` (s), after one untimed call if ``warm_up``."""
    if warm_up:
        fn()
    times = np.empty(calls)
    for k in range(calls):
        t0 = time.perf_counter()
        fn()
        times[k] = time.perf_counter() - t0
    return times


def median_us(fn: Callable[[], object], calls: int = 1000, warm_up: bool = False) -> float:
    """Median wall time of ``fn`` over ``calls`` calls, microseconds."""
    return float(np.median(wall_times(fn, calls, warm_up))) * 1e6
