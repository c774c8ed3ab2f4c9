"""A free discrete chain as a :class:`~cvtfem.assembly.model.Model`: one chain family without sheaves, in
the protocol every analysis uses.  :class:`FreeChain` carries the symmetric families S1, S2, S3
(:mod:`cvtfem.elements.chain.symmetric`), :class:`FreeChainA` the whole-pin asymmetric ones: A1
(:class:`~cvtfem.elements.chain.asymmetric.ChainA1`, plates as an elastic layer) and A3/A4
(:class:`~cvtfem.elements.chain.per_plate.ChainPerPlate`, per-plate plates).

The first step of the chain into the machine (issue 13): time runs (``integrate.solve(model, ...)``),
modal analysis of the linearised chain (``linearize``), outputs and energy through the same interface
as the band models.  Sheave contact, the clamping loops and the initial state on the sheaves come later.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.assembly.colouring import color_columns
from cvtfem.assembly.model import Linearization, ModelBase, StateLayout
from cvtfem.outputs import OutputSpec


#: Names of a pin's coordinates in the column order of a family's ``dof_index``, by coordinates per pin:
#: S1/S2/S3 (``u'`` the S3 end tangent) and the whole-pin A families (``u_0..u_3`` in-plane, ``w_0, w_1`` axial).
PIN_COORDINATES = {2: ("u1", "u2"), 3: ("u1", "u2", "u3"), 5: ("u1", "u2", "u3", "u'1", "u'2"),
                   10: ("u0_1", "u0_2", "u1_1", "u1_2", "u2_1", "u2_2", "u3_1", "u3_2", "w0", "w1")}


def pin_coordinate_label(family, j: int, rate: bool = False) -> str:
    """``"pin 17, u3"`` for coordinate ``j`` of a chain family's ``q`` (``"pin 17, du3/dt"`` for its
    velocity with ``rate``); ``"chain coordinate j"`` where the family has no per-pin index."""
    index = getattr(family, "dof_index", None)
    hit = np.argwhere(index == j) if index is not None else np.empty((0, 2))
    if not len(hit):
        return f"chain coordinate {j}" + (" rate" if rate else "")
    pin, col = (int(c) for c in hit[0])
    names = PIN_COORDINATES.get(index.shape[1])
    name = names[col] if names else f"coordinate {col}"
    return f"pin {pin}, " + (f"d{name}/dt" if rate else name)


def _first_order(dq: sp.csr_matrix, dv: sp.csr_matrix) -> sp.csr_matrix:
    """CSR ``[[0, I], [dq, dv]]`` of ``x = [q, q']`` from the accelerations' blocks (n x n each), built directly
    (``sp.bmat`` passes through COO and costs as much as the blocks themselves here)."""
    dq, dv = sp.csr_matrix(dq), sp.csr_matrix(dv)
    n = dq.shape[0]
    a, b = np.diff(dq.indptr), np.diff(dv.indptr)
    indptr = np.concatenate([np.arange(n + 1), n + np.cumsum(a + b)])
    start = indptr[n:-1]
    pos_q = np.repeat(start - dq.indptr[:-1], a) + np.arange(dq.nnz)
    pos_v = np.repeat(start + a - dv.indptr[:-1], b) + np.arange(dv.nnz)
    indices, data = np.empty(indptr[-1], np.int64), np.empty(indptr[-1])
    indices[:n], data[:n] = n + np.arange(n), 1.0
    indices[pos_q], data[pos_q] = dq.indices, dq.data
    indices[pos_v], data[pos_v] = n + dv.indices, dv.data
    return sp.csr_matrix((data, indices, indptr), shape=(2 * n, 2 * n))


@dataclass(frozen=True, eq=False)
class FreeChain(ModelBase):
    """``M q'' = Q(q, q')`` of a chain family with constant mass matrix, state ``x = [q, q']``.

    Parameters
    ----------
    family : SymmetricChain
        ``ChainS1``, ``ChainS2`` or ``ChainS3`` (``forces``, ``jacobian``, ``mass_matrix``, ``solve_mass``,
        ``energy``, ``rayleigh``, ``outputs``).
    q0 : array (n2,)
        Start coordinates (absolute pin positions, m; S3 also end tangents); start velocity ``v0`` (m/s).
    """

    family: Any
    q0: np.ndarray
    v0: np.ndarray | None = None

    @cached_property
    def layout(self) -> StateLayout:
        return StateLayout(tuple(self.family.blocks))

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        return tuple(self.family.output_specs)

    def initial_state(self) -> np.ndarray:
        v0 = np.zeros_like(self.q0) if self.v0 is None else self.v0
        return np.concatenate([self.q0, v0]).astype(float)

    def _split(self, x):
        n = self.n2
        return x[:n], x[n:]

    def state_label(self, i: int) -> str:
        """What state component ``i`` is, for failure messages: ``"pin 17, u3"`` or ``"pin 17, du3/dt"``."""
        return pin_coordinate_label(self.family, int(i) % self.n2, rate=int(i) >= self.n2)

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[q', M^-1 Q(q, q')]``."""
        q, v = self._split(x)
        return np.concatenate([v, self.family.solve_mass(self.family.forces(q, v))])

    @cached_property
    def _inv_mass(self) -> sp.csr_matrix:
        """``M^-1`` (block-diagonal per pin: its pattern is M's)."""
        M = self.family.mass_matrix().tocsc()
        return sp.csr_matrix(spla.inv(M))

    def jac(self, t: float, x: np.ndarray) -> sp.csr_matrix:
        """Sparse ``[[0, I], [M^-1 dQ/dq, M^-1 dQ/dq']]`` from the family's Jacobian blocks."""
        q, v = self._split(x)
        dq, dv = self.family.jacobian(q, v)
        return _first_order(self._inv_mass @ dq, self._inv_mass @ dv)

    @cached_property
    def jac_sparsity(self) -> sp.csr_matrix:
        """``u' = v`` rows and ``M^-1`` times the family's pattern (pins ``p +- 2``) in the velocity rows."""
        lower = (abs(self._inv_mass) @ sp.csr_matrix(self.family.jac_sparsity, dtype=float)) != 0
        return sp.bmat([[None, sp.identity(self.n2, format="csr")], [lower, lower]], format="csr").astype(bool)

    def outputs(self, t: float, x: np.ndarray) -> dict[str, Any]:
        q, v = self._split(x)
        return self.family.outputs(q, v)

    def linearize(self, x0: np.ndarray) -> Linearization:
        """``M du'' + C du' + K du = 0`` about ``x0``: ``K = -dQ/dq``, ``C = -dQ/dq'``, ``G = 0``."""
        q, v = self._split(x0)
        dq, dv = self.family.jacobian(q, v)
        return Linearization(M=self.family.mass_matrix(), C=-dv, G=sp.csr_matrix(dq.shape), K=-dq)

    def energy(self, x: np.ndarray) -> float:
        """Kinetic plus elastic energy of the chain, J."""
        q, v = self._split(x)
        return float(self.family.energy(q, v))

    def power(self, t: float, x: np.ndarray) -> dict[str, float]:
        """Input power (none: a free chain) and the dissipated power ``2 Phi`` of the Rayleigh forces, W
        (``dE/dt = input - dissipated``)."""
        q, v = self._split(x)
        return {"input": 0.0, "dissipated": 2.0 * float(self.family.rayleigh(q, v))}


@dataclass(frozen=True, eq=False)
class FreeChainA(FreeChain):
    """``M q'' = Q(q, q')`` of an A-family chain (A1, A3, A4: 10 coordinates per pin), state ``x = [q, q']``.

    Parameters
    ----------
    family : ChainA1 | ChainPerPlate
        Offers ``accel`` (per-pin mass solve), ``forces``, ``dissipative_forces``, ``stiffness_matrix``,
        ``damping_matrix``, ``jac_sparsity``, ``mass_matrix``, ``kinetic_energy``, ``potential_energy``,
        ``rayleigh``, ``outputs``; ``ChainPerPlate`` also its ``base`` (the ChainA1 part) and ``jacobians(q, v)``.
    q0, v0 : arrays (10 n,)
        Start coordinates and velocities (layout of ``ChainA1``).

    The Jacobian is the family's exact ``dQ/dq`` of the elastic forces and ``dQ/dq'`` of the dissipative
    ones, with the plates of A3/A4 differentiated within their current states (their damping forces jump
    with the state, a difference across a boundary would not be a derivative), plus the small, smooth
    ``d(Q_d)/dq`` of A1's damping terms at ``q' != 0`` by coloured forward differences over the pattern.
    """

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[q', M^-1 Q(q, q')]``."""
        q, v = self._split(x)
        return np.concatenate([v, self.family.accel(q, v)])

    @cached_property
    def _inv_mass(self) -> sp.csr_matrix:
        M = self.family.mass_matrix.tocsc()
        return sp.csr_matrix(spla.inv(M))

    @cached_property
    def _difference_plan(self) -> tuple[sp.csr_matrix, list]:
        """Pattern (CSR) of the family and, per colour of :func:`color_columns`, its columns and the
        ``(positions in the CSR data, rows, columns)`` of its entries: one forward difference per colour
        without re-deriving these masks each call (``coloured_difference`` does, which is most of its cost)."""
        pattern = sp.csr_matrix(self.family.jac_sparsity, dtype=bool)
        pattern.sort_indices()
        colors = color_columns(pattern)
        rows = np.repeat(np.arange(pattern.shape[0]), np.diff(pattern.indptr))
        plan = []
        for c in range(int(colors.max()) + 1):
            pos = np.flatnonzero(colors[pattern.indices] == c)
            plan.append((np.flatnonzero(colors == c), pos, rows[pos], pattern.indices[pos]))
        return pattern, plan

    def _dissipative_dq(self, smooth, q: np.ndarray, v: np.ndarray) -> sp.csr_matrix:
        """``d(Q_d)/dq`` of ``smooth.dissipative_forces(q, v)`` by coloured forward differences (steps
        ``sqrt(eps) max(|q|, 1)``, as ``coloured_difference``)."""
        pattern, plan = self._difference_plan
        delta = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(q), 1.0)
        delta = (q + delta) - q
        f0 = smooth.dissipative_forces(q, v)
        data = np.empty(pattern.nnz)
        for cols, pos, r, c in plan:
            qp = q.copy()
            qp[cols] += delta[cols]
            data[pos] = (smooth.dissipative_forces(qp, v) - f0)[r] / delta[c]
        return sp.csr_matrix((data, pattern.indices, pattern.indptr), shape=pattern.shape)

    def _blocks(self, q: np.ndarray, v: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``(dQ/dq, dQ/dq')`` of the family's total forces."""
        smooth = getattr(self.family, "base", None)                  # A3/A4: the ChainA1 part, without plates
        if smooth is None:
            smooth, dq, dv = self.family, self.family.stiffness_matrix(q), self.family.damping_matrix(q)
        else:
            dq, dv = self.family.jacobians(q, v)
        if np.any(v):
            dq = dq + self._dissipative_dq(smooth, q, v)
        return sp.csr_matrix(dq), dv

    def jac(self, t: float, x: np.ndarray) -> sp.csr_matrix:
        """Sparse ``[[0, I], [M^-1 dQ/dq, M^-1 dQ/dq']]``."""
        q, v = self._split(x)
        dq, dv = self._blocks(q, v)
        return _first_order(self._inv_mass @ dq, self._inv_mass @ dv)

    def linearize(self, x0: np.ndarray) -> Linearization:
        """``M du'' + C du' + K du = 0`` about ``x0``: ``K = -dQ/dq``, ``C = -dQ/dq'``, ``G = 0``."""
        q, v = self._split(x0)
        dq, dv = self._blocks(q, v)
        return Linearization(M=self.family.mass_matrix, C=-dv, G=sp.csr_matrix(dq.shape), K=-dq)

    def energy(self, x: np.ndarray) -> float:
        """Kinetic plus elastic energy of the chain, J."""
        q, v = self._split(x)
        return self.family.kinetic_energy(v) + self.family.potential_energy(q)
