"""The symmetric chain (S2, S3) with H1 contact on sheave faces that open under the pin forces (issue 20).

Quasi-static faces, as the band models have them (:mod:`cvtfem.elements.sheave_face`): the sheave's modes (4 kHz
and up) lie far above the chain's contact dynamics, so each face takes the static opening of its current loads.
On pulley ``k`` the face opens at pin end ``i`` by ``d_i = sum_j K_ij N_j``,
``K_ij = sum_n c_n(r_ij) cos n (theta_i - theta_j)``, the face compliance of the solid sheave (bore clamped) with
the contacts' angles ``theta`` about the shaft (only differences enter, so the sheave's spin angle drops out) and
``r_ij = (r_i + r_j) / 2`` (the fit is in one radius; the pin ends of an arc differ by up to 0.4 mm, and the
rule is exact on the diagonal), radii clamped to the fitted range.  The H1 gap of each end is reduced by its
face's opening, ``Delta = Delta_rigid - d``, and with ``N = c Delta^1.5`` that is an implicit system per pulley and
right-hand side, solved by :func:`~cvtfem.elements.contact.compliant_faces.compliant_penetrations` (damped Newton
on the strictly convex complementary energy: unique forces).  The face's opening enters the contact kernel as an
axial offset of the sheave at that end (input ``z``), so the normal and friction forces, the sheave's axial force
and the outputs follow the true penetration.  The mirror sheave opens alike (symmetric pair).

The forces are the gradient of the condensed energy ``min_d [sum 2/5 c (Delta_rigid - d)^2.5 + d^T K^-1 d / 2]``:
the Hertz forces of the true penetrations and, because ``K`` moves with the pins, the in-plane force
``N_i sum_j N_j dK_ij/dx_i`` on each pin end (the normal force on the face tilted by its own opening: a few newtons
per pin, which moves F1/F2 by about two percentage points at ratio 2.4), so the work integrals balance the energy with the faces' strain energy ``N^T K N / 2`` per sheave.  Left out: the
faces' opening rate in the slip velocity (quasi-static) and the faces' coupling in the right-hand side's Jacobian
(``jac`` is the rigid-face kernel's at the deformed gaps; the quasi-static start adds the coupling, below).
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
    _coupling: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    #: No compiled contact path: the faces' opening enters through the numpy contact set (:meth:`_contact_set`).
    _compiled_contact = None

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
    def _pair_weights(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Per pulley the weights ``(B, B_r)`` (each (H + 1, D + 1, D + 1)) of :meth:`face_matrices`: with ``c_n`` a
        polynomial ``sum_p b_np x^p`` of the mapped radius ``x``, ``c_n((x_i + x_j) / 2) = sum_{q+t <= D} B_nqt
        x_i^q x_j^t``, ``B_nqt = b_n,q+t C(q+t, q) 2^-(q+t)``; ``B_r`` the same for ``dc_n/dr`` (m/N per m)."""
        out = []
        for f in self.faces:
            D = f.coef.shape[1] - 1
            to_power = np.zeros((D + 1, D + 1))                       # Chebyshev T_k -> powers of x
            for k in range(D + 1):
                to_power[k, :k + 1] = np.polynomial.chebyshev.cheb2poly(np.eye(D + 1)[k])[:k + 1]
            b = f.coef @ to_power                                                          # (H + 1, D + 1)
            b_r = np.zeros_like(b)
            b_r[:, :-1] = b[:, 1:] * np.arange(1, D + 1) * 2 / (f.r_hi - f.r_lo)
            pair = []
            for poly in (b, b_r):
                B = np.zeros((len(b), D + 1, D + 1))
                for q in range(D + 1):
                    for t in range(D + 1 - q):
                        B[:, q, t] = poly[:, q + t] * math.comb(q + t, q) / 2.0 ** (q + t)
                pair.append(B)
            out.append(tuple(pair))
        return tuple(out)

    def face_matrices(self, k: int, r, theta, derivatives: bool = False):  # noqa: ANN001, ANN201
        """Influence matrix ``K`` (m/N) of pulley ``k``'s face between contacts at radii ``r`` (m) and angles
        ``theta`` (rad): ``K_ij = sum_n c_n(r_ij) cos n (theta_i - theta_j)``, pairs at their mean radius
        ``r_ij``, clamped to the fitted range; computed as ``sum_n V_n^T B_n V_n`` over
        ``V_n[q, i] = x_i^q cos n theta_i`` (and ``sin``), no polynomial per pair (:attr:`_pair_weights`).
        With ``derivatives`` also ``K_r`` (m/N per m), ``sum_n dc_n/dr (r_ij) cos n (theta_i - theta_j)`` (zero
        for a clamped ``r_i``), and ``K_t`` (m/N per rad), ``-sum_n n c_n(r_ij) sin n (theta_i - theta_j)``."""
        f = self.faces[k]
        H, D = f.coef.shape[0] - 1, f.coef.shape[1] - 1
        m = len(r)
        r = np.asarray(r, float)
        x = (2 * np.clip(r, f.r_lo, f.r_hi) - (f.r_lo + f.r_hi)) / (f.r_hi - f.r_lo)
        powers = x[None, :] ** np.arange(D + 1)[:, None]                               # (D + 1, m)
        nt = np.arange(H + 1)[:, None] * np.asarray(theta, float)[None, :]
        B, B_r = self._pair_weights[k]
        Vc = (powers[None, :, :] * np.cos(nt)[:, None, :]).reshape((H + 1) * (D + 1), m)
        Vs = (powers[None, :, :] * np.sin(nt)[:, None, :]).reshape(Vc.shape)

        def weighted(W, V):  # noqa: ANN001, ANN202
            return np.matmul(W, V.reshape(H + 1, D + 1, m)).reshape(V.shape)
        K = Vc.T @ weighted(B, Vc) + Vs.T @ weighted(B, Vs)
        K = 0.5 * (K + K.T)
        if not derivatives:
            return K
        inside = (r >= f.r_lo) & (r <= f.r_hi)
        K_r = (Vc.T @ weighted(B_r, Vc) + Vs.T @ weighted(B_r, Vs)) * inside[:, None]
        n = np.repeat(np.arange(H + 1), D + 1)[:, None]
        K_t = -(Vs.T @ weighted(B, n * Vc) - Vc.T @ weighted(B, n * Vs))
        return K, K_r, 0.5 * (K_t - K_t.T)

    def face_matrix(self, k: int, r, theta) -> np.ndarray:  # noqa: ANN001
        """The influence matrix ``K`` of :meth:`face_matrices`, m/N."""
        return self.face_matrices(k, r, theta)

    def face_solution(self, X, shafts) -> dict[str, Any]:
        """Per contact (local inputs ``X``, shafts ``shafts``): rigid-face penetration ``delta_rigid``, true
        penetration ``delta``, face opening ``opening`` (m), force ``N``, and ``in_plane`` (m, 2) the in-plane force
        on one pin end of the compliance varying with the pin positions, ``N_i sum_j N_j dK_ij/dx_i`` (N: the
        condensed energy's gradient beyond the Hertz forces'); per pulley ``K`` (influence matrices), ``members``
        (contact indices) and ``iterations``."""
        m = len(X)
        arm = X[:, :2] - self.contact.centres[shafts]
        r = np.hypot(arm[:, 0], arm[:, 1])
        theta = np.arctan2(arm[:, 1], arm[:, 0])
        delta_r = np.empty(m)
        for k in (0, 1):
            sel = shafts == k
            delta_r[sel] = self.contact._profiles[k](r[sel])[0] + X[sel, 2] - X[sel, 3]
        delta, N, in_plane = delta_r.copy(), np.zeros(m), np.zeros((m, 2))
        out: dict[str, Any] = {"K": [], "members": [], "iterations": []}
        for k in (0, 1):
            idx = np.flatnonzero(shafts == k)
            K, K_r, K_t = self.face_matrices(k, r[idx], theta[idx], derivatives=True)
            delta[idx], N[idx], it = compliant_penetrations(delta_r[idx], K, float(self.contact.c[k]))
            Nk = N[idx]
            Q_r, Q_t = 0.5 * Nk * (K_r @ Nk), Nk * (K_t @ Nk)                # dK_ij/dr_i = K_r,ij / 2
            e_r = arm[idx] / r[idx, None]
            in_plane[idx] = Q_r[:, None] * e_r + (Q_t / r[idx])[:, None] * np.column_stack([-e_r[:, 1], e_r[:, 0]])
            out["K"].append(K)
            out["members"].append(idx)
            out["iterations"].append(it)
        out.update(delta_rigid=delta_r, delta=delta, opening=delta_r - delta, N=N, in_plane=in_plane)
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
        Y = self.contact.local(X, shafts, details)
        (Y[0] if details else Y)[:, :2] += 2 * sol["in_plane"]            # both pin ends (mirror pair)
        return ends, shafts, cols, coef, X, Y

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


