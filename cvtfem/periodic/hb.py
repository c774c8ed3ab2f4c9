"""Harmonic balance of torsional networks: Galerkin, AFT, Newton-Kantorovich.

Unknowns are complex harmonics ``a[s, k]`` of node ``s`` for ``n = k - N``,
``n = -N..N`` (spec B:(8)), ``x_s(t) = sum_n a_s^n exp(i n omega t)`` with
conjugate symmetry.  The Galerkin residual (B:(9), physical time, spec 8.2)
is ``r_s^n = (-n^2 omega^2 m_s + i n omega b_s) a_s^n + (D^T F)_s^n - p_s^n``
with ``F_e^n`` the harmonics of ``f_e(l_e(t)) + d_e l_e'(t)``, computed by the
alternating frequency-time (AFT) method.  Newton-Kantorovich (B:(28)-(30))
linearises ``f_e`` with the Toeplitz blocks ``(C_e)_{nm} = c_e^(n-m)`` of
B:(38), the Fourier coefficients of ``f_e'(l_e(t))``; every linear solve goes
through the block sweep.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from cvtfem.assembly.numbering import Topology, through_numbering
from cvtfem.blas import single_thread_blas
from cvtfem.elements.torsional import TorsionalNetwork, link_force
from cvtfem.errors import InputError, NumericalError
from cvtfem.periodic.blocktri import check_grounded, solve_blocks, solve_mixed

log = logging.getLogger(__name__)


def default_samples(N: int) -> int:
    """AFT samples: a power of two >= 8 N (and >= 64); spec 11.8 needs M >= 4N + 1."""
    return max(64, 1 << int(np.ceil(np.log2(8 * max(N, 1)))))


def to_time(a: np.ndarray, M: int) -> np.ndarray:
    """Samples ``x(t_m)``, ``t_m = m T / M`` (..., M) of harmonics ``a`` (..., 2N+1)."""
    K = a.shape[-1]
    N = (K - 1) // 2
    if M < 2 * N + 1:
        raise InputError("samples", M, f"must be at least 2N+1 = {2 * N + 1}")
    X = np.zeros(a.shape[:-1] + (M,), complex)
    X[..., np.arange(-N, N + 1) % M] = a
    return (np.fft.ifft(X, axis=-1) * M).real


def to_harmonics(x: np.ndarray, N: int) -> np.ndarray:
    """Harmonics ``n = -N..N`` (..., 2N+1) of samples over one period (..., M)."""
    M = x.shape[-1]
    return np.fft.fft(x, axis=-1)[..., np.arange(-N, N + 1) % M] / M


def load_harmonics(net: TorsionalNetwork, N: int) -> np.ndarray:
    """``p_s^n`` of B:(13) (S, 2N+1), complex N; orders above N are dropped."""
    p = np.zeros((net.n_nodes, 2 * N + 1), complex)
    for k, n in enumerate(net.orders.tolist()):
        if n > N:
            continue
        if n == 0:
            p[:, N] += net.Q[:, k].real
        else:
            p[:, N + n] += net.Q[:, k] / 2
            p[:, N - n] += np.conj(net.Q[:, k]) / 2
    return p


@dataclass(frozen=True)
class PeriodicSolution:
    """A periodic response (all harmonics of all nodes) and how it was found.

    Attributes
    ----------
    network : TorsionalNetwork
    omega : float, rad/s
        Base (cycle) angular frequency; the period is ``2 pi / omega``.
    a : ndarray (S, 2N+1) complex, m
        Harmonics ``n = -N..N`` of the circumferential displacements.
    converged : bool
    iterations : int
        Newton iterations (0 for a linear solve).
    residuals : tuple of float
        Relative residual norm before each iteration and at the end.
    method : str
        "sweep" or "sparse" (the linear solver of the last iteration).
    message : str
    """

    network: TorsionalNetwork
    omega: float
    a: np.ndarray
    converged: bool = True
    iterations: int = 0
    residuals: tuple[float, ...] = ()
    method: str = "sweep"
    message: str = "converged"
    samples: int = field(default=0)

    @property
    def N(self) -> int:
        return (self.a.shape[1] - 1) // 2

    @property
    def period(self) -> float:
        return 2 * np.pi / self.omega

    def displacements(self, M: int = 1024) -> np.ndarray:
        """``x`` over one period (S, M), m."""
        return to_time(self.a, M)

    def state(self) -> np.ndarray:
        """State ``[x(0), v(0)]`` (2S,) at the start of the period (m, m/s)."""
        n = np.arange(-self.N, self.N + 1)
        return np.concatenate([self.a.sum(axis=1).real, (self.a * (1j * n * self.omega)).sum(axis=1).real])

    def link_forces(self, M: int = 1024) -> np.ndarray:
        """Link forces ``f(l) + d l'`` over one period (E, M), N."""
        D = self.network.incidence()
        n = np.arange(-self.N, self.N + 1)
        la = D @ self.a
        return self.network.forces(to_time(la, M), to_time(1j * n * self.omega * la, M))

    def link_moments(self, M: int = 1024) -> np.ndarray:
        """Link moments at the first end ``i`` of each link (E, M), N m (force x radius)."""
        return self.link_forces(M) * self.network.radius[self.network.i][:, None]

    def amplitudes(self) -> np.ndarray:
        """One-sided amplitude of harmonic ``n = 0..N`` of every node (S, N+1), m."""
        amp = 2 * np.abs(self.a[:, self.N:])
        amp[:, 0] /= 2
        return amp


