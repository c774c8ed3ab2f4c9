"""Stability of periodic responses: Floquet multipliers from one period of time integration.

The variational equations about ``x*(t)`` (spec 11.8) are
``M y'' + (B + D^T diag(d) D) y' + D^T diag(f'(l*(t))) D y = 0``; integrating the
2S fundamental solutions over one period gives the monodromy matrix, whose
eigenvalues (multipliers) lie inside the unit circle for a stable response.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.torsional import TorsionalNetwork, link_force
from cvtfem.errors import NumericalError
from cvtfem.periodic import transient
from cvtfem.periodic.hb import PeriodicSolution


@dataclass(frozen=True)
class Floquet:
    """Floquet multipliers of a periodic solution.

    Attributes
    ----------
    multipliers : ndarray (2S,) complex
        Eigenvalues of the monodromy matrix, sorted by decreasing modulus.
    stable : bool
        ``max |mu| < 1``.
    nfev : int
        Right-hand-side evaluations of the variational integration.
    """

    multipliers: np.ndarray
    stable: bool
    nfev: int

    @property
    def spectral_radius(self) -> float:
        return float(np.abs(self.multipliers[0]))


#: DOP853 right-hand-side evaluations per radian of the stiffest rate over one period (engine gear train,
#: rtol 1e-8: 38,150 evaluations for a Gershgorin rate x period of 1095).
EVALUATIONS_PER_RADIAN = 40


def evaluations_estimate(net: TorsionalNetwork, omega: float) -> float:
    """Rough right-hand-side evaluations of :func:`floquet` at ``omega`` (rad/s): ``EVALUATIONS_PER_RADIAN``
    x the period x the stiffest rate, a Gershgorin bound of ``M^-1 K`` (contact stiffness, as a frequency)
    and ``M^-1 C`` (1/s); explicit integration pays for every stiff mode whether it is excited or not."""
    inner = net.j >= 0

    def rows(v):
        return np.bincount(net.i, v, net.n_nodes) + np.bincount(net.j[inner], v[inner], net.n_nodes)

    stiff = rows(2 * np.maximum(net.k_out, net.k_in)) / net.m
    damp = (rows(2 * net.d) + net.b) / net.m
    return EVALUATIONS_PER_RADIAN * max(np.sqrt(stiff.max()), damp.max(), omega) * 2 * np.pi / omega


def floquet(sol: PeriodicSolution, rtol: float = 1e-9, method: str = "DOP853") -> Floquet:
    """Monodromy matrix by integrating the variational equations over one period."""
    net = sol.network
    S = net.n_nodes
    D = net.incidence().toarray()
    n = np.arange(-sol.N, sol.N + 1)
    la = D @ sol.a
    C = np.diag(net.b) + D.T @ (net.d[:, None] * D)
    Minv = 1 / net.m

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        Y = y.reshape(2 * S, 2 * S)
        l = (la @ np.exp(1j * n * sol.omega * t)).real
        _, df = link_force(l, net.law, net.k_in, net.k_out, net.h, net.zone)
        K = D.T @ (df[:, None] * D)
        acc = -Minv[:, None] * (K @ Y[:S] + C @ Y[S:])
        return np.concatenate([Y[S:], acc]).ravel()

    out = transient.integrate(rhs, (0.0, sol.period), np.eye(2 * S).ravel(), method=method, rtol=rtol,
                              atol=rtol * 1e-3)
    if out.status != 0:
        raise NumericalError(f"variational integration failed: {out.message}", component="floquet")
    mu = np.linalg.eigvals(out.y[:, -1].reshape(2 * S, 2 * S))
    mu = mu[np.argsort(-np.abs(mu))]
    return Floquet(mu, bool(np.abs(mu[0]) < 1), int(out.nfev))
