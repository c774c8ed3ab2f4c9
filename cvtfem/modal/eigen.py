"""Modes of ``M q'' + (C + Omega G) q' + K q = 0`` at a spin speed Omega (spec §12.7).

Two scipy backends solve the gyroscopic quadratic eigenproblem through its
first-order companion form ``A z = lambda B z`` with ``z = [q, q']``,
``A = [[0, I], [-K, -D]]``, ``B = diag(I, M)``, ``D = C + Omega G``:

* ``dense``: the DOFs split into independent blocks (connected components of
  the sparsity of M + K + C + G: e.g. lateral, axial, torsion); per block
  ``M^{-1} K``, ``M^{-1} C``, ``M^{-1} G`` are formed once (one Cholesky
  factorisation reused for every speed), the state matrix goes to LAPACK
  ``geev``, and blocks without gyroscopic coupling are solved only once;
* ``sparse``: ARPACK (``scipy.sparse.linalg.eigs``) in shift-invert mode with a
  real shift ``sigma < 0``; applying ``(A - sigma B)^{-1} B`` needs only the
  sparse LU of the n x n matrix ``K + sigma D + sigma^2 M``.

``slepc`` (optional, :mod:`cvtfem.modal.slepc_backend`) solves the same problem
with SLEPc's PEP solver.  Eigenvalues with ``|Im lambda|`` below a threshold
(rigid-body and overdamped modes, spec §12.7) are discarded.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from cvtfem.errors import InputError, NumericalError
from cvtfem.modal.whirl import circularize, classify

#: Models up to this many DOF are solved densely by ``method="auto"``.
DENSE_LIMIT = 600
#: Eigenvalues with |Im| below this fraction of the frequency scale count as non-oscillatory.
ZERO_RTOL = 1e-7


@dataclass(frozen=True)
class Modes:
    """Modes at one speed, ascending in damped frequency.

    Attributes
    ----------
    speed : float, rad/s
    eigenvalues : complex array (k,)
        ``lambda = -zeta wn + i wd`` with ``wd > 0``, 1/s.
    shapes : complex array (n, k)
        Displacement part of the eigenvectors (unit max-modulus).
    whirl : tuple of str
        "forward", "backward", "torsional" or "axial".
    whirl_ratio : array (k,)
        +1 circular forward ... -1 circular backward.
    """

    speed: float
    eigenvalues: np.ndarray
    shapes: np.ndarray
    whirl: tuple[str, ...]
    whirl_ratio: np.ndarray = field(repr=False)

    @property
    def wn(self) -> np.ndarray:
        """Undamped natural frequencies ``|lambda|``, rad/s."""
        return np.abs(self.eigenvalues)

    @property
    def wd(self) -> np.ndarray:
        """Damped natural frequencies ``Im lambda``, rad/s."""
        return self.eigenvalues.imag

    @property
    def damping_ratio(self) -> np.ndarray:
        """``-Re lambda / |lambda|``."""
        return -self.eigenvalues.real / np.abs(self.eigenvalues)

    @property
    def log_dec(self) -> np.ndarray:
        """Logarithmic decrement ``2 pi zeta / sqrt(1 - zeta^2)``."""
        z = np.clip(self.damping_ratio, -0.999999, 0.999999)
        return 2 * np.pi * z / np.sqrt(1 - z**2)

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary (one entry per mode)."""
        return {"speed_rad_s": float(self.speed), "wn_rad_s": self.wn.tolist(), "wd_rad_s": self.wd.tolist(),
                "damping_ratio": self.damping_ratio.tolist(), "log_dec": self.log_dec.tolist(),
                "whirl": list(self.whirl), "whirl_ratio": self.whirl_ratio.tolist()}


