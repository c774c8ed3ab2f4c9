"""Forced harmonic response of ``M x'' + (C + Omega G) x' + K x = f e^{i w t}``: receptances, unbalance, orders.

Two routes give the same complex receptance ``H(w) = Y(w) Z(w)^{-1} F`` with the dynamic stiffness
``Z(w) = K - w^2 M + i w (C + Omega G)``, inputs ``F`` (n x m) and outputs ``Y(w) = D + i w V`` (p x n):

* :func:`frf_direct`: one sparse LU (``scipy.sparse.linalg.splu``) of ``Z`` per frequency, on one
  sparsity pattern assembled once (:class:`DynamicStiffness`); exact up to round-off;
* :class:`ModalBasis` / :func:`frf_modal`: a real basis of modes (per speed the right and left complex
  modes from :class:`~cvtfem.modal.eigen.ModalProblem`, or the undamped modes at rest), optionally with
  residual-flexibility vectors; M, K, C, G are projected on it and the complex modes of the reduced
  state-space matrix are summed, ``H = Y Phi (i w - Lambda)^{-1} Psi F``.  With ``C = G = 0`` the reduced
  modes are the real modes themselves.

Only the DOF blocks the inputs reach (connected components of the sparsity of M + K + C + G) are
solved: the response of the other blocks is zero.  Amplitudes are complex: the motion is
``Re(x e^{i w t})``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from cvtfem.errors import InputError, NumericalError
from cvtfem.modal.eigen import ModalProblem


@dataclass(frozen=True)
class OutputMap:
    """Outputs ``y = D x + V x'`` (p rows over n DOFs); at frequency w, ``y = (D + i w V) x``.

    Attributes
    ----------
    D, V : scipy.sparse.csr_matrix (p, n)
    names : tuple of str (p,)
    """

    D: sp.csr_matrix
    V: sp.csr_matrix
    names: tuple[str, ...]


def displacement(dofs, n: int, names: tuple[str, ...] = ()) -> OutputMap:
    """Displacements of the DOFs ``dofs`` (m or rad)."""
    dofs = np.atleast_1d(np.asarray(dofs, dtype=np.int64))
    S = sp.csr_matrix((np.ones(len(dofs)), (np.arange(len(dofs)), dofs)), shape=(len(dofs), n))
    return OutputMap(S, sp.csr_matrix(S.shape), names or tuple(f"x[{d}]" for d in dofs))


def velocity(dofs, n: int, names: tuple[str, ...] = ()) -> OutputMap:
    """Velocities of the DOFs ``dofs`` (m/s or rad/s)."""
    d = displacement(dofs, n, names or tuple(f"v[{k}]" for k in np.atleast_1d(dofs)))
    return OutputMap(d.V, d.D, d.names)


def _check(M, K, C, G) -> list[sp.csr_matrix]:
    mats = [sp.csr_matrix(X) for X in (M, K, C, G)]
    n = mats[0].shape[0]
    for name, X in zip("MKCG", mats):
        if X.shape != (n, n):
            raise InputError(name, X.shape, f"must be a square matrix of the size of M, ({n}, {n})")
        if not np.all(np.isfinite(X.data)):
            raise InputError(name, "non-finite entries", "must be finite")
    return mats


def _inputs(F, n: int) -> np.ndarray:
    F = np.asarray(F.toarray() if sp.issparse(F) else F, dtype=complex)
    F = F[:, None] if F.ndim == 1 else F
    if F.shape[0] != n or F.ndim != 2:
        raise InputError("inputs", F.shape, f"must be a force vector or matrix with {n} rows")
    return F


def reached(M, K, C, G, F: np.ndarray) -> np.ndarray:
    """DOFs in the blocks (connected components of M + K + C + G) where ``F`` has non-zero rows."""
    pattern = abs(M) + abs(K) + abs(C) + abs(G)
    _, label = connected_components(pattern, directed=False)
    hit = np.unique(label[np.any(F != 0, axis=1)])
    return np.flatnonzero(np.isin(label, hit))


def _omegas(omegas) -> np.ndarray:
    w = np.atleast_1d(np.asarray(omegas, dtype=float))
    if w.ndim != 1 or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise InputError("omegas", w.tolist()[:5], "must be finite frequencies >= 0 rad/s")
    return w


class DynamicStiffness:
    """``Z(w, Omega) = K - w^2 M + i w (C + Omega G)`` on the DOFs ``dofs``, one CSC pattern for all w.

    Parameters
    ----------
    M, K, C, G : sparse (n, n)
    dofs : int array
        The DOFs kept (a union of independent blocks).
    """

    def __init__(self, M, K, C, G, dofs: np.ndarray) -> None:
        sub = [X[dofs][:, dofs].tocsc() for X in _check(M, K, C, G)]
        P = (abs(sub[0]) + abs(sub[1]) + abs(sub[2]) + abs(sub[3])).tocsc()
        P.sort_indices()
        m = len(dofs)
        key = np.repeat(np.arange(m), np.diff(P.indptr)) * m + P.indices
        self.pattern = P
        self.data = []
        for X in sub:
            X = X.tocoo()
            d = np.zeros(P.nnz)
            np.add.at(d, np.searchsorted(key, X.col.astype(np.int64) * m + X.row), X.data)
            self.data.append(d)

    def __call__(self, w: float, speed: float) -> sp.csc_matrix:
        Md, Kd, Cd, Gd = self.data
        Z = sp.csc_matrix((Kd - w * w * Md + 1j * w * (Cd + speed * Gd), self.pattern.indices,
                           self.pattern.indptr), shape=self.pattern.shape)
        return Z

    def solve(self, w: float, speed: float, F: np.ndarray) -> np.ndarray:
        """``Z(w, speed)^{-1} F``; NumericalError when Z is singular (a resonance of an undamped system)."""
        try:
            return spla.splu(self(w, speed)).solve(F)
        except RuntimeError as err:
            raise NumericalError(f"dynamic stiffness singular at w = {w:g} rad/s, speed {speed:g} rad/s ({err}): "
                                 "an undamped resonance or an unsupported rigid-body mode",
                                 component="modal.forced") from None


def _direct(M, K, C, G, inputs, outputs: OutputMap):
    """What a direct solve needs, restricted to the DOFs the inputs reach: the dynamic stiffness, the inputs
    and the output maps on those DOFs."""
    M, K, C, G = _check(M, K, C, G)
    F = _inputs(inputs, M.shape[0])
    dofs = reached(M, K, C, G, F)
    return DynamicStiffness(M, K, C, G, dofs), F[dofs], outputs.D[:, dofs], outputs.V[:, dofs]


def frf_direct(M, K, C, G, inputs, outputs: OutputMap, omegas, speed: float = 0.0) -> np.ndarray:
    """Receptances by one sparse solve per frequency.

    Parameters
    ----------
    M, K, C, G : sparse (n, n)
        G per unit spin speed.
    inputs : array (n,) or (n, m)
        Force distributions (N per unit input).
    outputs : OutputMap
    omegas : array (w,), rad/s
    speed : float, rad/s

    Returns
    -------
    complex array (w, p, m): output per unit input.
    """
    Z, F, D, V = _direct(M, K, C, G, inputs, outputs)
    w = _omegas(omegas)
    H = np.zeros((len(w), D.shape[0], F.shape[1]), dtype=complex)
    for i, wi in enumerate(w):
        X = Z.solve(wi, speed, F)
        H[i] = D @ X + 1j * wi * (V @ X)
    return H


#: Columns of a basis group with an M-norm below this fraction of the group's largest are round-off (the
#: imaginary part of a real mode); Gram eigenvalues below this fraction of the largest are dependent columns
#: (1e-10 dropped directions that carried 1e-3 of a Friswell FRF: keep all but round-off).
COLUMN_RTOL = 1e-8
GRAM_RTOL = 1e-13
#: Shift ``a = RIGID_SHIFT max(diag K) / max(diag M)`` of the static correction ``(K + a M)^{-1} F`` when K is singular
#: (rigid-body modes in the excited blocks): the correction then carries the rigid-body response, which the
#: eigen-solvers drop, with the elastic modes' part off by a relative ``a / w_j^2``.
RIGID_SHIFT = 1e-12
#: A reduced block whose eigenvector matrix has a reciprocal condition number below this is (nearly) defective and
#: is solved by batched reduced solves instead of its modes.
DEFECTIVE_RCOND = 1e-10
#: Singular values of a reduced stiffness below this fraction of the largest are rigid-body directions: such a block
#: (a Jordan pair at lambda = 0) is solved by batched reduced solves too.
RIGID_RCOND = 1e-9


def _unit_columns(X: np.ndarray, M) -> np.ndarray:
    """Columns of X with M-norm 1, round-off columns dropped."""
    norm = np.sqrt(np.abs(np.einsum("ij,ij->j", X, M @ X)))
    keep = norm > COLUMN_RTOL * norm.max(initial=0.0)
    return X[:, keep] / norm[keep]


class ModalBasis:
    """Modal superposition on a real basis of modes (+ static correction vectors), reduced per speed.

    Parameters
    ----------
    M, K, C, G : sparse (n, n)
    inputs : array (n,) or (n, m)
        Force distributions; they select the DOF blocks and, with ``residual``, add ``K^{-1} F``.
    n_modes : int
        Modes in the basis.
    residual : bool
        Add the static responses ``X0 = K^{-1} F`` and ``K^{-1} A X0`` for A = M, C, G (residual flexibility
        to first order in w): the reduced model is exact at ``w = 0`` and keeps the quasi-static, damping and
        gyroscopic parts of the neglected modes (stiffness-proportional damping gives even far modes a
        response ``~ beta w`` out of phase, which ``K^{-1} F`` alone misses).
    modes : {"complex", "rest", "sweep"}
        "complex": per speed, the right and the left complex modes of ``(M, K, C, speed G)`` (the left ones
        as right modes of the transposed matrices).  A Galerkin projection on a space holding both keeps
        each retained mode's eigenvalue and residue ``x y^H / (y^H (2 lam M + D) x)`` exactly: the modal
        FRF differs from the direct one only by the neglected modes.  "rest": the undamped modes of
        ``((K + K^T)/2, M)`` at rest, one eigen-solve for every speed (the classic pseudo-modal method;
        exact for ``C = G = 0``, approximate when G or non-proportional C couple the modes).  "sweep": one
        basis for every speed, spanning the right and left complex modes at ``basis_speeds`` (a global basis for
        the speed range: exact at those speeds like "complex", close to it between them because the modes turn
        smoothly with speed); two eigen-solves per basis speed instead of per speed.
    method : str
        Eigen backend of :class:`~cvtfem.modal.eigen.ModalProblem`.
    basis_speeds : array, rad/s
        Speeds whose modes span the "sweep" basis (e.g. the ends and the middle of the sweep).

    Attributes
    ----------
    dofs : int array
        DOFs of the reached blocks.
    """

    def __init__(self, M, K, C, G, inputs, n_modes: int, residual: bool = True, modes: str = "complex",
                 method: str = "auto", basis_speeds=()) -> None:
        M, K, C, G = _check(M, K, C, G)
        F = _inputs(inputs, M.shape[0])
        if n_modes < 1:
            raise InputError("n_modes", n_modes, "must be >= 1")
        if modes not in ("complex", "rest", "sweep"):
            raise InputError("modes", modes, "must be 'complex', 'rest' or 'sweep'")
        self.basis_speeds = np.atleast_1d(np.asarray(basis_speeds, dtype=float))
        if modes == "sweep" and (len(self.basis_speeds) < 1 or not np.all(np.isfinite(self.basis_speeds))):
            raise InputError("basis_speeds", self.basis_speeds.tolist(), "must be one or more finite speeds (rad/s) "
                             "for modes='sweep'")
        self.dofs = dofs = reached(M, K, C, G, F)
        self.mats = [X[dofs][:, dofs].tocsr() for X in (M, K, C, G)]
        self.F = F[dofs]
        _, label = connected_components(abs(self.mats[0]) + abs(self.mats[1]) + abs(self.mats[2]) + abs(self.mats[3]),
                                        directed=False)
        self.blocks = [np.flatnonzero(label == b) for b in np.unique(label)]
        self.n_modes, self.method = min(n_modes, len(dofs)), method
        self.kind = np.full(len(dofs), 2)  # no whirl pairs needed: labels are not used here
        self.modes = "rest" if self.mats[2].nnz == 0 and self.mats[3].nnz == 0 else modes
        self.static = self._static() if residual else None
        self._reduced: dict[float, tuple] = {}
        self._poles: tuple | None = None

    def _static(self) -> np.ndarray:
        K, M = self.mats[1].tocsc(), self.mats[0].tocsc()
        try:
            lu = spla.splu(K)
        except RuntimeError:  # free rigid-body motion (e.g. an unsupported spin): shift, K + a M
            scale = float(np.max(np.abs(K.diagonal())) / np.max(np.abs(M.diagonal())))
            try:
                lu = spla.splu((K + RIGID_SHIFT * scale * M).tocsc())
            except RuntimeError as err:
                raise NumericalError(f"stiffness singular in the excited blocks even shifted ({err}): no static "
                                     "correction (use residual=False)", component="modal.forced") from None
        X = np.hstack([lu.solve(self.F.real), lu.solve(self.F.imag)])
        return np.hstack([X] + [lu.solve(A @ X) for A in (self.mats[0], self.mats[2], self.mats[3]) if A.nnz])

    def _shapes(self, speed: float) -> tuple[list[np.ndarray], float]:
        """Mode shapes (complex columns) spanning the basis at ``speed``, and the highest |lambda| among them."""
        M, K, C, G = self.mats
        if self.modes == "rest":
            zero = sp.csr_matrix(M.shape)
            md = ModalProblem(M, (K + K.T) / 2, zero, zero, self.kind, self.method, damped=False).solve(
                0.0, self.n_modes)
            return [md.shapes], float(md.wn.max())
        right = ModalProblem(M, K, C, G, self.kind, self.method).solve(speed, self.n_modes)
        left = ModalProblem(M.T, K.T, C.T, G.T, self.kind, self.method).solve(speed, self.n_modes)
        return [right.shapes, left.shapes], float(max(right.wn.max(), left.wn.max()))

    def _sweep_shapes(self) -> tuple[list[np.ndarray], float]:
        """Right and left complex modes at every basis speed, and the lowest of their highest |lambda|."""
        shapes, tops = [], []
        for s in self.basis_speeds:
            group, top = self._shapes(float(s))
            shapes += group
            tops.append(top)
        return shapes, min(tops)

    def _blocks(self, key: float) -> list[tuple]:
        """Per independent DOF block (connected component of the pattern among the reached DOFs): ``(rows, V,
        K_r, C_r, G_r, F_r)`` with V an M-orthonormal basis of the block (kept apart, so the reduced matrices have
        no round-off coupling between blocks), and the highest retained natural frequency."""
        if key not in self._reduced:
            shapes, wmax = self._sweep_shapes() if self.modes == "sweep" else self._shapes(key)
            groups = [np.hstack([X.real, X.imag]) for X in shapes]
            if self.static is not None:
                groups.append(self.static)
            blocks = []
            for rows in self.blocks:
                M, K, C, G = (X[rows][:, rows] for X in self.mats)
                B = np.hstack([_unit_columns(X[rows], M) for X in groups])
                if B.shape[1] == 0:
                    continue
                lam, U = sla.eigh(B.T @ (M @ B))
                keep = lam > GRAM_RTOL * lam.max()  # drop dependent columns (both halves of a circular pair, ...)
                V = B @ (U[:, keep] / np.sqrt(lam[keep]))  # M-orthonormal
                blocks.append((rows, V, V.T @ (K @ V), V.T @ (C @ V), V.T @ (G @ V), V.T @ self.F[rows]))
            self._reduced = {} if self.modes == "complex" else self._reduced  # keep one speed
            self._reduced[key] = (blocks, wmax)
        return self._reduced[key]

    def reduced(self, speed: float) -> tuple[np.ndarray, ...]:
        """``(V, K_r, D_r, F_r, wmax)`` at ``speed``: M-orthonormal basis V (dofs x r, block-diagonal over the
        independent blocks), reduced stiffness and damping ``V^T (C + speed G) V``, forces; wmax (rad/s) is the
        highest retained natural frequency."""
        blocks, wmax = self._blocks(float(speed) if self.modes == "complex" else 0.0)
        V = sla.block_diag(*(b[1] for b in blocks))
        order = np.concatenate([b[0] for b in blocks])
        Vd = np.zeros((len(self.dofs), V.shape[1]))
        Vd[order] = V
        return (Vd, sla.block_diag(*(b[2] for b in blocks)),
                sla.block_diag(*(b[3] + speed * b[4] for b in blocks)), np.vstack([b[5] for b in blocks]), wmax)

    def wmax(self, speed: float = 0.0) -> float:
        """Highest natural frequency in the basis at ``speed``, rad/s (modal FRFs are meant below it)."""
        return self._blocks(float(speed) if self.modes == "complex" else 0.0)[1]

    def poles(self, speed: float) -> list[tuple]:
        """Per block at ``speed``: ``("modal", lam, X, L)`` from the reduced state-space matrix
        ``A = [[0, I], [-K_r, -D_r]] = Phi diag(lam) Phi^{-1}``, the modes' displacement shapes ``X = V Phi_q``
        (dofs x 2r) and participations ``L = Phi^{-1} [0; F_r]`` (2r x m); or, for a block with a rigid-body mode
        (K_r singular to ``RIGID_RCOND``: a Jordan pair at 0, or two nearly equal poles whose modal sum cancels
        badly) or a defective Phi, ``("direct", X, Kr, Dr, Fr)`` with ``X = V`` for batched reduced solves.
        The last speed's are kept."""
        if self._poles is not None and self._poles[0] == speed:
            return self._poles[1]
        blocks, _ = self._blocks(float(speed) if self.modes == "complex" else 0.0)
        out = []
        for rows, V, Kr, Cr, Gr, Fr in blocks:
            r = V.shape[1]
            X = np.zeros((len(self.dofs), r))
            X[rows] = V
            A = np.zeros((2 * r, 2 * r))
            A[:r, r:] = np.eye(r)
            A[r:, :r], A[r:, r:] = -Kr, -(Cr + speed * Gr)
            sv = np.linalg.svd(Kr, compute_uv=False)
            if sv.min() < RIGID_RCOND * sv.max():  # a rigid-body mode: no modal sum
                out.append(("direct", X, Kr, Cr + speed * Gr, Fr))
                continue
            lam, Phi = sla.eig(A)
            if 1.0 / np.linalg.cond(Phi) < DEFECTIVE_RCOND:
                out.append(("direct", X, Kr, Cr + speed * Gr, Fr))
                continue
            L = sla.solve(Phi, np.vstack([np.zeros_like(Fr), Fr]))  # (2r, m) modal participations
            out.append(("modal", lam, X @ Phi[:r], L))
        self._poles = (speed, out)
        return out

    def frf(self, outputs: OutputMap, omegas, speed: float = 0.0, columns=None) -> np.ndarray:
        """Receptances (w, p, m), per block by summing the complex modes of the reduced state-space matrix
        (:meth:`poles`), ``H(w) = (D + i w V) X (i w - lam)^{-1} L``, or by batched reduced solves
        ``V (K_r - w^2 + i w D_r)^{-1} F_r``; ``columns`` selects inputs (default all)."""
        w = _omegas(omegas)
        cols = slice(None) if columns is None else columns
        m = self.F[:, cols].shape[1]
        D, Vo = outputs.D[:, self.dofs], outputs.V[:, self.dofs]
        H = np.zeros((len(w), D.shape[0], m), dtype=complex)
        for part in self.poles(speed):
            if part[0] == "modal":
                _, lam, X, L = part
                gL = L[None, :, cols] / (1j * w[:, None, None] - lam[None, :, None])  # (w, 2r, m)
            else:
                _, X, Kr, Dr, Fr = part
                if not np.any(Fr[:, cols]):
                    continue
                Z = Kr[None] - (w * w)[:, None, None] * np.eye(len(Kr)) + 1j * w[:, None, None] * Dr[None]
                gL = _batched_solve(Z, Fr[:, cols], w, speed)
            Dq, Vq = D @ X, Vo @ X
            H += Dq[None] @ gL
            if np.any(Vq):
                H += 1j * w[:, None, None] * (Vq[None] @ gL)
        return H


