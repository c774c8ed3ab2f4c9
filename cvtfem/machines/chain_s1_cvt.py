"""The S1 chain on two rigid shafts: :class:`ChainS1CVT`, the transmission of
:class:`~cvtfem.machines.chain_cvt.ChainCVT` with the rigid contact of S1 (its pin ends follow the sheave faces,
:class:`~cvtfem.elements.chain.sheave_contact_rigid.RigidSheaveContact`).

S1 has two coordinates per pin (in-plane position, mass lumped at the pin middle): the input slot of the pin-end
axial position in the contact map reads the pin's axial stiffness from a constant column, the slot of its rate a
constant zero (chain-models-1 §2.2: ``u3`` is not a coordinate of S1).
"""
from __future__ import annotations

from functools import cached_property

import numpy as np

from cvtfem.machines.chain_cvt import ChainCVT


class ChainS1CVT(ChainCVT):
    """chain-S1 + rigid contact + two rigid shafts + regime + loops (state layout of :class:`ChainCVT` without the
    pins' axial coordinates)."""

    @cached_property
    def _constants(self) -> np.ndarray:
        """``[c_p (n,), 0]``: the pins' axial stiffness (N/m) and a zero, appended to ``[q, v]``."""
        return np.concatenate([self.family.geom.c_pin, [0.0]])

    def _contact_columns(self, pins, shafts):
        """Columns of the 9 local inputs: in-plane position, ``c_p`` (constant), ``z``, in-plane velocity, 0
        (constant), ``z'``, spin rate."""
        _, iphi, iz, dof = self._idx
        n2 = self.n2
        c_p, zero = 2 * n2 + pins, np.full(len(pins), 2 * n2 + self.family.n)
        return np.column_stack([dof[pins, 0], dof[pins, 1], c_p, iz[shafts], n2 + dof[pins, 0], n2 + dof[pins, 1],
                                zero, n2 + iz[shafts], n2 + iphi[shafts]])

    def pin_end_axial(self, q_chain, z) -> np.ndarray:
        """Axial positions (n,) m of the pins' ``x3 > 0`` ends at chain coordinates ``q_chain`` and sheave positions
        ``z`` (2,) m: ``l/2``, or the face ``z_k + s(r)`` where it lies inside the free end (the dependent
        coordinate)."""
        u, con = self.pin_positions(q_chain), self.contact
        x3 = np.full(self.family.n, con.half_length)
        for k in (0, 1):
            r = np.linalg.norm(u - con.centres[k], axis=1)
            near = r < con.r_outer
            face = z[k] - con._profiles[k](r[near])[0]
            x3[near] = np.minimum(x3[near], face)
        return x3
