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

from contextlib import nullcontext
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from cvtfem.blas import arpack_start
from cvtfem.errors import InputError, NumericalError
from cvtfem.modal.whirl import circularize, classify, mac

#: ``method="auto"`` solves a block densely when it has at most ``DENSE_PER_MODE (n_modes + 5)`` DOF, else by
#: sparse shift-invert: dense costs ~m^3 whatever the modes asked, sparse ~m (n_modes + 5). Measured crossover
#: (studies/rotor/bench_backend.py, one solve of a damped gyroscopic shaft): 44 lateral DOF about even, 84 DOF
#: sparse 1.6-2x faster for 6-12 modes, dense still 1.4x faster for 24 modes; 4 puts the switch at 44, 68 and
#: 116 DOF for 6, 12 and 24 modes. (Before: dense up to 600 DOF, 10-50x slower on 160-600 DOF blocks.)
DENSE_PER_MODE = 4
#: Dense: eigenvalues with Im below this fraction of the block's largest |lambda| count as non-oscillatory
#: (a rigid-body Jordan pair is perturbed by about sqrt(eps) |lambda|_max).
ZERO_RTOL = 1e-6
#: Sparse/slepc: the same, as a fraction of the largest |lambda| computed (the band of interest).
SPARSE_ZERO = 1e-4
#: |whirl ratio| below this is a planar mode; at zero speed its label comes from the speed
#: PLANAR_SPEED x (highest frequency found), rad/s.
PLANAR = 1e-6
PLANAR_SPEED = 1e-6
#: Default shift of the sparse backend, rad/s: a real shift below the lowest frequency of interest keeps
#: the shift-inverted spectrum well separated (|lambda - sigma| grows with the frequency).
SIGMA = 1.0
#: ARPACK restarts before the sparse backend gives up with a NumericalError (shift-invert converges in tens;
#: scipy's default, 10 x the size, let a pathological model run for hours).
ARPACK_RESTARTS = 300
#: Relative real parts below this count as round-off in undamped problems.
ROUNDOFF = 1e-9


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
        return -self.eigenvalues.real / np.abs(self.eigenvalues) + 0.0

    @property
    def log_dec(self) -> np.ndarray:
        """Logarithmic decrement ``2 pi zeta / sqrt(1 - zeta^2)``."""
        z = np.clip(self.damping_ratio, -0.999999, 0.999999)
        return 2 * np.pi * z / np.sqrt(1 - z**2)

    def to_dict(self, shapes: bool = False) -> dict[str, object]:
        """JSON-ready summary (one entry per mode); ``shapes=True`` adds the mode shapes.

        Shapes are ``shape_real`` / ``shape_imag``: per mode a list of nodes, each
        ``[u1, u2, u3, theta1, theta2, phi]`` (normalised to unit peak modulus).
        """
        out: dict[str, object] = {
            "speed_rad_s": float(self.speed), "wn_rad_s": self.wn.tolist(), "wd_rad_s": self.wd.tolist(),
            "damping_ratio": self.damping_ratio.tolist(), "log_dec": self.log_dec.tolist(),
            "whirl": list(self.whirl), "whirl_ratio": self.whirl_ratio.tolist()}
        if shapes:
            X = self.shapes.T.reshape(self.shapes.shape[1], -1, 6)
            out["shape_real"], out["shape_imag"] = X.real.tolist(), X.imag.tolist()
        return out