def _batched_solve(Z: np.ndarray, F: np.ndarray, w: np.ndarray, speed: float) -> np.ndarray:
    """``Z[i]^{-1} F`` for a stack Z (w, r, r) of a block with a rigid-body mode.  At w = 0 Z is singular: the
    static solution orthogonal to the rigid-body modes when F does not load them (pseudo-inverse, singular values
    below ``RIGID_RCOND`` of the largest dropped), else a NumericalError (no steady state)."""
    out = np.empty((len(Z),) + F.shape, dtype=complex)
    moving = w > 0
    try:
        out[moving] = np.linalg.solve(Z[moving], np.broadcast_to(F, (int(moving.sum()),) + F.shape))
    except np.linalg.LinAlgError:
        raise NumericalError(f"reduced dynamic stiffness singular at speed {speed:g} rad/s", component="modal.forced"
                             ) from None
    for i in np.flatnonzero(~moving):
        out[i] = np.linalg.pinv(Z[i], rcond=RIGID_RCOND) @ F
        if np.linalg.norm(Z[i] @ out[i] - F) > 1e-6 * np.linalg.norm(F):
            raise NumericalError(f"a static (w = 0) load on a free rigid-body mode at speed {speed:g} rad/s has no "
                                 "steady state", component="modal.forced")
    return out