def _node_term(net: TorsionalNetwork, omega: float, n: np.ndarray) -> np.ndarray:
    return -(n * omega) ** 2 * net.m[:, None] + 1j * n * omega * net.b[:, None]


def residual(net: TorsionalNetwork, omega: float, a: np.ndarray, p: np.ndarray, M: int,
             D=None) -> tuple[np.ndarray, np.ndarray]:
    """Galerkin residual ``r`` (S, K) and link stiffness samples ``f'(l(t))`` (E, M) by AFT."""
    N = (a.shape[1] - 1) // 2
    n = np.arange(-N, N + 1)
    D = net.incidence() if D is None else D
    la = D @ a
    f, df = link_force(to_time(la, M), net.law, net.k_in, net.k_out, net.h, net.zone)
    F = to_harmonics(f, N) + 1j * n * omega * net.d[:, None] * la
    r = _node_term(net, omega, n) * a + D.T @ F - p
    return r, df


def _linear_blocks(net: TorsionalNetwork, omega: float, n: np.ndarray):
    Nb = _node_term(net, omega, n)[:, :, None, None]
    Lb = (net.k_out[:, None] + 1j * n * omega * net.d[:, None])[:, :, None, None]
    return Nb, Lb


def prepare(net: TorsionalNetwork) -> Topology | None:
    """Check grounding and number the network (None for loops)."""
    check_grounded(net.n_nodes, net.i, net.j, net.k_in + net.k_out, net.names)
    prefer = np.zeros(net.n_nodes, bool)
    nl = net.law != 0
    prefer[net.i[nl]] = True
    prefer[net.j[nl][net.j[nl] >= 0]] = True
    return through_numbering(net.n_nodes, net.i, net.j, prefer)


def solve_linear(net: TorsionalNetwork, omega: float, N: int, stiffness: str = "contact",
                 method: str = "auto", topo: Topology | None = None) -> PeriodicSolution:
    """Linear periodic response (spec B:(10)-(12)): harmonics decouple, one sweep per batch.

    Parameters
    ----------
    net : TorsionalNetwork
    omega : float, rad/s
        Base frequency.
    N : int
        Number of harmonics.
    stiffness : str
        Nonlinear links taken with their "contact" or "gap" stiffness.
    method : str
        "auto", "sweep" or "sparse" (see :func:`cvtfem.periodic.blocktri.solve_blocks`).
    """
    _check(omega, N)
    lin = net.linearized(stiffness)
    topo = prepare(lin) if topo is None else topo
    n = np.arange(-N, N + 1)
    Nb, Lb = _linear_blocks(lin, omega, n)
    g = load_harmonics(lin, N)[:, :, None]
    a, used = solve_blocks(Nb, Lb, lin.i, lin.j, g, topo, method)
    return PeriodicSolution(lin, omega, _symmetrize(a[:, :, 0]), method=used)


def _check(omega: float, N: int) -> None:
    if not (np.isfinite(omega) and omega > 0):
        raise InputError("omega", omega, "must be a positive finite angular frequency (rad/s)")
    if int(N) != N or N < 1:
        raise InputError("harmonics", N, "must be a positive integer")


def _symmetrize(a: np.ndarray) -> np.ndarray:
    return (a + np.conj(a[:, ::-1])) / 2