class ModalProblem:
    """A linear rotor ``(M, K, C, G)`` prepared for repeated solves over speeds.

    Parameters
    ----------
    M, K, C, G : sparse or dense (n, n)
        Mass (SPD), stiffness, damping, gyroscopic per unit speed.
    dof_kind : int array (n,)
        Node-DOF kind 0..5 of every DOF (``u1 u2 u3 theta1 theta2 phi``).
    method : {"auto", "dense", "sparse", "slepc"}
        "auto" picks dense for blocks up to ``DENSE_PER_MODE (n_modes + 5)`` DOF (:data:`DENSE_PER_MODE`),
        sparse above; :attr:`method` then tells the backends the last solve used.
    damped : bool
        False drops C (undamped analysis; G is kept).
    blas_threads : int or None
        BLAS threads during solves (via threadpoolctl when installed); None leaves
        the library default.  1 by default: these blocks are small, and on a
        shared 2-core machine multi-threaded OpenBLAS was measured 10-25x slower
        (96 x 96 ``geev``: 0.43 s with 2 threads under load vs 0.018 s with 1).
    speed_terms : callable or None
        Speed-dependent supports: ``speed_terms(speed) -> (dK, dC)`` (sparse (n, n)) added to K and C at each
        speed, with ``speed_terms.pattern`` (sparse) where they may be non-zero and ``speed_terms.damped``
        (e.g. :attr:`cvtfem.machines.rotor.RotorModel.speed_terms`). Blocks they touch are re-solved per speed.
    """

    def __init__(self, M, K, C, G, dof_kind: np.ndarray, method: str = "auto", damped: bool = True,
                 blas_threads: int | None = 1, speed_terms=None) -> None:
        if method not in ("auto", "dense", "sparse", "slepc"):
            raise InputError("method", method, "must be 'auto', 'dense', 'sparse' or 'slepc'")
        self.M, self.K, self.G = (sp.csr_matrix(x) for x in (M, K, G))
        self.C = sp.csr_matrix(C) if damped else sp.csr_matrix(self.M.shape)
        self.n = self.M.shape[0]
        self.kind = np.asarray(dof_kind)
        for name, X in (("M", self.M), ("K", self.K), ("C", self.C), ("G", self.G)):
            if X.shape != (self.n, self.n):
                raise InputError(name, X.shape, f"must be a square matrix of the size of M, ({self.n}, {self.n})")
            if not np.all(np.isfinite(X.data)):
                raise InputError(name, "non-finite entries", "must be finite")
        if self.kind.shape != (self.n,) or np.any((self.kind < 0) | (self.kind > 5)):
            raise InputError("dof_kind", self.kind.shape, f"must hold {self.n} DOF kinds in 0..5")
        counts = np.bincount(self.kind.astype(int), minlength=6)
        if counts[0] != counts[1] or counts[3] != counts[4]:  # whirl needs (x, y) pairs
            raise InputError("dof_kind", f"{counts[0]} u1, {counts[1]} u2, {counts[3]} theta1, {counts[4]} theta2",
                             "must pair every lateral DOF: as many u1 as u2 and theta1 as theta2",
                             "planar or axial models: use kinds 2 (u3) or 5 (phi)")
        self.mdiag = self.M.diagonal()
        self.speed_terms = speed_terms
        self.damped = damped
        pattern = abs(self.M) + abs(self.K) + abs(self.C) + abs(self.G)
        if speed_terms is not None:
            pattern = pattern + abs(sp.csr_matrix(speed_terms.pattern))
        n_blocks, label = connected_components(pattern, directed=False)
        self.blocks = [np.flatnonzero(label == b) for b in range(n_blocks)]
        #: backend of each block ("auto": chosen per solve by :meth:`backend`)
        self.block_methods = [method] * n_blocks
        self.method = "+".join(sorted(set(self.block_methods)))
        touched = (np.zeros(self.n, bool) if speed_terms is None
                   else np.asarray(abs(sp.csr_matrix(speed_terms.pattern)).sum(axis=1)).ravel() > 0)
        #: per block: whether it depends on the speed through the supports (solved at every speed)
        self._supports = [bool(touched[d].any()) for d in self.blocks]
        self._gyro = [self.G[d].nnz > 0 or t for d, t in zip(self.blocks, self._supports)]
        self._blas = _blas_controller() if blas_threads is not None else None
        self.blas_threads = blas_threads
        self._dense: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray | None]] = {}
        self._cho: dict[int, tuple] = {}
        self._cache: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
        self._definite: dict[int, bool] = {}

    def _sub(self, b: int, speed: float | None = None) -> list[sp.csr_matrix]:
        """Block ``b``'s M, K, C, G; with ``speed``, K and C include the speed-dependent supports there."""
        dofs = self.blocks[b]
        M, K, C, G = (X[dofs][:, dofs] for X in (self.M, self.K, self.C, self.G))
        if speed is not None and self._supports[b]:
            dK, dC = self._terms(speed)
            K = (K + dK[dofs][:, dofs]).tocsr()
            C = (C + dC[dofs][:, dofs]).tocsr() if self.damped else C
        return [M, K, C, G]

    def _terms(self, speed: float) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        dK, dC = self.speed_terms(speed)
        return sp.csr_matrix(dK), sp.csr_matrix(dC)

    def solve(self, speed: float, n_modes: int, sigma: float | None = None, min_modes: int | None = None) -> Modes:
        """Lowest ``n_modes`` oscillatory modes at ``speed`` (rad/s).

        ``min_modes`` (default ``n_modes``): fewer oscillatory modes than this is a
        :class:`NumericalError`; between ``min_modes`` and ``n_modes`` all found are returned.

        Independent DOF blocks (connected components of the sparsity of
        M + K + C + G) are solved separately; blocks without gyroscopic coupling
        do not depend on the speed and are solved once and reused.
        """
        if n_modes < 1:
            raise InputError("n_modes", n_modes, "must be >= 1")
        limit = self._blas.limit(limits=self.blas_threads, user_api="blas") if self._blas else nullcontext()
        if "auto" in self.block_methods:
            self.method = "+".join(sorted({self.backend(b, n_modes) for b in range(len(self.blocks))}))
        with limit:
            modes = self._solve(speed, n_modes, sigma, min_modes)
            planar = (np.abs(modes.whirl_ratio) < PLANAR) & np.isin(modes.whirl, ("forward", "backward"))
            if speed == 0 and np.any(planar) and self.G.nnz:
                modes = self._label_planar(modes, planar, sigma)
        return modes

    def _label_planar(self, modes: Modes, planar: np.ndarray, sigma: float | None) -> Modes:
        """Whirl labels of planar modes at zero speed: the limit Omega -> 0+ (anisotropic supports).

        Modes that are planar at rest (e.g. x and y modes of anisotropic bearings)
        become slightly elliptic under a tiny spin; the branch they join there
        (matched by MAC) is their label.  Frequencies and whirl ratios stay those at rest.
        """
        eps = PLANAR_SPEED * float(modes.wd.max())
        near = self._solve(eps, len(modes.wd), sigma, 1)
        col = np.argmax(mac(modes.shapes, near.shapes), axis=1)
        labels = [near.whirl[col[i]] if planar[i] else modes.whirl[i] for i in range(len(modes.wd))]
        return Modes(modes.speed, modes.eigenvalues, modes.shapes, tuple(labels), modes.whirl_ratio)

    def _solve(self, speed: float, n_modes: int, sigma: float | None, min_modes: int | None) -> Modes:
        lams, vecs = [], []
        for b, dofs in enumerate(self.blocks):
            gyro = self._gyro[b]
            key = (b, n_modes)
            if not gyro and key in self._cache:
                lam, Zb = self._cache[key]
            else:
                lam, Zb = self._solve_block(b, speed if gyro else 0.0, n_modes, sigma)
                if not gyro:
                    self._cache[key] = (lam, Zb)
            Z = np.zeros((self.n, len(lam)), dtype=complex)
            Z[dofs] = Zb
            lams.append(lam)
            vecs.append(Z)
        return self._finish(speed, np.concatenate(lams), np.concatenate(vecs, axis=1), n_modes,
                            n_modes if min_modes is None else min_modes)

    def backend(self, b: int, n_modes: int) -> str:
        """Backend that solves block ``b`` for ``n_modes`` modes.

        Blocks too small for a Krylov space of the requested size (``n_modes + 5``
        DOF or fewer) are solved densely by every backend.
        """
        m = len(self.blocks[b])
        if m <= n_modes + 5:
            return "dense"
        if self.block_methods[b] == "auto":
            return "dense" if m <= DENSE_PER_MODE * (n_modes + 5) else "sparse"
        return self.block_methods[b]

    def _solve_block(self, b: int, speed: float, n_modes: int,
                     sigma: float | None) -> tuple[np.ndarray, np.ndarray]:
        """Oscillatory eigenpairs (Im lambda > threshold) of one block."""
        m = len(self.blocks[b])
        if self.backend(b, n_modes) == "dense":
            lam, Z = self._solve_dense(b, speed)
            # no rigid-body modes when K is symmetric positive definite: the threshold is then relative to
            # each |lambda| (drops only split real pairs); relative to |lambda|_max it would drop genuine
            # low modes of stiff supports (|lambda|_max ~ 1e9 rad/s)
            scale = np.abs(lam) if self._stiffness_definite(b) else np.abs(lam).max(initial=0.0)
            thr = ZERO_RTOL * scale
        elif self.backend(b, n_modes) == "sparse":
            lam, Z = self._solve_sparse(b, speed, n_modes, sigma)
            thr = SPARSE_ZERO * np.abs(lam).max(initial=0.0)
        else:
            from cvtfem.modal.slepc_backend import solve_gep, solve_pep

            M, K, C, G = self._sub(b, speed)
            s = -SIGMA if sigma is None else sigma
            if C.nnz == 0 and (G.nnz == 0 or speed == 0):
                lam, Z = solve_gep(M, K, n_modes, s)
            else:
                lam, Z = solve_pep(M, K, C + speed * G, min(n_modes + 4, m), s)
            thr = SPARSE_ZERO * np.abs(lam).max(initial=0.0)
        keep = lam.imag > thr
        return lam[keep], Z[:, keep]

    def _stiffness_definite(self, b: int) -> bool:
        """Whether block ``b``'s stiffness is symmetric positive definite to working precision, cached.

        The test is on the Jacobi-equilibrated ``D^-1/2 K D^-1/2`` (``D = diag K``), so that penalty-like
        terms (supports of 1e18 N/m, elastic connections of 1e12 N m/rad) do not set the scale: definite
        means every eigenvalue of the scaled matrix exceeds ``n eps`` times its largest (the numerical-rank
        tolerance of ``numpy.linalg.matrix_rank``).  A free rigid-body mode leaves an eigenvalue of
        round-off size whose sign depends on the BLAS kernel; a Cholesky test of K accepted it as positive,
        and the rigid mode became a spurious 'oscillatory' mode at ~sqrt(eps) |lambda|_max (issue 11).
        """
        if b not in self._definite:
            K = self._sub(b)[1].toarray()
            d = np.diag(K)
            ok = bool(np.all(d > 0)) and np.allclose(K, K.T, rtol=0.0, atol=1e-12 * np.abs(K).max(initial=0.0))
            if ok:
                s = 1.0 / np.sqrt(d)
                w = sla.eigvalsh(s[:, None] * K * s[None, :], check_finite=False)
                ok = bool(w[0] > len(w) * np.finfo(float).eps * w[-1])
            self._definite[b] = ok
        return self._definite[b]

    def _solve_dense(self, b: int, speed: float) -> tuple[np.ndarray, np.ndarray]:
        if b not in self._dense:  # one Cholesky of the block mass matrix, reused for every speed
            M, K, C, G = (X.toarray() for X in self._sub(b))
            try:
                cho = sla.cho_factor(M)
            except np.linalg.LinAlgError:
                raise NumericalError("mass matrix is not positive definite (a DOF without inertia?)",
                                     component="modal.dense") from None
            self._dense[b] = (sla.cho_solve(cho, K), sla.cho_solve(cho, C),
                              sla.cho_solve(cho, G) if np.any(G) else None)
            self._cho[b] = cho
        MK, MC, MG = self._dense[b]
        if self._supports[b]:
            dofs = self.blocks[b]
            dK, dC = (X[dofs][:, dofs].toarray() for X in self._terms(speed))
            cho = self._cho[b]
            MK = MK + sla.cho_solve(cho, dK)
            MC = MC + sla.cho_solve(cho, dC) if self.damped else MC
        if not all(np.all(np.isfinite(X)) for X in (MK, MC) + (() if MG is None else (MG,))):
            raise NumericalError("M^-1 K (or C, G) overflows: stiffness or damping far too large for the masses "
                                 "(ratios beyond double precision)", component="modal.dense")
        m = MK.shape[0]
        A = np.zeros((2 * m, 2 * m))
        A[:m, m:] = np.eye(m)
        A[m:, :m] = -MK
        A[m:, m:] = -MC if MG is None else -(MC + speed * MG)
        lam, Z = sla.eig(A, overwrite_a=True, check_finite=False)
        return lam, Z[:m]

    def _solve_sparse(self, b: int, speed: float, n_modes: int,
                      sigma: float | None) -> tuple[np.ndarray, np.ndarray]:
        M, K, C, G = self._sub(b, speed)
        n = M.shape[0]
        s = -SIGMA if sigma is None else float(sigma)
        if C.nnz == 0 and (G.nnz == 0 or speed == 0):
            return self._solve_symmetric(M, K, n_modes, s)
        D = (C + speed * G).tocsc()
        P = (K + s * D + s * s * M).tocsc()
        try:
            lu = spla.splu(P)
        except RuntimeError as err:
            raise NumericalError(f"shift-invert factorisation failed at sigma = {s:g} ({err})",
                                 component="modal.sparse") from None
        DsM = (D + s * M).tocsr()

        def op(w: np.ndarray) -> np.ndarray:
            a, c = w[:n], M @ w[n:]
            x = -lu.solve(c + DsM @ a)
            return np.concatenate([x, a + s * x])

        k = min(2 * n_modes + 6, 2 * n - 2)
        A = spla.LinearOperator((2 * n, 2 * n), matvec=op, dtype=float)
        try:
            mu, Z = spla.eigs(A, k=k, which="LM", ncv=min(2 * n, 2 * k + 1), tol=1e-12, maxiter=ARPACK_RESTARTS,
                              v0=arpack_start(2 * n))
        except spla.ArpackNoConvergence as err:
            raise NumericalError(f"ARPACK did not converge at Omega = {speed:g} rad/s ({err})",
                                 component="modal.sparse") from None
        return s + 1.0 / mu, Z[:n]

    @staticmethod
    def _solve_symmetric(M: sp.csr_matrix, K: sp.csr_matrix, n_modes: int,
                         s: float) -> tuple[np.ndarray, np.ndarray]:
        """Undamped, non-gyroscopic block: ``K x = w^2 M x`` (Lanczos, shift ``-s^2``); rigid modes stay simple."""
        k = min(n_modes + 4, M.shape[0] - 1)
        try:
            w2, X = spla.eigsh(K.tocsc(), k=k, M=M.tocsc(), sigma=-s * s, which="LM", tol=1e-12,
                               maxiter=ARPACK_RESTARTS, v0=arpack_start(M.shape[0]))
        except spla.ArpackNoConvergence as err:
            raise NumericalError(f"ARPACK (Lanczos) did not converge ({err})", component="modal.sparse") from None
        return 1j * np.sqrt(np.clip(w2, 0.0, None)), X.astype(complex)

    def _finish(self, speed: float, lam: np.ndarray, X: np.ndarray, n_modes: int, min_modes: int) -> Modes:
        if not np.all(np.isfinite(lam)):
            raise NumericalError("non-finite eigenvalues", component="modal")
        if self.C.nnz == 0 and not (self.damped and getattr(self.speed_terms, "damped", False)):
            # conservative gyroscopic system: the spectrum is imaginary, drop round-off
            lam = lam.copy()
            lam.real[np.abs(lam.real) < ROUNDOFF * np.abs(lam)] = 0.0
        order = np.argsort(lam.imag)[:n_modes + 2]
        lam, X = lam[order], X[:, order]
        if len(lam) < min_modes:
            raise NumericalError(f"found only {len(lam)} oscillatory modes, {min_modes} requested",
                                 component="modal")
        X = circularize(lam, X, self.kind, self.mdiag)
        peak = X[np.argmax(np.abs(X), axis=0), np.arange(X.shape[1])]
        X = X / peak
        labels, ratio = classify(X, self.mdiag, self.kind, spin_sign=-1.0 if speed < 0 else 1.0)
        # repeated frequencies (clusters): backward before forward, the order they take for Omega > 0
        cluster = np.concatenate([[0], np.cumsum(np.diff(lam.imag) > 1e-7 * lam.imag[1:])])
        order = np.lexsort((ratio, cluster))[:n_modes]
        lam, X, ratio = lam[order], X[:, order], ratio[order]
        labels = [labels[i] for i in order]
        return Modes(float(speed), lam, X, tuple(labels), ratio)


def _blas_controller():  # noqa: ANN202 - threadpoolctl.ThreadpoolController or None
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return None
    return ThreadpoolController()


def solve_modes(M, K, C, G, speed: float, n_modes: int, dof_kind: np.ndarray,
                method: str = "auto", damped: bool = True) -> Modes:
    """One-shot :meth:`ModalProblem.solve` (see there)."""
    return ModalProblem(M, K, C, G, dof_kind, method, damped).solve(speed, n_modes)