def frf_modal(M, K, C, G, inputs, outputs: OutputMap, omegas, speed: float = 0.0, n_modes: int = 20,
              residual: bool = True, modes: str = "complex", method: str = "auto", basis_speeds=()) -> np.ndarray:
    """Receptances (w, p, m) by modal superposition (one-shot :class:`ModalBasis`)."""
    return ModalBasis(M, K, C, G, inputs, n_modes, residual, modes, method, basis_speeds).frf(outputs, omegas, speed)


def unbalance_response(M, K, C, G, load, outputs: OutputMap, speeds, speed_terms=None) -> np.ndarray:
    """Steady response to a synchronous load ``Omega^2 load e^{i Omega t}`` at each spin speed Omega.

    Parameters
    ----------
    load : complex array (n,)
        Force amplitude per unit ``Omega^2`` (e.g. ``me e^{i phase} (e1 - i e2)`` at a disk: forward).
    speeds : array (s,), rad/s
        The spin speed is also the excitation frequency; G and C are those at each speed.
    speed_terms : callable or None
        Speed-dependent supports, ``speed_terms(Omega) -> (dK, dC)`` added to K and C (see
        :class:`cvtfem.modal.eigen.ModalProblem`).

    Returns
    -------
    complex array (s, p): output amplitudes.
    """
    s = _omegas(speeds)
    if speed_terms is not None:
        return _unbalance_tabulated(M, K, C, G, load, outputs, s, speed_terms)
    Z, F, D, V = _direct(M, K, C, G, load, outputs)
    out = np.zeros((len(s), D.shape[0]), dtype=complex)
    for i, w in enumerate(s):
        X = Z.solve(w, w, w * w * F)[:, 0]
        out[i] = D @ X + 1j * w * (V @ X)
    return out


