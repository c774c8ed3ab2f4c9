"""Campbell diagrams along a run of the chain on elastic shafts: at stored states, the modes of the structure block
J11 of the Jacobian (shafts, sheaves and bearings with the chain frozen in its state), tracked by MAC.

J11 (shafts-sheaves-supports (1.358)) is the part of the first-order Jacobian ``dF/dx`` whose rows and columns are
the structure's positions and velocities.  The chain's coordinates are held at their stored values, so the chain
enters only as a load: the stiffness and damping its Hertz contacts (and their friction) oppose to a motion of the
shafts and sheaves.  It is not the Schur complement (the chain's own response condensed onto the structure).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from cvtfem.blas import single_thread_blas
from cvtfem.errors import InputError, NumericalError
from cvtfem.modal.campbell import MAC_JUMP, track
from cvtfem.modal.eigen import Modes
from cvtfem.modal.whirl import circularize, classify

#: Eigenvalues with ``Im lambda`` below this fraction of the block's largest ``|lambda|`` are not oscillatory
#: (free spins, the free slide of an unloaded movable sheave, friction-damped real modes).
ZERO_RTOL = 1e-6
#: Modes damped above this ratio are left out: the friction of the frozen chain makes the spins' modes nearly
#: critically damped (no resonance to draw), and their frequency comes and goes from one state to the next.
OVERDAMPED = 0.9


def structure_rows(model) -> np.ndarray:
    """State indices of the structure's positions, then its velocities (the rows and columns of J11)."""
    structure = getattr(model, "structure", None)
    if structure is None:
        raise InputError("RESULTS", type(model).__name__, "must be a run of a chain on elastic shafts "
                         "(cvt.effects.shaft_elasticity = true): J11 is the shafts' and sheaves' block")
    nc, n2 = model.family.size, model.n2
    pos = nc + np.arange(structure.n)
    return np.concatenate([pos, n2 + pos])


def structure_block(model, t: float, x: np.ndarray) -> np.ndarray:
    """J11 (2m, 2m), 1/s and 1/s^2: the model's Jacobian at ``(t, x)`` over the structure's ``m`` positions and
    velocities (:func:`structure_rows`), dense."""
    rows = structure_rows(model)
    return model.jac(t, np.asarray(x, float))[rows][:, rows].toarray()


def block_modes(J11: np.ndarray, dof_kind: np.ndarray, mdiag: np.ndarray, key: float = 0.0) -> Modes:
    """Oscillatory modes of a first-order block ``[[0, I], [A_q, A_v]]`` (``Im lambda > 0``, damping ratio below
    :data:`OVERDAMPED`), ascending in damped
    frequency, repeated pairs rotated into circular whirl, labelled by whirl (:mod:`cvtfem.modal.whirl`).

    Parameters
    ----------
    J11 : (2m, 2m)
    dof_kind, mdiag : (m,)
        Node-DOF kinds 0..5 and the mass diagonal of the positions (whirl weights).
    key : float
        Stored as ``Modes.speed`` (here the time, s).
    """
    if not np.all(np.isfinite(J11)):
        raise NumericalError("non-finite entries in the structure block J11", t=key, component="campbell-run")
    lam, X = sla.eig(J11)
    top = float(np.abs(lam).max()) if lam.size else 0.0
    keep = (lam.imag > ZERO_RTOL * max(top, 1.0)) & (-lam.real < OVERDAMPED * np.abs(lam))
    lam, X = lam[keep], X[:len(mdiag), keep]
    order = np.argsort(lam.imag)
    lam, X = lam[order], circularize(lam[order], X[:, order], dof_kind, mdiag)
    X = X / X[np.argmax(np.abs(X), axis=0), np.arange(X.shape[1])]
    labels, ratio = classify(X, mdiag, dof_kind)
    return Modes(float(key), lam, X, tuple(labels), ratio)


@dataclass(frozen=True)
class RunCampbell:
    """Tracked modes of J11 at stored times of a run.

    Attributes
    ----------
    t : (s,) s
        Stored times analysed.
    speed : (s, 2) rad/s
        Driving and driven shaft speeds at those times.
    wd : (s, k) rad/s
        Damped frequency of tracked mode ``j`` (column ``j``: identity kept by MAC from time to time).
    damping_ratio : (s, k)
    whirl : (s, k) str
    mac : (s, k)
        MAC of tracked mode ``j`` with itself at the previous time (1 at the first).
    """

    t: np.ndarray
    speed: np.ndarray
    wd: np.ndarray
    damping_ratio: np.ndarray
    whirl: np.ndarray
    mac: np.ndarray

    @property
    def jumps(self) -> list[tuple[float, int, float]]:
        """``(t, mode, MAC)`` where tracking lost a mode (MAC below :data:`~cvtfem.modal.campbell.MAC_JUMP`)."""
        return [(float(self.t[i]), int(j), float(self.mac[i, j])) for i, j in zip(*np.nonzero(self.mac < MAC_JUMP))]


def run_campbell(model, times, states, n_modes: int = 12, extra: int = 6) -> RunCampbell:
    """Modes of J11 at each ``(t, x)`` of a run, the lowest ``n_modes`` of the first time tracked by MAC.

    Parameters
    ----------
    model : ElasticChainCVT (any model with a ``structure`` block)
    times : (s,) s
    states : (s, n)
        Full states at those times (the run's ``state`` series).
    n_modes : int
        Tracked modes.
    extra : int
        Further modes kept per time so that curves can re-order.
    """
    times, states = np.asarray(times, float), np.asarray(states, float)
    if states.ndim != 2 or states.shape != (times.size, model.size) or times.size < 1:
        raise InputError("states", states.shape, f"must be one state of {model.size} values per time "
                         f"({times.size})")
    if not (isinstance(n_modes, int) and n_modes >= 1):
        raise InputError("n_modes", n_modes, "must be a positive integer")
    s = model.structure
    mdiag = s.M.diagonal()
    modes = []
    with single_thread_blas():
        for t, x in zip(times, states):
            m = block_modes(structure_block(model, t, x), s.dof_kind, mdiag, t)
            if len(m.eigenvalues) < n_modes:
                raise NumericalError(f"J11 has only {len(m.eigenvalues)} oscillatory modes, {n_modes} asked for",
                                     t=float(t), component="campbell-run")
            k = min(n_modes + extra, len(m.eigenvalues))
            modes.append(Modes(m.speed, m.eigenvalues[:k], m.shapes[:, :k], m.whirl[:k], m.whirl_ratio[:k]))
    idx, match = track(modes, n_modes)
    lam = np.array([m.eigenvalues[i] for m, i in zip(modes, idx)])
    whirl = np.array([np.array(m.whirl)[i] for m, i in zip(modes, idx)])
    speed = states[:, model.n2 + model.family.size + s.spin_dof]
    return RunCampbell(times, speed, lam.imag, -lam.real / np.abs(lam), whirl, match)
