"""Cost counters and timers of one integration run (spec §6, Table 2.3 names)."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

#: Counter names, in the order reports list them.
COUNTERS = ("nfev", "nfev_jac", "njev", "nlu", "nsolve", "nsteps", "nreject", "nnewton",
            "nnewton_fail", "njac_refresh", "nevents", "ntruncated", "nevfun")
#: Timer names (seconds of wall time spent in each costly operation).
TIMERS = ("t_rhs", "t_jac", "t_lu", "t_solve", "t_total")


@dataclass
class Stats:
    """Mutable counters of costly operations, filled while a solver runs.

    ``nfev`` counts every right-hand-side call, including the ``nfev_jac`` calls spent on
    finite-difference Jacobians; ``njev`` Jacobians, ``nlu`` LU factorisations, ``nsolve``
    linear solves, ``nnewton`` Newton iterations, ``nevents`` located events,
    ``ntruncated`` event-truncated steps, ``nevfun`` indicator evaluations.
    """

    counts: dict[str, int] = field(default_factory=lambda: dict.fromkeys(COUNTERS, 0))
    times: dict[str, float] = field(default_factory=lambda: dict.fromkeys(TIMERS, 0.0))

    def add(self, name: str, n: int = 1) -> None:
        self.counts[name] += n

    def timer(self, name: str) -> "_Timer":
        """Accumulate the wall time of a ``with`` block into ``times[name]``."""
        return _Timer(self.times, name)

    def as_dict(self) -> dict[str, float]:
        """Counters and timers in one flat dict (the ``.stats`` of a result)."""
        return {**self.counts, **self.times}


class _Timer:
    """The ``with`` block of :meth:`Stats.timer` (a plain class: a generator-based context manager
    costs several microseconds per RHS call and linear solve)."""

    __slots__ = ("times", "name", "t0")

    def __init__(self, times: dict, name: str) -> None:
        self.times, self.name = times, name

    def __enter__(self) -> None:
        self.t0 = time.perf_counter()

    def __exit__(self, *exc) -> None:
        self.times[self.name] += time.perf_counter() - self.t0