def _unbalance_tabulated(M, K, C, G, load, outputs: OutputMap, speeds: np.ndarray, speed_terms) -> np.ndarray:
    """:func:`unbalance_response` with K and C of speed-dependent supports: one sparse LU per speed."""
    M, K, C, G = _check(M, K, C, G)
    F = _inputs(load, M.shape[0])
    dofs = reached(M, K + abs(sp.csr_matrix(speed_terms.pattern)), C, G, F)
    D, V = outputs.D[:, dofs], outputs.V[:, dofs]
    out = np.zeros((len(speeds), D.shape[0]), dtype=complex)
    for i, w in enumerate(speeds):
        dK, dC = speed_terms(w)
        Z = (K + dK - w * w * M + 1j * w * (C + dC + w * G))[dofs][:, dofs].tocsc()
        try:
            X = spla.splu(Z).solve(w * w * F[dofs])[:, 0]
        except RuntimeError as err:
            raise NumericalError(f"dynamic stiffness singular at speed {w:g} rad/s ({err})",
                                 component="modal.forced") from None
        out[i] = D @ X + 1j * w * (V @ X)
    return out


def orbit(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Semi-axes of the elliptic orbit ``(Re(a e^{i w t}), Re(b e^{i w t}))``.

    The orbit is ``r_f e^{i w t} + r_b e^{-i w t}`` in the complex plane ``x + i y`` with
    ``r_f = (a + i b)/2``, ``r_b = (conj(a) + i conj(b))/2``.

    Returns
    -------
    major : array, ``|r_f| + |r_b|``
    minor : array, ``|r_f| - |r_b|``: positive for a forward orbit (from e1 to e2), negative backward.
    """
    rf = np.abs(a + 1j * b) / 2
    rb = np.abs(np.conj(a) + 1j * np.conj(b)) / 2
    return rf + rb, rf - rb
