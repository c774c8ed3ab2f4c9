"""The :class:`Problem` record shared by all test problems."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = ["Problem"]


@dataclass(frozen=True)
class Problem:
    """An initial-value problem ready for :func:`cvtfem.integrate.solve`.

    ``exact(t) -> (n,)`` gives the closed-form solution when known; ``y_ref`` is a published
    reference value at ``t_span[1]`` (``ref_index`` selects the components it covers).
    ``solve_kwargs()`` returns the keyword arguments for ``solve`` (fun, y0, n2, jac, ...).
    """

    name: str
    fun: Callable
    y0: np.ndarray
    t_span: tuple[float, float]
    n2: int = 0
    jac: Callable | None = None
    jac_sparsity: object | None = None
    events: object | None = None
    switch: Callable | None = None
    exact: Callable | None = None
    y_ref: np.ndarray | None = None
    ref_index: np.ndarray | None = None
    info: dict = field(default_factory=dict)

    def solve_kwargs(self) -> dict:
        kw = dict(fun=self.fun, t_span=self.t_span, y0=self.y0.copy(), n2=self.n2)
        for key in ("jac", "jac_sparsity", "events", "switch"):
            if getattr(self, key) is not None:
                kw[key] = getattr(self, key)
        return kw

    def reference(self) -> np.ndarray:
        """Reference solution at ``t_span[1]`` (closed form or published), selected components."""
        if self.exact is not None:
            return self.exact(self.t_span[1])
        return self.y_ref