def linearize(net: TorsionalNetwork, omega: float, a: np.ndarray, p: np.ndarray, M: int, D):
    """Residual ``r`` (S, K) and Jacobian blocks: node ``N`` (S, 1, K, K), link ``L`` (E, 1, K, K).

    ``L_e`` is the Toeplitz matrix of B:(38) (Fourier coefficients of
    ``f_e'(l_e(t))`` by FFT, ``(L_e)_{nm} = c_e^(n-m)``) plus ``i n omega d_e``.
    """
    N = (a.shape[1] - 1) // 2
    n = np.arange(-N, N + 1)
    K = len(n)
    r, df = residual(net, omega, a, p, M, D)
    chat = np.fft.fft(df, axis=-1) / M
    L = chat[:, (n[:, None] - n[None, :]) % M]
    diag = np.arange(K)
    L[:, diag, diag] += (1j * n * omega)[None, :] * net.d[:, None]
    lin = np.flatnonzero(net.law == 0)  # exactly diagonal (no FFT round-off): the sweep's fast path
    L[lin] = 0
    L[lin[:, None], diag, diag] = net.k_out[lin, None] + (1j * n * omega)[None, :] * net.d[lin, None]
    Nb = np.zeros((net.n_nodes, 1, K, K), complex)
    Nb[:, 0, np.arange(K), np.arange(K)] = _node_term(net, omega, n)
    return r, Nb, L[:, None]


def linearize_mixed(net: TorsionalNetwork, omega: float, a: np.ndarray, p: np.ndarray, M: int, D):
    """:func:`linearize` in mixed storage: ``(r, Nd, Ld, dense, Ldense)``.

    Node blocks and the blocks of linear links are diagonal in the harmonic index and kept as
    vectors ``Nd`` (S, K), ``Ld`` (E, K); only the links with backlash (``dense``) get their
    full Toeplitz blocks ``Ldense`` (Ed, K, K).  Same entries as :func:`linearize`.
    """
    N = (a.shape[1] - 1) // 2
    n = np.arange(-N, N + 1)
    K = len(n)
    r, df = residual(net, omega, a, p, M, D)
    dense = np.flatnonzero(net.law != 0)
    chat = np.fft.fft(df[dense], axis=-1) / M
    Ldense = chat[:, (n[:, None] - n[None, :]) % M]
    diag = np.arange(K)
    iw = (1j * n * omega)[None, :]
    Ldense[:, diag, diag] += iw * net.d[dense, None]
    Ld = net.k_out[:, None] + iw * net.d[:, None]
    return r, _node_term(net, omega, n), Ld, dense, Ldense


def newton_step(net, omega, a, p, M, topo, D, method="auto"):
    """One Newton-Kantorovich correction (B:(29)): returns ``(delta, r, method_used)``.

    Trees go through the sweep in mixed storage (only backlash links' blocks full);
    ``method="sparse"`` or loops assemble the full blocks (:func:`linearize`).
    """
    if topo is not None and method != "sparse":
        r, Nd, Ld, dense, Ldense = linearize_mixed(net, omega, a, p, M, D)
        # the operator is real: solving for the conjugate-symmetric part of r is what
        # _symmetrize(delta) gives anyway, and the real-basis sweep needs it
        delta, used = solve_mixed(Nd, Ld, dense, Ldense, net.i, net.j, -_symmetrize(r), topo, method)
        return _symmetrize(delta), r, used
    r, Nb, L = linearize(net, omega, a, p, M, D)
    delta, used = solve_blocks(Nb, L, net.i, net.j, -r[:, None], topo, method)
    return _symmetrize(delta[:, 0]), r, used


def newton(net: TorsionalNetwork, omega: float, p: np.ndarray, a: np.ndarray, M: int, topo, D,
           tol: float, max_iter: int, method: str = "auto") -> tuple[np.ndarray, bool, list[float], str]:
    """Damped Newton-Kantorovich iterations B:(28) from ``a``; returns ``(a, converged, history, method)``.

    The step is halved until ``||r||`` decreases by ``1 - alpha / 4`` (spec 4.3);
    the iteration stops early when no step length decreases it.
    """
    scale = max(np.linalg.norm(p), 1e-300)
    history: list[float] = []
    used = "sweep"
    for it in range(max_iter + 1):
        delta, r, used_now = newton_step(net, omega, a, p, M, topo, D, method)
        norm = np.linalg.norm(r) / scale
        history.append(norm)
        if not np.isfinite(norm) or norm <= tol or it == max_iter:
            break
        used = used_now
        alpha = 1.0
        while alpha >= 1 / 256:
            trial = a + alpha * delta
            r_trial, _ = residual(net, omega, trial, p, M, D)
            if np.linalg.norm(r_trial) / scale < (1 - 0.25 * alpha) * norm:
                break
            alpha /= 2
        else:
            break
        a = trial
        log.debug("Newton %d: residual %.3e, step %.3g", it, norm, alpha)
    return a, bool(history[-1] <= tol), history, used


