"""The symmetric chain (S2, S3) with H1 contact on sheave faces that open under the pin forces (issue 20).

Quasi-static faces, as the band models have them (:mod:`cvtfem.elements.sheave_face`): the sheave's modes (4 kHz
and up) lie far above the chain's contact dynamics, so each face takes the static opening of its current loads.
On pulley ``k`` the face opens at pin end ``i`` by ``d_i = sum_j K_ij N_j``,
``K_ij = sum_n c_n(r_ij) cos n (theta_i - theta_j)``, the face compliance of the solid sheave (bore clamped) with
the contacts' angles ``theta`` about the shaft (only differences enter, so the sheave's spin angle drops out) and
``r_ij = (r_i + r_j) / 2`` (the fit is in one radius; the pin ends of an arc differ by tens of um, and the
compliance is exact on the diagonal), radii clamped to the fitted range.  The H1 gap of each end is reduced by its
face's opening, ``Delta = Delta_rigid - d``, and with ``N = c Delta^1.5`` that is an implicit system per pulley and
right-hand side, solved by :func:`~cvtfem.elements.contact.compliant_faces.compliant_penetrations` (damped Newton
on the strictly convex complementary energy: unique forces).  The face's opening enters the contact kernel as an
axial offset of the sheave at that end (input ``z``), so the normal and friction forces, the sheave's axial force
and the outputs follow the true penetration.  The mirror sheave opens alike (symmetric pair).

Left out: the faces' opening rate in the slip velocity (quasi-static), the in-plane force ``N^T dK/dx N / 2`` of
the compliance varying with the pin positions (it vanishes for pins moving rigidly together along an arc), and the
faces' coupling in the right-hand side's Jacobian (``jac`` is the rigid-face kernel's at the deformed gaps; the
quasi-static start adds the coupling, below).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import Any

import numpy as np

from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.contact.compliant_faces import compliant_penetrations
from cvtfem.errors import InputError
from cvtfem.machines.chain_cvt import ChainCVT


@dataclass(frozen=True, eq=False)
class FlexibleChainCVT(ChainCVT):
    """:class:`~cvtfem.machines.chain_cvt.ChainCVT` (H1) on compliant sheave faces.

    Attributes
    ----------
    faces : (FaceCompliance, FaceCompliance)
        Axial face compliance of the driving and the driven pulley's sheaves (m/N).
    """

    faces: tuple = ()
    #: While the quasi-static start solves (:meth:`_solve_balance`): the faces' coupling of the last contact set.
    _coupling: dict = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def on_faces(cls, model: ChainCVT, faces) -> "FlexibleChainCVT":  # noqa: ANN001
        """The rigid-face model ``model`` (chain-S2 or S3 with H1 contact) on the faces ``faces``."""
        if type(model) is not ChainCVT or type(model.contact) is not SheaveContact:
            raise InputError("sheave.flexibility", "reduced", f"must be 'rigid' for {type(model).__name__}: flexible "
                             "faces are built for chain-S2 and chain-S3 with H1 contact ('hertz') only")
        if len(faces) != 2:
            raise InputError("faces", faces, "must be one FaceCompliance per pulley (driving, driven)")
        return cls(**{f.name: getattr(model, f.name) for f in fields(ChainCVT)}, faces=tuple(faces))

    # ----- the faces' opening ------------------------------------------------------------------
    @cached_property
    def _pair_weights(self) -> tuple[np.ndarray, ...]:
        """Per pulley the weights ``B`` (H + 1, D + 1, D + 1) of :meth:`face_matrix`: with ``c_n`` a polynomial
        ``sum_p b_np x^p`` of the mapped radius, ``c_n((x_i + x_j) / 2) = sum_{q+t <= D} B_nqt x_i^q x_j^t``,
        ``B_nqt = b_n,q+t C(q+t, q) 2^-(q+t)``."""
        out = []
        for f in self.faces:
            D = f.coef.shape[1] - 1
            to_power = np.zeros((D + 1, D + 1))                       # Chebyshev T_k -> powers of x
            for k in range(D + 1):
                to_power[k, :k + 1] = np.polynomial.chebyshev.cheb2poly(np.eye(D + 1)[k])[:k + 1]
            b = f.coef @ to_power                                                          # (H + 1, D + 1)
            B = np.zeros((len(b), D + 1, D + 1))
            for q in range(D + 1):
                for t in range(D + 1 - q):
                    B[:, q, t] = b[:, q + t] * math.comb(q + t, q) / 2.0 ** (q + t)
            out.append(B)
        return tuple(out)

    def face_matrix(self, k: int, r, theta) -> np.ndarray:  # noqa: ANN001
        """Influence matrix (m/N) of pulley ``k``'s face between contacts at radii ``r`` (m) and angles ``theta``
        (rad): ``sum_n c_n(r_ij) cos n (theta_i - theta_j)`` with pairs at their mean radius, clamped to the fitted
        range.  As ``sum_n V_n^T B_n V_n`` over ``V_n[q, i] = x_i^q cos n theta_i`` (and ``sin``): no polynomial
        per pair (:attr:`_pair_weights`)."""
        f = self.faces[k]
        H, D = f.coef.shape[0] - 1, f.coef.shape[1] - 1
        if len(r) == 0:
            return np.zeros((0, 0))
        x = (2 * np.clip(np.asarray(r, float), f.r_lo, f.r_hi) - (f.r_lo + f.r_hi)) / (f.r_hi - f.r_lo)
        powers = x[None, :] ** np.arange(D + 1)[:, None]                               # (D + 1, m)
        nt = np.arange(H + 1)[:, None] * np.asarray(theta, float)[None, :]
        B = self._pair_weights[k]
        K = np.zeros((len(x), len(x)))
        for trig in (np.cos(nt), np.sin(nt)):
            V = powers[None, :, :] * trig[:, None, :]                                    # (H + 1, D + 1, m)
            K += V.reshape(-1, len(x)).T @ np.matmul(B, V).reshape(-1, len(x))
        return 0.5 * (K + K.T)

    def face_solution(self, X, shafts) -> dict[str, Any]:
        """Per contact (local inputs ``X``, shafts ``shafts``): rigid-face penetration ``delta_rigid``, true
        penetration ``delta``, face opening ``opening`` (m), force ``N``; per pulley ``K`` (influence matrices),
        ``members`` (contact indices) and ``iterations``."""
        m = len(X)
        arm = X[:, :2] - self.contact.centres[shafts]
        r = np.hypot(arm[:, 0], arm[:, 1])
        theta = np.arctan2(arm[:, 1], arm[:, 0])
        delta_r = np.empty(m)
        for k in (0, 1):
            sel = shafts == k
            delta_r[sel] = self.contact._profiles[k](r[sel])[0] + X[sel, 2] - X[sel, 3]
        delta, N = delta_r.copy(), np.zeros(m)
        out: dict[str, Any] = {"K": [], "members": [], "iterations": []}
        for k in (0, 1):
            idx = np.flatnonzero(shafts == k)
            K = self.face_matrix(k, r[idx], theta[idx])
            delta[idx], N[idx], it = compliant_penetrations(delta_r[idx], K, float(self.contact.c[k]))
            out["K"].append(K)
            out["members"].append(idx)
            out["iterations"].append(it)
        out.update(delta_rigid=delta_r, delta=delta, opening=delta_r - delta, N=N)
        return out

    def _contact_set(self, q, v, details=False):
        """As :meth:`ChainCVT._contact_set`, the sheave input of each contact moved back by its face's opening."""
        ends, shafts = self._candidates(q)
        cols, coef = self._contact_map(ends, shafts)
        X = (coef * np.concatenate([q, v, self._constants])[cols]).sum(axis=2)
        sol = self.face_solution(X, shafts)
        X[:, 3] += sol["opening"]
        if self._coupling.get("on"):
            self._coupling.update(cols=cols, coupling=self._opening_sensitivity(X, shafts, sol))
        return ends, shafts, cols, coef, X, self.contact.local(X, shafts, details)

    def _opening_sensitivity(self, X, shafts, sol) -> list:
        """Per pulley ``(members, T, G)``: ``T = dd/dDelta_rigid = K N' (I + K N')^-1`` (the opening's response to
        the rigid-face penetrations, ``N' = dN/dDelta``) and ``G`` (m_k, 4) the gradient of ``Delta_rigid`` over
        the contact's position inputs (pin end x1 x2 x3, sheave z); the change of ``K`` with the positions is left
        out."""
        arm = X[:, :2] - self.contact.centres[shafts]
        r = np.hypot(arm[:, 0], arm[:, 1])
        out = []
        for k, (idx, K) in enumerate(zip(sol["members"], sol["K"])):
            dN = 1.5 * float(self.contact.c[k]) * np.sqrt(np.maximum(sol["delta"][idx], 0.0))
            T = np.linalg.solve((np.eye(len(idx)) + K * dN[None, :]).T, (K * dN[None, :]).T).T
            fp = self.contact._profiles[k](r[idx])[1]
            G = np.column_stack([fp / r[idx] * arm[idx, 0], fp / r[idx] * arm[idx, 1], np.ones(len(idx)),
                                 -np.ones(len(idx))])
            out.append((idx, T, G))
        return out

    def _contact_entries(self, cols, coef, Jl, n_in: int | None = None):
        """As :meth:`ChainCVT._contact_entries`, plus (in the quasi-static start) the faces' coupling: contact
        ``i``'s forces through its sheave input (column 3) change with every contact ``j`` of its face by
        ``Jl[i, :, 3] T_ij G_j``."""
        r0, c0, v0 = super()._contact_entries(cols, coef, Jl, n_in)
        if self._coupling.get("cols") is not cols:
            return r0, c0, v0
        n_pos = min(4, cols.shape[1] if n_in is None else n_in)
        rows, rw = self._output_rows(cols, coef)
        R, C, V = [r0], [c0], [v0]
        for idx, T, G in self._coupling["coupling"]:
            vals = ((rw[idx, :, 0] * Jl[idx, :-1, 3])[:, :, None, None] * T[:, None, :, None]
                    * G[None, None, :, :n_pos])                              # (i, output, j, input)
            vals = vals * np.where(cols[idx, :n_pos, 0] < 2 * self.n2, coef[idx, :n_pos, 0], 0.0)[None, None]
            shape = vals.shape
            Rr = np.broadcast_to(rows[idx, :, 0][:, :, None, None], shape)
            Cc = np.broadcast_to(cols[idx, :n_pos, 0][None, None], shape)
            keep = vals != 0
            R.append(Rr[keep])
            C.append(Cc[keep])
            V.append(vals[keep])
        return np.concatenate(R), np.concatenate(C), np.concatenate(V)

    def _solve_balance(self, residual, jacobian, y0, tol: float):
        """The quasi-static balance with the faces' coupling in its Jacobian."""
        self._coupling.clear()
        self._coupling["on"] = True
        try:
            return super()._solve_balance(residual, jacobian, y0, tol)
        finally:
            self._coupling.clear()

    def energy(self, x) -> float:
        """Kinetic plus elastic energy with the faces' strain energy ``N^T K N / 2`` of both sheaves of a pair, J."""
        q, v, _, _ = self.split(x)
        ends, shafts = self._candidates(q)
        cols, coef = self._contact_map(ends, shafts)
        X = (coef * np.concatenate([q, v, self._constants])[cols]).sum(axis=2)
        sol = self.face_solution(X, shafts)
        faces = sum(float(sol["N"][i] @ K @ sol["N"][i]) for K, i in zip(sol["K"], sol["members"]))
        return super().energy(x) + faces
