"""Compiled (numba) H2 contact of independent pin-half ends (A5, variant (e)) over a constant contact map: broad phase,
gather, the refined kernel, scatter, and the contacts' Jacobian entries.

The H1 path of :mod:`~cvtfem.elements.chain.sheave_contact_kernel` with the local contact of
:class:`~cvtfem.elements.chain.half_end_contact.HalfEndContact` (inside :class:`EndContact`: half the mirrored pair's
outputs): the 17 inputs of a pair are spread to the refined kernel's 21 (:func:`half_end_contact._spread`), the
kernel (:func:`sheave_contact_refined_kernel.refined_local_kernel`) runs on that one contact, its outputs are mapped
back (:func:`half_end_contact._gather`) and scattered through the pair's output rows.  The numpy path of
:class:`~cvtfem.machines.chain_cvt.ChainCVT` (``reference=True``) is the tested twin
(``tests/machines/test_chain_halves_refined_cvt.py``).  Arguments as the H1 kernels' (``y = [q, v, constants]``,
the pair table ``cols``, ``coef``, ``shaft``, ``rows``, ``rw``) and the constants of :func:`pack`.  Units SI.
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.chain.half_end_contact import N_POS, _gather, _spread
from cvtfem.elements.chain.sheave_contact_kernel import _inputs, _near, scatter_forces, scatter_jacobian
from cvtfem.elements.chain.sheave_contact_refined_kernel import refined_local_kernel
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.contact.kernels import LAW_CODES
from cvtfem.elements.jit import njit

N_IN, N_OUT = 2 * N_POS + 1, N_POS + 2
#: Central-difference steps of the local inputs (m, m/s, rad/s): those of ``HalfEndContact.local_jacobian``.
STEPS = np.array([1e-9] * N_POS + [1e-6] * N_POS + [1e-5])


def pack(contact, scale: float) -> tuple:
    """Kernel constants of a :class:`HalfEndContact` whose outputs are scaled by ``scale`` (0.5 inside
    :class:`EndContact`): ``(centres (2, 2), r_outer^2, meridians (2, 4), face (R_f, tan theta), end-slope factor, c (2,),
    (f0, v0, eps, scale), law code)``."""
    h2 = contact.pair
    if not h2.slopes:
        raise ValueError("half_end_contact_kernel.pack: the H2 kernel of a half end has slopes")
    return (np.ascontiguousarray(h2.centres, float), float(h2.r_outer) ** 2, np.ascontiguousarray(h2._meridians, float),
            h2.face, float(END_SLOPE_FACTOR), np.ascontiguousarray(h2.c, float),
            np.array([h2.f0, h2.v0, h2.eps, scale]), LAW_CODES[h2.law])


@njit(cache=True)
def _candidates(y, cols, coef, shaft, centres, r2, X, sh, pair):
    """Broad phase and gather: the inputs ``X[:m]`` (m, 17), shafts ``sh[:m]`` and pair indices ``pair[:m]`` of the
    ``m`` (returned) pairs whose half end lies within the outer radius of its shaft."""
    m = 0
    for i in range(cols.shape[0]):
        k = shaft[i]
        if _near(y, cols, coef, i, centres[k], r2):
            _inputs(y, cols, coef, i, X[m])
            sh[m], pair[m] = k, i
            m += 1
    return m


@njit(cache=True)
def _local(X, sh, centres, meridians, face, slope_factor, c, par, law, Y):
    """Outputs ``Y`` (m, 10) of the contacts with inputs ``X`` (m, 17) on shafts ``sh``: ``HalfEndContact.local``
    times ``par[3]``, the refined kernel called once for all of them.  Returns the kernel's flag (>= 0: a half end
    on the shaft axis)."""
    m = X.shape[0]
    Xk, Yk = np.empty((m, 2 * (N_POS + 2) + 1)), np.empty((m, N_OUT + 2))
    slip, fr = np.empty((m, 3)), np.empty((m, 3))
    _spread(X, Xk, N_POS + 2)
    bad = refined_local_kernel(Xk, sh, centres, meridians, face, True, slope_factor, c, par[0], par[1], law,
                               par[2], Yk, slip, fr)
    _gather(Yk, Y)
    for i in range(m):
        for o in range(Y.shape[1]):
            Y[i, o] *= par[3]
    return bad


@njit(cache=True)
def forces(y, cols, coef, shaft, rows, rw, centres, r2, meridians, face, slope_factor, c, par, law, Q):
    """Add the contact forces to ``Q`` (n2,); returns ``(friction power (W, <= 0), first pair with its half end on the
    shaft axis or -1)``."""
    P = cols.shape[0]
    X, sh, pair = np.empty((P, N_IN)), np.empty(P, np.int64), np.empty(P, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, X, sh, pair)
    Y = np.empty((m, N_OUT))
    bad = _local(X[:m], sh[:m], centres, meridians, face, slope_factor, c, par, law, Y)
    return scatter_forces(pair[:m], Y, rows, rw, Q), (pair[bad] if bad >= 0 else -1)


@njit(cache=True)
def local_jacobians(y, cols, coef, shaft, rows, rw, centres, r2, meridians, face, slope_factor, c, par, law,
                    steps):
    """``(pair (m,), Jl (m, 10, 17))``: the candidates in contact and their local Jacobians by central differences
    with ``steps`` (``HalfEndContact.local_jacobian``: one perturbed input column for all of them at once).  A
    candidate whose outputs are all zero (no penetration: the normal force and with it the friction vanish) is left
    out: its Jacobian is zero (``HalfEndContact.local_jacobian`` differs only within a step of contact onset, where
    its secant straddles the kink); on the benchmark's running state 116 of 300 candidates."""
    P = cols.shape[0]
    X, sh, pair = np.empty((P, N_IN)), np.empty(P, np.int64), np.empty(P, np.int64)
    m = _candidates(y, cols, coef, shaft, centres, r2, X, sh, pair)
    Y0 = np.empty((m, N_OUT))
    _local(X[:m], sh[:m], centres, meridians, face, slope_factor, c, par, law, Y0)
    k = 0
    for t in range(m):                                            # the candidates in contact, in their order
        if np.any(Y0[t] != 0.0):
            X[k], sh[k], pair[k] = X[t], sh[t], pair[t]
            k += 1
    m = k
    X0, sh = X[:m], sh[:m]
    Xs, Yp, Ym = X0.copy(), np.empty((m, N_OUT)), np.empty((m, N_OUT))
    Jl = np.empty((m, N_OUT, N_IN))
    for j in range(N_IN):
        Xs[:, j] = X0[:, j] + steps[j]
        _local(Xs, sh, centres, meridians, face, slope_factor, c, par, law, Yp)
        Xs[:, j] = X0[:, j] - steps[j]
        _local(Xs, sh, centres, meridians, face, slope_factor, c, par, law, Ym)
        Xs[:, j] = X0[:, j]
        for t in range(m):
            for o in range(N_OUT):
                Jl[t, o, j] = (Yp[t, o] - Ym[t, o]) / (2 * steps[j])
    return pair[:m], Jl


@njit(cache=True)
def jacobian(y, cols, coef, shaft, rows, rw, centres, r2, meridians, face, slope_factor, c, par, law, steps,
             n_state, r_out, c_out, v_out, dD):
    """Entries of ``dQ/dy`` of :func:`forces` (over ``y[:n_state]``) into ``r_out``, ``c_out``, ``v_out`` (their count
    returned) and ``-d(friction power)/dy`` added to ``dD``: the local Jacobians of :func:`local_jacobians` (10, 17)
    mapped on both sides ``R^T (dY/dX) P``."""
    pair, Jl = local_jacobians(y, cols, coef, shaft, rows, rw, centres, r2, meridians, face, slope_factor, c,
                               par, law, steps)
    return scatter_jacobian(pair, Jl, cols, coef, rows, rw, n_state, dD, r_out, c_out, v_out)

__all__ = ["STEPS", "forces", "jacobian", "local_jacobians", "pack"]
