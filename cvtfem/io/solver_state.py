"""Integrator memory in a checkpoint, so that a resumed run is bitwise equal to an uninterrupted one.

A checkpoint stores fixed-size float vectors (:mod:`cvtfem.io.checkpoint`); this module flattens the
step-to-step memory of the methods that carry one and restores it into a freshly built solver:

- cvtfem theta family (``trapezoidal``, ``implicit-euler``, ``theta``) through
  :class:`~cvtfem.integrate.CvtfemSolver`: Jacobian, ``h alpha`` of the iteration matrix and whether
  its LU is current, previous step and slope (error estimate), ``F`` at the current point, and the
  Newton solver's memory (Jacobian marked stale, contraction estimate of the last solve);
- scipy ``Radau``: Jacobian and whether it is current, whether the LU factors are current, the last two
  step sizes and error norms (predictive controller), the collocation increments ``Z``, ``y_old``,
  ``t_old`` (dense output = Newton start of the next step), the finite-difference factors;
- scipy ``BDF``: the difference array ``D``, order, equal-step count, step, Jacobian, LU flag, factors.

LU factors are not stored: they are recomputed with the same call from the matrix that was factorised
(LAPACK is deterministic for the same input).  For scipy's Radau and BDF that matrix is saved as it was
(``iteration_matrices``, recorded by :func:`cvtfem.analysis.steppers.make_stepper`): rebuilding it from
the current step is wrong, because scipy keeps a factorisation across steps whose sizes differ in the last
bits (Radau: ``h = (t + h) - t`` is re-rounded every step; BDF keeps the LU after an error rejection), and
that difference surfaced at 1e-9 under some OpenBLAS kernels (issue 11).  The theta family rebuilds
``I - h alpha J`` reduced from its saved ``h alpha``. Unknown values (``None``) are stored as NaN. Methods without memory (explicit
Runge-Kutta) have an empty state; scipy ``LSODA`` keeps its history inside Fortran work arrays that
scipy does not expose for writing, so it restarts (agreement within the tolerance only).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

__all__ = ["state_size", "export_state", "import_state", "BITWISE"]

#: Methods whose resumed run is bitwise equal (besides those without memory).
BITWISE = ("trapezoidal", "implicit-euler", "theta", "Radau", "BDF")
BDF_ROWS = 5 + 3  # scipy.integrate BDF: MAX_ORDER + 3 rows of D


def _fields(method: str, n: int, n2: int) -> tuple[tuple[str, int], ...]:
    if method in ("trapezoidal", "implicit-euler", "theta"):
        return (("gamma", 1), ("lu_valid", 1), ("prev_h", 1), ("prev_f", n), ("J", n * n), ("f_start", n),
                ("newton_stale", 1), ("newton_eta", 1))
    if method == "Radau":
        return (("h_abs_old", 1), ("error_norm_old", 1), ("J", n * n), ("current_jac", 1), ("lu_valid", 1),
                ("Z", 3 * n), ("y_old", n), ("t_old", 1), ("jac_factor", n), ("h_abs", 1),
                ("A_real", n * n), ("A_complex", 2 * n * n))
    if method == "BDF":
        return (("D", BDF_ROWS * n), ("order", 1), ("n_equal_steps", 1), ("h_abs", 1), ("J", n * n),
                ("lu_valid", 1), ("jac_factor", n), ("A_real", n * n))
    return ()


def state_size(method: str, n: int, n2: int = 0) -> int:
    """Floats of the memory of ``method`` for ``n`` states (0: nothing to save)."""
    return sum(k for _, k in _fields(method, n, n2))


def _opt(v, size: int) -> np.ndarray:
    if v is None:
        return np.full(size, np.nan)
    v = v.toarray() if sp.issparse(v) else np.asarray(v, dtype=float)
    return v.ravel()


def _get(v: np.ndarray):
    return None if np.all(np.isnan(v)) else v


def export_state(method: str, solver, n: int, n2: int = 0) -> np.ndarray:
    """The memory of ``solver`` (a :class:`CvtfemSolver` or scipy ``OdeSolver``) as one vector."""
    f = _fields(method, n, n2)
    if not f:
        return np.zeros(0)
    if method in ("Radau", "BDF"):
        s = solver
        valid = getattr(s, "LU_real" if method == "Radau" else "LU") is not None
        A = s.iteration_matrices if valid else {}
        v = {"J": _opt(s.J, n * n), "lu_valid": [float(valid)], "jac_factor": _opt(s.jac_factor, n),
             "h_abs": [s.h_abs], "A_real": _opt(A.get("real"), n * n)}
        if method == "Radau":
            v.update(h_abs_old=[math.nan if s.h_abs_old is None else s.h_abs_old],
                     error_norm_old=[math.nan if s.error_norm_old is None else s.error_norm_old],
                     current_jac=[float(s.current_jac)], Z=_opt(s.Z, 3 * n), y_old=_opt(s.y_old, n),
                     t_old=[math.nan if s.t_old is None else s.t_old],
                     A_complex=_opt(None, 2 * n * n) if "complex" not in A else
                     np.concatenate([_opt(A["complex"].real, n * n), _opt(A["complex"].imag, n * n)]))
        else:
            v.update(D=np.asarray(s.D[:BDF_ROWS], dtype=float).ravel(), order=[s.order],
                     n_equal_steps=[s.n_equal_steps])
    else:
        st = solver.stepper
        prev = st._prev
        start = st._start
        at_t = start is not None and start[0] == solver.t and np.array_equal(start[1], solver.y)
        v = {"gamma": [math.nan if st._gamma is None else st._gamma],
             "lu_valid": [float(st.newton.B is not None)], "prev_h": [math.nan if prev is None else prev[0]],
             "prev_f": _opt(None if prev is None else prev[1], n), "J": _opt(st.J, n * n),
             "f_start": _opt(start[2] if at_t else None, n), "newton_stale": [float(st.newton.stale)],
             "newton_eta": [st.newton._eta]}
    return np.concatenate([np.asarray(v[name], dtype=float).ravel() for name, _ in f])


def import_state(method: str, solver, vec: np.ndarray, n: int, n2: int = 0) -> None:
    """Restore the memory saved by :func:`export_state` into a solver built at the checkpoint's ``t, y``.

    Counters change (the LU factors are recomputed): set them afterwards.
    """
    f = _fields(method, n, n2)
    if not f:
        return
    v, i = {}, 0
    for name, k in f:
        v[name] = np.asarray(vec[i:i + k], dtype=float)
        i += k
    if method in ("Radau", "BDF"):
        _import_scipy(method, solver, v, n)
    else:
        _import_theta(solver, v, n, n2)


def _matrix(fmt: str | None, dense: np.ndarray, n: int):
    """``dense`` (n*n) as an (n, n) array, or a sparse matrix of format ``fmt`` (``csc``, ``csr``)."""
    J = dense.reshape(n, n)
    return J if fmt is None else sp.csr_matrix(J).asformat(fmt)


def _import_scipy(method: str, s, v: dict, n: int) -> None:
    J = _get(v["J"])
    fmt = s.J.format if sp.issparse(s.J) else None
    if J is not None:
        s.J = _matrix(fmt, J, n)
    jf = _get(v["jac_factor"])
    s.jac_factor = None if jf is None else jf.copy()
    s.h_abs = float(v["h_abs"][0])
    A_real = _get(v["A_real"]) if v["lu_valid"][0] == 1.0 else None
    LU_real = None if A_real is None else s.lu(_matrix(fmt, A_real.copy(), n))
    if method == "Radau":
        s.h_abs_old = None if math.isnan(v["h_abs_old"][0]) else float(v["h_abs_old"][0])
        s.error_norm_old = None if math.isnan(v["error_norm_old"][0]) else float(v["error_norm_old"][0])
        s.current_jac = bool(v["current_jac"][0])
        Z = _get(v["Z"])
        if Z is not None:
            s.Z, s.y_old, s.t_old = Z.reshape(3, n), v["y_old"].copy(), float(v["t_old"][0])
            s.sol = s._compute_dense_output()
        re_im = v["A_complex"].reshape(2, n * n)
        A_complex = None if LU_real is None else _matrix(fmt, re_im[0] + 1j * re_im[1], n)
        s.LU_real, s.LU_complex = LU_real, None if A_complex is None else s.lu(A_complex)
    else:
        s.D[:BDF_ROWS] = v["D"].reshape(BDF_ROWS, n)
        s.order, s.n_equal_steps = int(v["order"][0]), int(v["n_equal_steps"][0])
        s.LU = LU_real


def _import_theta(solver, v: dict, n: int, n2: int) -> None:
    from cvtfem.integrate.linsolve import DENSE_MAX, reduced_matrix

    st = solver.stepper
    J = _get(v["J"])
    if J is not None:
        st.J = _matrix("csr" if n > DENSE_MAX else None, J, n)   # as JacobianProvider returns it
    gamma = float(v["gamma"][0])
    st._gamma = None if math.isnan(gamma) else gamma
    st._prev = None if math.isnan(v["prev_h"][0]) else (float(v["prev_h"][0]), v["prev_f"].copy())
    f_start = _get(v["f_start"])
    if f_start is not None:
        st._start = (solver.t, np.array(solver.y), f_start.copy())
    st.newton.invalidate()
    if v["lu_valid"][0] == 1.0 and st.J is not None and st._gamma is not None:
        st.newton._set(reduced_matrix(st.J, n2, st._gamma))
    st.newton.stale, st.newton._eta = bool(v["newton_stale"][0]), float(v["newton_eta"][0])
