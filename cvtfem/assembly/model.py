"""The Model protocol: what every machine kind (band CVT, rotor, torsional network, later the
discrete chain) offers every analysis, and the shared parts of its implementations.

A model's state is ``x = [u, v, z]`` (spec eq. (2.4)): the coordinates ``u`` of its
second-order blocks, their velocities ``v`` and the first-order states ``z``, with
``rhs = [v, F_v, F_z]``.  ``machines/`` builds a model from a scene in one pass, assembling only
the element families the scene switches on.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any, Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly.colouring import color_columns, coloured_difference
from cvtfem.elements.base import Block
from cvtfem.outputs import OutputSpec
from cvtfem.errors import InputError

__all__ = ["Block", "StateLayout", "Linearization", "Model", "ModelBase"]


@dataclass(frozen=True)
class StateLayout:
    """Named coordinate blocks in state order: second-order blocks (``u``, then ``v``), then first-order ones."""

    blocks: tuple[Block, ...]

    def __post_init__(self) -> None:
        orders = [b.order for b in self.blocks]
        if any(o not in (1, 2) for o in orders) or orders != sorted(orders, reverse=True):
            raise InputError("layout.blocks", orders, "orders must be 2 or 1, the second-order blocks first")

    @cached_property
    def n2(self) -> int:
        """Second-order coordinates (each with a velocity)."""
        return sum(b.size for b in self.blocks if b.order == 2)

    @cached_property
    def n1(self) -> int:
        """First-order states."""
        return sum(b.size for b in self.blocks if b.order == 1)

    @cached_property
    def size(self) -> int:
        """State length ``2 n2 + n1``."""
        return 2 * self.n2 + self.n1

    def index(self, name: str) -> np.ndarray:
        """State indices of block ``name`` (of its coordinates ``u`` for a second-order block; ``+ n2``: velocities)."""
        start = {2: 0, 1: 2 * self.n2}
        for b in self.blocks:
            if b.name == name:
                return np.arange(start[b.order], start[b.order] + b.size)
            start[b.order] += b.size
        raise InputError("block", name, "must be one of " + ", ".join(b.name for b in self.blocks))

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Views ``u, v, z`` of a state vector."""
        n = self.n2
        return x[:n], x[n:2 * n], x[2 * n:]


@dataclass(frozen=True)
class Linearization:
    """A model linearised at a state: ``M u'' + (C + speed G) u' + K u = f`` or ``x' = A x``.

    Second-order models fill M, C, G, K (``n2 x n2``, sparse; G per unit spin speed, rad/s);
    first-order ones (a closed loop with controller states) fill A (``size x size``).
    """

    M: Any = None
    C: Any = None
    G: Any = None
    K: Any = None
    A: Any = None


@runtime_checkable
class Model(Protocol):
    """What every machine kind offers (attributes and methods; see ``docs/architecture.md``)."""

    layout: StateLayout
    n2: int
    size: int
    output_specs: tuple[OutputSpec, ...]
    jac_sparsity: sp.csr_matrix | None
    jac: Any  # callable (t, x) -> sparse or dense, or None (difference over jac_sparsity)
    events: Any
    switch: Any

    def initial_state(self) -> np.ndarray: ...

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray: ...

    def fd_jac(self, t: float, x: np.ndarray) -> sp.csr_matrix: ...

    def outputs(self, t: float, x: np.ndarray) -> dict[str, Any]: ...

    def linearize(self, x0: np.ndarray) -> Linearization: ...

    def energy(self, x: np.ndarray) -> float: ...


class ModelBase:
    """Defaults of the concrete models: sizes from :attr:`layout`, no events, no analytic Jacobian.

    Subclasses provide ``layout``, ``rhs``, ``jac_sparsity``, ``output_specs`` and ``outputs``; they
    define ``jac`` where their element families give analytic blocks.
    """

    #: Event indicators ``g(t, x) -> (m,)`` with ``event_direction``/``event_terminal`` (None: no events).
    events = None
    event_direction = np.zeros(0, int)
    event_terminal = np.zeros(0, bool)
    #: Discrete-state switch ``switch(t, x, fired) -> x or None`` at an event (None: no discrete states).
    switch = None

    @property
    def n2(self) -> int:
        return self.layout.n2

    @property
    def size(self) -> int:
        return self.layout.size

    @cached_property
    def colouring(self) -> tuple[sp.coo_matrix, np.ndarray]:
        """``(pattern, colors)`` of :attr:`jac_sparsity` (:func:`~cvtfem.assembly.colouring.color_columns`)."""
        pattern = sp.csr_matrix(self.jac_sparsity, dtype=bool)
        return pattern.tocoo(), color_columns(pattern)

    #: Analytic ``jac(t, x)`` where the families give blocks; None: analyses difference over
    #: :attr:`jac_sparsity` with the same colouring and count the calls (:meth:`fd_jac` does it here).
    jac = None

    def fd_jac(self, t: float, x: np.ndarray) -> sp.csr_matrix:
        """``d rhs / dx`` by coloured forward differences: as many RHS calls as colours, plus ``rhs(t, x)``."""
        pattern, colors = self.colouring
        return coloured_difference(self.rhs, t, x, self.rhs(t, x), pattern, colors)
