"""The compiled mapped-contact path of the chains on elastic shafts: :class:`CompiledMappedContacts`, the part of
:class:`~cvtfem.machines.chain_cvt_elastic.ElasticChainCVT` that runs the contacts in the sheave frames through
:mod:`~cvtfem.elements.chain.mapped_contact_kernel` (the pair table built once, the kernel constants, forces and
Jacobian entries); ElasticChainCVT's numpy path (``mapped_local``, ``reference=True``) is its tested twin."""
from __future__ import annotations

from functools import cached_property

import numpy as np

from cvtfem.elements.chain import mapped_contact_kernel as MCK
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.jit import HAVE_NUMBA
from cvtfem.errors import NumericalError


def difference_steps(n_pos: int) -> np.ndarray:
    """Central-difference steps of a mapped contact's inputs: positions 1e-9 m (rad), rates 1e-6 m/s, spin 1e-5 rad/s."""
    return np.concatenate([np.full(n_pos, 1e-9), np.full(n_pos, 1e-6), [1e-5]])


class CompiledMappedContacts:
    """Mixin of ElasticChainCVT (reads its pair map ``_pairs_map``, output rows, sides, structure, face references)."""

    @cached_property
    def _mapped_table(self) -> tuple:
        """``(cols, coef, shafts, sheaves, rows, weights)`` of the mapped contact of every ``(end, shaft)`` pair (the
        contact map and output rows, built once): the table the compiled path loops over."""
        _, k, j, cols, coef = self._pairs_map(*self._all_pairs())
        rows, w = self._output_rows(cols, coef)
        return tuple(np.ascontiguousarray(a, t) for a, t in ((cols, np.int64), (coef, float), (k, np.int64),
                                                               (j, np.int64), (rows, np.int64), (w, float)))

    def _mapped_kernel(self):
        """The pair kernel the compiled path runs: H1's :class:`SheaveContact` (the symmetric chain's, or single ends'
        in ``EndContact``), or None (other kernels: the numpy path)."""
        pair = self.contact.pair if isinstance(self.contact, EndContact) else self.contact
        return pair if type(pair) is SheaveContact else None

    @cached_property
    def _compiled_mapped(self) -> tuple | None:
        """Constants of :mod:`~cvtfem.elements.chain.mapped_contact_kernel` for :meth:`_mapped_kernel`; None without
        numba or a kernel (the numpy path)."""
        pair = self._mapped_kernel()
        if not HAVE_NUMBA or pair is None:
            return None
        single = isinstance(self.contact, EndContact)
        return MCK.pack_point(pair, self._sides, self.structure.sheave_x3, self.face_ref, 0.5 if single else 1.0,
                              self.kernel_share, self.axial_relative)

    def _compiled_mapped_forces(self, q, v, Q) -> float:
        """Add the mapped contacts' generalized forces to ``Q`` (n2,) compiled; return the friction power (W)."""
        Pf, bad = MCK.forces(np.concatenate([q, v]), *self._mapped_table, *self._compiled_mapped, Q)
        self._raise_on_axis(bad)
        return Pf

    def _compiled_contact_jacobian(self, q, v):
        """``((rows, cols, values), dD)``: the entries of ``dQ/dy`` of the mapped contacts (``y = [q, v]``) and
        ``-d P_fr / dy`` (2 n2,), compiled (central differences with :func:`difference_steps`)."""
        table = self._mapped_table
        cols, rows = table[0], table[4]
        size = cols.shape[0] * rows.shape[1] * cols.shape[1] * cols.shape[2] ** 2
        r, c, d = np.empty(size, np.int64), np.empty(size, np.int64), np.empty(size)
        dD = np.zeros(2 * self.n2)
        steps = difference_steps((cols.shape[1] - 1) // 2)
        k, bad = MCK.jacobian(np.concatenate([q, v]), *table, *self._compiled_mapped, steps, 2 * self.n2, r, c, d, dD)
        self._raise_on_axis(bad)
        return (r[:k], c[:k], d[:k]), dD

    @staticmethod
    def _raise_on_axis(bad: int) -> None:
        if bad >= 0:
            raise NumericalError(f"H2 contact on elastic shafts: a pin end on the shaft axis (pair {bad})",
                                 component="contact.refined")
