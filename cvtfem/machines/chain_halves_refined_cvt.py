"""Variant (e) on rigid shafts: the chain with independent pin halves (A5) whose half ends touch the sheaves with
the refined contact H2 (Table 1.1 (e) with rigid instead of elastic shafts; contact digest §5.5 "independent
halves"): :class:`ChainHalvesRefinedCVT`.

Everything but the contact is :class:`~cvtfem.machines.chain_halves_cvt.ChainHalvesCVT`'s: 21 coordinates per
pin, four contact ends per pin (``e = 4 p + 2 h + s``: half ``h`` 0 = ``p-``, 1 = ``p+``; side ``s`` 0 = ``x3 < 0``,
1 = ``x3 > 0``), each half end on the sheave on its side of each shaft, a fixed and a movable sheave per shaft.
Each half end has its own crowned (biconvex) face, crown radius ``face_radius``; its contact is the H2 kernel of
variant (a) at the half's own end (:class:`~cvtfem.elements.chain.half_end_contact.HalfEndContact`).  Its inputs
are linear in the coordinates, as A1's (:meth:`ChainACVT._refined_positions`): the half end ``u_0 + s u_1``, the
chord of the half's link (``u+_{p+1,0} - u-_{p,0}`` for ``p-``, ``u+_{p,0} - u-_{p-1,0}`` for ``p+``), ``x3 = s w_0 +
w_1`` and the end slope ``s (2/l u_1 + u_2|3) / END_SLOPE_FACTOR`` of the half, in the mirrored frame of the end; so
the forces act back through the same contact map of ChainCVT: the normal forces are the exact gradient of the
Hertz potential, the friction power the exact work rate.
"""
from __future__ import annotations

from dataclasses import replace
from functools import cached_property

import numpy as np

from cvtfem.elements.chain import half_end_contact_kernel as HEK
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.half_end_contact import HalfEndContact
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.jit import HAVE_NUMBA
from cvtfem.errors import InputError, NumericalError
from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT


class ChainHalvesRefinedCVT(ChainHalvesCVT):
    """A5 on two rigid shafts with H2 at both ends of every pin half (variant (e) on rigid shafts).

    The contact pass and its Jacobian run compiled over ChainCVT's pair table
    (:mod:`~cvtfem.elements.chain.half_end_contact_kernel`, as H1's :mod:`sheave_contact_kernel`); ChainCVT's numpy
    path (``reference=True``, and for the mean slip of ``evaluate(slip=True)``) is their tested twin."""

    _contact_kernel = HEK          # ChainCVT's compiled contact Jacobian runs this module's kernel

    @cached_property
    def _compiled_contact(self) -> tuple | None:
        """Constants of :mod:`~cvtfem.elements.chain.half_end_contact_kernel` (None without numba)."""
        return HEK.pack(self.contact.pair, 0.5) if HAVE_NUMBA else None

    def _contact_forces(self, q, v, Q, slip: bool = False, reference: bool = False):
        """ChainCVT's contact forces (the friction power, W, and with ``slip`` the mean slip speed per shaft, m/s),
        compiled unless ``reference`` or ``slip`` (the mean slip comes from the numpy path's details)."""
        ck = self._compiled_contact
        if reference or slip or ck is None:
            return super()._contact_forces(q, v, Q, slip, reference=True)
        Pf, bad = HEK.forces(np.concatenate([q, v, self._constants]), *self._pair_table, *ck, Q)
        if bad >= 0:
            raise NumericalError(f"H2 contact: a pin-half end on the shaft axis (pair {bad})",
                                 component="contact.refined")
        return Pf, None

    def _link_chords(self, ends, d):
        """``(front, rear)`` (m, 2) coordinate positions of the ``u_0`` of the two halves of each end's link: ``p-``
        with ``(p+1)+``, ``(p-1)-`` with ``p+`` (chain-models-2 §5.1)."""
        fam = self.family
        pins, plus = self.pin_of(ends), ((ends // 2) % 2 == 1)[:, None]
        rear = np.where(plus, fam.dof_index[(pins - 1) % fam.n, 0:2], d[:, 0:2])
        front = np.where(plus, d[:, 0:2], fam.dof_index[fam.ip1[pins], 10:12])
        return front, rear

    def _refined_positions(self, ends, d, side):
        """:class:`HalfEndContact`'s position inputs as ``(column a, column b, weight a, weight b)``: the half end
        ``u_0 + s u_1``, its link chord, ``x3 = s w_0 + w_1`` and the end slope (far end ``s = -1``: ``u_2``, near
        ``u_3``) in the mirrored frame, over ``END_SLOPE_FACTOR``."""
        front, rear = self._link_chords(ends, d)
        one = np.ones(len(ends))
        bend = np.where(side[:, None] > 0, d[:, 6:8], d[:, 4:6])
        k = side / END_SLOPE_FACTOR
        kl = 2 / self.family.geom.l * k
        return [(d[:, 0], d[:, 2], one, side), (d[:, 1], d[:, 3], one, side),
                (front[:, 0], rear[:, 0], one, -one), (front[:, 1], rear[:, 1], one, -one),
                (d[:, 8], d[:, 9], side, one),
                (d[:, 2], bend[:, 0], kl, k), (d[:, 3], bend[:, 1], kl, k)]

    @classmethod
    def from_parameters(cls, geom, *, contact: str = "hertz-refined", face_radius: float = 0.02,
                        **kw) -> "ChainHalvesRefinedCVT":
        """:meth:`ChainHalvesCVT.from_parameters` with H2 at every half end (crown radius ``face_radius``, m);
        ``contact`` must be ``"hertz-refined"`` and the model ``chain-A5`` (``chain-A5-point`` is the point contact
        of variant (zh))."""
        if contact != "hertz-refined":
            raise InputError("cvt.effects.contact", contact, "must be 'hertz-refined' for ChainHalvesRefinedCVT "
                             "(variant (e)); the point contact is ChainHalvesCVT")
        if kw.get("model", "chain-A5") != "chain-A5":
            raise InputError("cvt.model", kw.get("model"), "must be 'chain-A5' with the refined contact "
                             "('chain-A5-point' is the contact at the half axis, variant (zh))")
        kw["model"] = "chain-A5"
        model = super().from_parameters(geom, contact="hertz", face_radius=face_radius, **kw)
        h1, fam = model.contact.pair, model.family
        h2 = RefinedSheaveContact(h1.centres, h1.faces, h1.c, h1.r_outer, h1.f0, h1.v0, face_radius,
                                  (np.arange(fam.n) - 1) % fam.n, fam.ip1, slopes=True, law=h1.law, eps=h1.eps,
                                  face_inclination=kw.get("face_inclination", 0.0))
        return replace(model, contact=EndContact(HalfEndContact(h2)))._settled()