#: Margin of the faces' fitted radii beyond the scene's contact range, m: the chain's pins seat up to half a
#: millimetre beyond ``r_max`` on the driven arc.
RADIUS_MARGIN = 3e-3


def flexible_faces_model(scene, model):  # noqa: ANN001, ANN201
    """``model`` (built from a CVT ``scene`` with ``[sheave] flexibility = "reduced"``) on the scene's flexible
    sheave faces (:func:`~cvtfem.machines.sheave.cvt_sheave_section`, ``sheave.harmonics``, the section mesh),
    fitted over ``r_min - RADIUS_MARGIN .. r_max + RADIUS_MARGIN`` within the face; InputError naming
    ``sheave.flexibility`` for a model other than chain-S2/S3 with H1 contact on rigid shafts, or ``"full"``."""
    from cvtfem.elements.sheave_face import PATCH_WIDTH, face_compliance
    from cvtfem.machines.sheave import cvt_sheave_section

    opts, g = scene.sheave, scene.cvt.geometry
    if opts.flexibility != "reduced" or type(model) is not ChainCVT or type(model.contact) is not SheaveContact:
        raise InputError("sheave.flexibility", opts.flexibility,
                         f"must be 'rigid' for `{scene.cvt.model}` with contact '{scene.cvt.effects.contact}': "
                         "flexible faces ('reduced') run chain-S2 and chain-S3 with H1 contact ('hertz') on rigid "
                         "shafts only")
    section = cvt_sheave_section(scene)
    lo = max(g.r_min - RADIUS_MARGIN, section.hub_radius + PATCH_WIDTH / 2)
    hi = min(g.r_max + RADIUS_MARGIN, section.outer_radius - PATCH_WIDTH / 2)
    faces = face_compliance(section, lo, hi, opts.harmonics, (opts.cells_radial, opts.cells_axial))
    return FlexibleChainCVT.on_faces(model, (faces, faces))
