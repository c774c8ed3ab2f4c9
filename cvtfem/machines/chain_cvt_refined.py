"""The chain on two rigid shafts with the refined pin–sheave contact H2 (issue 13, deliverable 3).

:class:`RefinedChainCVT` is :class:`~cvtfem.machines.chain_cvt.ChainCVT` with a
:class:`~cvtfem.elements.chain.sheave_contact_refined.RefinedSheaveContact`: its contacts read the pin's
neighbours (pin spin, twist) and the S3 slope coordinates, so the three layout hooks (local inputs, their
state columns, the rows of the local force outputs) follow the refined contact's layout.  Everything else
(loops, work integrals, Jacobian assembly, the quasi-static start) is ChainCVT's.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.machines.chain_cvt import ChainCVT


def refined_contact(family, centres, face, c, r_outer, f0, v0, law, face_radius,
                    face_inclination=0.0) -> RefinedSheaveContact:
    """The H2 contact of ``family`` (S2 or S3) with the sheave ``face`` on both shafts at ``centres`` (2, 2) m,
    Hertz stiffness ``c`` (N/m^1.5), pin end faces crowned with ``face_radius`` (m), inclined by
    ``face_inclination`` (rad)."""
    return RefinedSheaveContact(centres, (face, face), np.array([c, c]), r_outer, f0, v0, face_radius,
                                family.im1, family.ip1, slopes=family.ndof == 5, law=law,
                                face_inclination=face_inclination)


class RefinedChainCVT(ChainCVT):
    """ChainCVT with H2 contact (``contact`` a :class:`RefinedSheaveContact`)."""

    def _static(self, ratio, w1, F2, tol):
        """ChainCVT's quasi-static start, with the slopes of the S3 pins in contact turning with their sheave
        (``u'' = phi_k' k x u'``): the material at the offset contact point then does not slip."""
        x0, rep = super()._static(ratio, w1, F2, tol)
        if self.contact.slopes:
            nc, iphi, _, _ = self._idx
            q = x0[:self.n2]
            pins, shafts, _, (_, d) = self._contacts(q, np.zeros(self.n2), details=True)
            up = self.family.split(q[:nc])[2]
            upd = self.family.split(x0[self.n2:self.n2 + nc])[2]
            for k in (0, 1):
                on = pins[(shafts == k) & (d["delta"] > 0)]
                upd[on] = x0[self.n2 + iphi[k]] * np.column_stack([-up[on, 1], up[on, 0]])
        return x0, rep

    def outputs(self, t: float, x):
        """ChainCVT's outputs with the support forces from the end forces of the contacts (both mirrored ends):
        the kernel's first outputs are the spin couple on the rear neighbour, not the end force."""
        out = super().outputs(t, x)
        q, v, _, _ = self.split(x)
        _, shafts, _, (_, c) = self._contacts(q, v, details=True)
        out["driving.support_force"], out["driven.support_force"] = (
            np.column_stack([self.sheaves_per_z * np.bincount(shafts, c["F"][:, j], 2) for j in (0, 1)]))
        return out

    def _extra_approach(self, k, r):
        return float(self.contact.extra_approach(k, r))

    def _contact_rows(self, pins, shafts):
        _, iphi, iz, _ = self._idx
        return self.contact.coordinates(pins, shafts, self.family.dof_index, iz, iphi)

    def _contact_columns(self, pins, shafts):
        rows = self._contact_rows(pins, shafts)
        return np.column_stack([rows[:, :-1], self.n2 + rows[:, :-1], self.n2 + rows[:, -1:]])