def _gap_fraction(net: TorsionalNetwork, omega: float, N: int, topo) -> float:
    """Largest load factor for which the gap-stiffness linear response stays in the gap (exact there)."""
    lin = solve_linear(net.linearized("gap"), omega, N, topo=topo)
    l = net.incidence() @ lin.displacements(default_samples(N))
    nl = net.law != 0
    half = np.where(net.law == 1, net.h / 2, net.h) * (1 - net.zone)
    lim = np.where(net.law[:, None] == 1, np.abs(l), np.maximum(l, 0.0))[nl].max(axis=1, initial=0.0)
    ratios = half[nl] / np.maximum(lim, 1e-300)
    return float(min(1.0, ratios.min(initial=1.0)))


def solve_periodic(net: TorsionalNetwork, omega: float, N: int, samples: int = 0, tol: float = 1e-10,
                   max_iter: int = 50, a0: np.ndarray | None = None, method: str = "auto",
                   raise_on_failure: bool = False) -> PeriodicSolution:
    """Nonlinear periodic response by damped Newton-Kantorovich iterations (spec 8.4, 11.8).

    Newton starts from ``a0``, else (or when that fails) from the linear response
    with contact stiffness; if that fails too it continues in the load factor ``lambda`` from the largest
    load whose gap-stiffness linear response stays inside the gaps (where it is
    exact) to 1, halving the load step on failure (spec 8.5, practical reading).

    Parameters
    ----------
    net : TorsionalNetwork
    omega : float, rad/s
        Base frequency.
    N : int
        Harmonics kept, ``n = -N..N``.
    samples : int
        AFT samples per period (0: :func:`default_samples`).
    tol : float
        Stop when ``||r|| <= tol * ||p||`` (harmonic 2-norms).
    max_iter : int
        Newton iterations per attempt.
    a0 : ndarray (S, 2N+1), optional
        Start; default as above.
    raise_on_failure : bool
        Raise :class:`NumericalError` instead of returning ``converged=False``.
    """
    with single_thread_blas():
        return _solve_periodic(net, omega, N, samples, tol, max_iter, a0, method, raise_on_failure)


def _solve_periodic(net, omega, N, samples, tol, max_iter, a0, method, raise_on_failure):
    _check(omega, N)
    M = samples or default_samples(N)
    if M < 4 * N + 1:
        raise InputError("samples", M, f"must be at least 4N+1 = {4 * N + 1} (aliasing of c(t) harmonics)")
    topo = prepare(net)
    p = load_harmonics(net, N)
    D = net.incidence()
    start = solve_linear(net, omega, N, topo=topo).a if a0 is None else np.array(a0, complex)
    a, ok, history, used = newton(net, omega, p, start, M, topo, D, tol, max_iter, method)
    iterations = len(history) - 1
    if not ok and a0 is not None:  # a given start failed: try the default one
        a, ok, history, used = newton(net, omega, p, solve_linear(net, omega, N, topo=topo).a, M, topo, D, tol,
                                      max_iter, method)
        iterations += len(history) - 1
    lam = 1.0
    if not ok:
        a_full, history_full = a, history  # full-load iterate: what a failure returns
        lam = _gap_fraction(net, omega, N, topo)
        a = solve_linear(net.linearized("gap"), omega, N, topo=topo).a * lam
        step = 1.0 - lam
        while lam < 1.0 and step > 1e-4:
            target = min(1.0, lam + step)
            trial, ok, hist, used = newton(net, omega, p * target, a * (target / max(lam, 1e-300)), M, topo, D,
                                           tol, max_iter, method)
            iterations += len(hist) - 1
            if ok:
                lam, a, history = target, trial, hist
                step *= 2
            else:
                step /= 2
        ok = lam >= 1.0 and ok
        if not ok:
            a, history = a_full, history_full
    if ok:
        return PeriodicSolution(net, omega, a, True, iterations, tuple(history), used, "converged", M)
    stagnated = len(history) > 3 and history[-1] > 0.5 * history[-4]
    msg = (f"Newton-Kantorovich did not converge at omega = {omega:.6g} rad/s ({iterations} iterations; "
           f"load continuation reached load factor {lam:.3g} of 1): relative residual {history[-1]:.3e} > "
           f"tol {tol:.1e} at full load"
           + ("; stagnating: the response may not be periodic with this period, or N is too small"
              if stagnated else ""))
    if raise_on_failure:
        raise NumericalError(msg, component="harmonic balance")
    return PeriodicSolution(net, omega, a, False, iterations, tuple(history), used, msg, M)
