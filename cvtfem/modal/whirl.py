"""Mode classification: energy fractions, whirl sense, circular pairs, MAC.

DOF kinds follow the node layout ``(u1, u2, u3, theta1, theta2, phi)`` =
kinds ``0..5``.  For an eigenvalue ``lambda = -zeta wn + i wd`` (wd > 0) the
physical motion is ``Re(x e^{i wd t})``; a lateral orbit ``(u1, u2)`` turns in
the spin sense (+e3, from e1 to e2) when ``Im(conj(u1) u2) < 0``: forward whirl.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

U1, U2, U3, T1, T2, PHI = range(6)


def _pairs(kind: np.ndarray, mdiag: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Index pairs (x, y) of lateral translations and tilts with their mass weights."""
    a = np.concatenate([np.flatnonzero(kind == U1), np.flatnonzero(kind == T1)])
    b = np.concatenate([np.flatnonzero(kind == U2), np.flatnonzero(kind == T2)])
    return a, b, 0.5 * (mdiag[a] + mdiag[b])


def whirl_form(X: np.ndarray, Y: np.ndarray, kind: np.ndarray, mdiag: np.ndarray) -> np.ndarray:
    """Hermitian whirl form ``X^H S Y`` (mass weighted ``2 Im(conj(x) y)`` summed over orbits).

    Parameters
    ----------
    X, Y : complex arrays (n, p), (n, q)
    kind : int array (n,)
    mdiag : array (n,)
        Diagonal of the mass matrix (weights).

    Returns
    -------
    complex array (p, q); for ``X = Y = x`` a real number < 0 for forward whirl.
    """
    a, b, w = _pairs(kind, mdiag)
    Xa, Xb, Ya, Yb = X[a], X[b], Y[a], Y[b]
    return -1j * ((Xa.conj() * w[:, None]).T @ Yb - (Xb.conj() * w[:, None]).T @ Ya)


def circularize(lam: np.ndarray, X: np.ndarray, kind: np.ndarray, mdiag: np.ndarray,
                rtol: float = 1e-7) -> np.ndarray:
    """Rotate the bases of repeated eigenvalues into circular (pure-whirl) modes.

    At zero speed with isotropic supports every lateral frequency is double and
    an eigensolver returns arbitrary (often planar) combinations; the
    combinations that diagonalise the whirl form are the limits of the
    forward/backward modes as the speed tends to 0.
    """
    X = X.copy()
    order = np.argsort(lam.imag)
    i = 0
    while i < len(order):
        j = i + 1
        while j < len(order) and abs(lam[order[j]] - lam[order[i]]) <= rtol * abs(lam[order[i]]):
            j += 1
        if j - i > 1:
            idx = order[i:j]
            V = X[:, idx]
            gram = (V.conj() * mdiag[:, None]).T @ V
            _, U = scipy.linalg.eigh(whirl_form(V, V, kind, mdiag), gram)
            X[:, idx] = V @ U
        i = j
    return X


def classify(X: np.ndarray, M_diag_blocks: np.ndarray, kind: np.ndarray,
             spin_sign: float = 1.0) -> tuple[list[str], np.ndarray]:
    """Whirl labels and whirl ratios of mode shapes.

    Parameters
    ----------
    X : complex array (n, k)
        Mode shapes (displacement part) with ``wd > 0``.
    M_diag_blocks : array (n,)
        Diagonal of the mass matrix.
    kind : int array (n,)
    spin_sign : float
        Sign of the spin speed: whirl is forward when the orbit turns with the spin.

    Returns
    -------
    labels : list of str
        "forward", "backward", "torsional" or "axial": torsional/axial when that
        group holds most of the (mass-weighted) motion, else by the orbit sense.
    ratio : array (k,)
        Whirl ratio in [-1, 1]: +1 circular forward, -1 circular backward, 0 planar.
    """
    w = M_diag_blocks[:, None] * np.abs(X) ** 2
    total = w.sum(axis=0)
    tors = w[kind == PHI].sum(axis=0) / total
    axial = w[kind == U3].sum(axis=0) / total
    lateral = total - w[kind == PHI].sum(axis=0) - w[kind == U3].sum(axis=0)
    a, b, wab = _pairs(kind, M_diag_blocks)
    s = (2 * wab[:, None] * np.imag(X[a].conj() * X[b])).sum(axis=0)
    ratio = spin_sign * np.where(lateral > 0, -s / np.where(lateral > 0, lateral, 1.0), 0.0)
    labels = []
    for k in range(X.shape[1]):
        if tors[k] > 0.5:
            labels.append("torsional")
        elif axial[k] > 0.5:
            labels.append("axial")
        else:
            labels.append("forward" if ratio[k] >= 0 else "backward")
    return labels, ratio


def mac(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Modal assurance criterion matrix ``|a^H b|^2 / (|a|^2 |b|^2)``, shape (p, q)."""
    num = np.abs(A.conj().T @ B) ** 2
    return num / np.outer(np.sum(np.abs(A) ** 2, axis=0), np.sum(np.abs(B) ** 2, axis=0))