class ModalProblem:
    """A linear rotor ``(M, K, C, G)`` prepared for repeated solves over speeds.

    Parameters
    ----------
    M, K, C, G : sparse or dense (n, n)
        Mass (SPD), stiffness, damping, gyroscopic per unit speed.
    dof_kind : int array (n,)
        Node-DOF kind 0..5 of every DOF (``u1 u2 u3 theta1 theta2 phi``).
    method : {"auto", "dense", "sparse", "slepc"}
    damped : bool
        False drops C (undamped analysis; G is kept).
    """

    def __init__(self, M, K, C, G, dof_kind: np.ndarray, method: str = "auto", damped: bool = True) -> None:
        if method not in ("auto", "dense", "sparse", "slepc"):
            raise InputError("method", method, "must be 'auto', 'dense', 'sparse' or 'slepc'")
        self.M, self.K, self.G = (sp.csr_matrix(x) for x in (M, K, G))
        self.C = sp.csr_matrix(C) if damped else sp.csr_matrix(self.M.shape)
        self.n = self.M.shape[0]
        self.kind = np.asarray(dof_kind)
        self.mdiag = self.M.diagonal()
        self.method = ("dense" if self.n <= DENSE_LIMIT else "sparse") if method == "auto" else method
        kd = np.abs(self.K.diagonal())
        self.scale = float(np.sqrt(kd.max() / self.mdiag[self.mdiag > 0].min())) if kd.max() > 0 else 1.0
        self._dense = None

    def _dense_blocks(self) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]]:
        """Independent DOF blocks with ``(dofs, M^-1 K, M^-1 C, M^-1 G or None)`` (Cholesky once)."""
        if self._dense is None:
            pattern = abs(self.M) + abs(self.K) + abs(self.C) + abs(self.G)
            n_blocks, label = connected_components(pattern, directed=False)
            self._dense = []
            for b in range(n_blocks):
                dofs = np.flatnonzero(label == b)
                sub = [X[dofs][:, dofs].toarray() for X in (self.M, self.K, self.C, self.G)]
                try:
                    cho = sla.cho_factor(sub[0])
                except np.linalg.LinAlgError:
                    raise NumericalError("mass matrix is not positive definite (a DOF without inertia?)",
                                         component="modal.dense") from None
                MK, MC = sla.cho_solve(cho, sub[1]), sla.cho_solve(cho, sub[2])
                MG = sla.cho_solve(cho, sub[3]) if np.any(sub[3]) else None
                self._dense.append((dofs, MK, MC, MG))
            self._cache: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        return self._dense

    def solve(self, speed: float, n_modes: int, sigma: float | None = None) -> Modes:
        """Lowest ``n_modes`` oscillatory modes at ``speed`` (rad/s)."""
        if n_modes < 1:
            raise InputError("n_modes", n_modes, "must be >= 1")
        if self.method == "dense":
            lam, Z = self._solve_dense(speed)
        elif self.method == "sparse":
            lam, Z = self._solve_sparse(speed, n_modes, sigma)
        else:
            from cvtfem.modal.slepc_backend import solve_pep

            lam, Z = solve_pep(self.M, self.K, self.C + speed * self.G, n_modes, sigma)
        return self._finish(speed, lam, Z, n_modes)

    def _solve_dense(self, speed: float) -> tuple[np.ndarray, np.ndarray]:
        lams, vecs = [], []
        for b, (dofs, MK, MC, MG) in enumerate(self._dense_blocks()):
            if MG is None and b in self._cache:  # speed-independent block: reuse
                lam, Z = self._cache[b]
            else:
                m = len(dofs)
                A = np.zeros((2 * m, 2 * m))
                A[:m, m:] = np.eye(m)
                A[m:, :m] = -MK
                A[m:, m:] = -MC if MG is None else -(MC + speed * MG)
                lam, Zb = sla.eig(A, overwrite_a=True, check_finite=False)
                keep = lam.imag > 0
                lam, Z = lam[keep], np.zeros((self.n, keep.sum()), dtype=complex)
                Z[dofs] = Zb[:m, keep]
                if MG is None:
                    self._cache[b] = (lam, Z)
            lams.append(lam)
            vecs.append(Z)
        return np.concatenate(lams), np.concatenate(vecs, axis=1)

    def _solve_sparse(self, speed: float, n_modes: int, sigma: float | None) -> tuple[np.ndarray, np.ndarray]:
        n = self.n
        s = -1e-3 * self.scale if sigma is None else float(sigma)
        D = (self.C + speed * self.G).tocsc()
        P = (self.K + s * D + s * s * self.M).tocsc()
        try:
            lu = spla.splu(P)
        except RuntimeError as err:
            raise NumericalError(f"shift-invert factorisation failed at sigma = {s:g} ({err})",
                                 component="modal.sparse") from None
        DsM = (D + s * self.M).tocsr()
        M = self.M

        def op(w: np.ndarray) -> np.ndarray:
            a, b = w[:n], M @ w[n:]
            x = -lu.solve(b + DsM @ a)
            return np.concatenate([x, a + s * x])

        k = min(2 * n_modes + 10, 2 * n - 2)
        A = spla.LinearOperator((2 * n, 2 * n), matvec=op, dtype=float)
        try:
            mu, Z = spla.eigs(A, k=k, which="LM", ncv=min(2 * n, max(2 * k + 1, 40)), tol=1e-12)
        except spla.ArpackNoConvergence as err:
            raise NumericalError(f"ARPACK did not converge at Omega = {speed:g} rad/s ({err})",
                                 component="modal.sparse") from None
        return s + 1.0 / mu, Z[:n]

    def _finish(self, speed: float, lam: np.ndarray, X: np.ndarray, n_modes: int) -> Modes:
        if not np.all(np.isfinite(lam)):
            raise NumericalError("non-finite eigenvalues", component="modal")
        keep = lam.imag > ZERO_RTOL * self.scale
        lam, X = lam[keep], X[:, keep]
        order = np.argsort(lam.imag)[:n_modes + 2]
        lam, X = lam[order], X[:, order]
        if len(lam) < n_modes:
            raise NumericalError(f"found only {len(lam)} oscillatory modes, {n_modes} requested",
                                 component="modal")
        X = circularize(lam, X, self.kind, self.mdiag)
        peak = X[np.argmax(np.abs(X), axis=0), np.arange(X.shape[1])]
        X = X / peak
        labels, ratio = classify(X, self.mdiag, self.kind)
        # repeated frequencies (clusters): backward before forward, the order they take for Omega > 0
        cluster = np.concatenate([[0], np.cumsum(np.diff(lam.imag) > 1e-7 * lam.imag[1:])])
        order = np.lexsort((ratio, cluster))[:n_modes]
        lam, X, ratio = lam[order], X[:, order], ratio[order]
        labels = [labels[i] for i in order]
        return Modes(float(speed), lam, X, tuple(labels), ratio)


def solve_modes(M, K, C, G, speed: float, n_modes: int, dof_kind: np.ndarray,
                method: str = "auto", damped: bool = True) -> Modes:
    """One-shot :meth:`ModalProblem.solve` (see there)."""
    return ModalProblem(M, K, C, G, dof_kind, method, damped).solve(speed, n_modes)
