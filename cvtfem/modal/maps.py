"""Rotor design maps from M and K: static deflection under gravity and the undamped critical-speed map.

The two analyses a rotordynamics user runs before any Campbell diagram (ROSS 3.1's ``run_static`` and
``run_ucs``). Both take plain matrices and DOF lists; which DOFs are supports is the model's business
(:meth:`cvtfem.machines.rotor.RotorModel.support_dofs`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import brentq

from cvtfem.errors import InputError, NumericalError
from cvtfem.modal.eigen import ModalProblem

#: Standard gravity (ISO 80000-3), m/s^2 (ROSS uses 9.8065).
STANDARD_GRAVITY = 9.80665


def static_deflection(M, K, kind: np.ndarray, pinned: np.ndarray, g: float = STANDARD_GRAVITY) -> np.ndarray:
    """Deflection under gravity along -e2: ``K u = M a`` with ``a = -g`` on every u2 DOF, ``pinned`` DOFs at 0.

    ``M a`` is the consistent load of the mass matrix (for a beam: its weight and the end moments of a uniform
    load). Returns ``u (n,)`` in m and rad; the free DOFs must be statically determined (NumericalError else).
    """
    M, K = sp.csr_matrix(M), sp.csr_matrix(K)
    n = M.shape[0]
    a = np.where(np.asarray(kind) == 1, -float(g), 0.0)
    lateral = np.setdiff1d(np.flatnonzero(np.isin(np.asarray(kind), (0, 1, 3, 4))), np.asarray(pinned, int))
    u = np.zeros(n)
    Kf = K[lateral][:, lateral].tocsc()
    try:
        u[lateral] = spla.splu(Kf).solve((M @ a)[lateral])
    except RuntimeError as err:
        raise NumericalError(f"static stiffness singular ({err}): the supports leave a rigid-body motion",
                             component="modal.static") from None
    if not np.all(np.isfinite(u)):
        raise NumericalError("static deflection not finite: the supports leave a rigid-body motion",
                             component="modal.static")
    return u


def critical_speed_map(M, K_free, kind: np.ndarray, supports: np.ndarray, stiffness, n_modes: int = 4,
                       method: str = "auto") -> np.ndarray:
    """Undamped natural frequencies at rest over the support stiffness (undamped critical-speed map).

    Parameters
    ----------
    M, K_free : sparse (n, n)
        Mass and the stiffness without the supports (shaft, connections, other springs).
    supports : int array (s, 2)
        ``(u1, u2)`` DOFs of each support; each gets ``k`` in both directions (isotropic, no damping).
    stiffness : array (p,), N/m
    n_modes : int
        Frequencies per stiffness: the lowest lateral modes, one of each (x, y) pair.

    Returns
    -------
    wn : array (p, n_modes), rad/s
    """
    k = np.atleast_1d(np.asarray(stiffness, float))
    if np.any(~np.isfinite(k)) or np.any(k <= 0):
        raise InputError("stiffness", k.tolist()[:5], "must be positive and finite (N/m)")
    supports = np.asarray(supports, int).reshape(-1, 2)
    n = M.shape[0]
    S = sp.csr_matrix((np.ones(supports.size), (supports.ravel(), supports.ravel())), shape=(n, n))
    zero = sp.csr_matrix((n, n))
    lateral = np.isin(np.asarray(kind), (0, 1, 3, 4))
    out = np.zeros((len(k), n_modes))
    for i, ki in enumerate(k):
        modes = ModalProblem(M, K_free + ki * S, zero, zero, kind, method, damped=False).solve(0.0, 2 * n_modes + 8)
        on = np.abs(modes.shapes[lateral]).max(axis=0) > 1e-6
        wn = np.sort(modes.wn[on & (modes.wn > 0)])
        if len(wn) < 2 * n_modes:
            raise NumericalError(f"found {len(wn) // 2} lateral mode pairs at k = {ki:g} N/m, {n_modes} asked",
                                 component="modal.maps")
        out[i] = wn[: 2 * n_modes: 2]
    return out


def critical_crossings(frequency_of_k, support_k, speeds, n_modes: int) -> list[tuple[int, float, float]]:
    """Where the supports' own stiffness curve ``k(speed)`` crosses the map: ``wn_j(k(s)) = s``.

    ``frequency_of_k(k) -> (n_modes,)`` rad/s; ``support_k(s)`` N/m; searched between the ``speeds`` (rad/s,
    increasing) by bracketing and Brent's method. Returns ``(mode, speed, k)`` per crossing.
    """
    s = np.asarray(speeds, float)
    f = np.array([frequency_of_k(support_k(x)) for x in s]) - s[:, None]
    out = []
    for j in range(n_modes):
        for a in np.flatnonzero(np.sign(f[:-1, j]) * np.sign(f[1:, j]) < 0):
            root = brentq(lambda x: frequency_of_k(support_k(x))[j] - x, s[a], s[a + 1], xtol=1e-10, rtol=1e-13)
            out.append((j, float(root), float(support_k(root))))
    return out
