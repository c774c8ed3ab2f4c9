"""The one place that picks the integrator of a time run: ``cvtfem.integrate`` methods or scipy's steppers."""
from __future__ import annotations

from typing import Any

import numpy as np

from cvtfem.errors import InputError

SCIPY_STEPPERS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")


def make_stepper(method: str, fun, t0: float, y0, t_end: float, rtol: float, atol: float, h: float = 0.0,
                 jac=None, n2: int = 0, first_step: float = 0.0, error_check: int = 0):
    """A step-by-step ODE solver with ``step()``, ``t``, ``y``, ``dense_output()`` and counters.

    The single place that picks the integrator: the ``cvtfem.integrate`` methods through
    :class:`~cvtfem.integrate.CvtfemSolver` (``h > 0``: fixed step, else adaptive with rtol/atol),
    otherwise scipy's ``OdeSolver`` classes (``h > 0``: first step).  ``n2``: second-order pairs
    ``x = [u, v, ...]`` with ``fun[:n2] = v`` (cvtfem implicit methods then solve for ``v`` only).
    ``first_step > 0`` (a resumed run: the step size saved at the checkpoint) overrides ``h`` as the first
    step of adaptive methods.  ``error_check``: local-error check of fixed-step cvtfem methods every that many
    steps (``CvtfemSolver.monitor``; 0: off).
    """
    from cvtfem.integrate import METHODS, CvtfemSolver

    if method in METHODS:
        try:
            return CvtfemSolver(fun, t0, np.asarray(y0, float), t_end, cvtfem_method=method, h=h or None, rtol=rtol,
                                atol=atol, n2=n2, jac=jac, first_step=(first_step or None) if not h else None,
                                error_check=error_check)
        except InputError as err:  # name the scene key, not the adapter's argument
            if err.where != "h":
                raise
            raise InputError("solver.h", h, f"must be a positive fixed step for {method!r} (it has no error "
                             "estimate, so no adaptive steps)") from None
    if method not in SCIPY_STEPPERS:
        raise InputError("solver.method", method, "must be one of " + ", ".join(SCIPY_STEPPERS + tuple(sorted(METHODS)))
                         + " for `cvtfem run`", _unavailable_hint(method))
    import scipy.integrate as si

    options: dict[str, Any] = {"rtol": rtol, "atol": atol}
    if first_step > 0:
        options["first_step"] = min(first_step, t_end - t0)
    elif h > 0:
        options["first_step"] = h
    if jac is not None and method in ("Radau", "BDF", "LSODA"):
        options["jac"] = jac
    solver = getattr(si, method)(fun, t0, np.asarray(y0, float), t_end, **options)
    if method in ("Radau", "BDF"):
        _remember_iteration_matrices(solver)
    return solver


def _remember_iteration_matrices(solver) -> None:
    """Make scipy's Radau/BDF keep a copy of the matrices they factorise last (``iteration_matrices``:
    ``"real"``, and ``"complex"`` for Radau), so that a checkpoint can restore their LU factors exactly."""
    factorise = solver.lu
    solver.iteration_matrices = {}

    def lu(A):
        solver.iteration_matrices["complex" if np.iscomplexobj(A) else "real"] = A.copy()
        return factorise(A)

    solver.lu = lu


def _unavailable_hint(method: str) -> str:
    """Why ``cvtfem.integrate`` refuses a method it names (none at present), else empty."""
    from cvtfem.integrate import solve

    try:
        solve(lambda t, y: -y, (0.0, 1.0), [1.0], method=method, h=0.1)
    except InputError as err:
        return err.rule + (f"; {err.hint}" if err.hint else "")
    except Exception:  # noqa: BLE001 - only a hint
        return ""
    return ""
