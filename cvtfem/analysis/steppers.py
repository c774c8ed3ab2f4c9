"""The one place that builds the step loop of a time run from the scene's solver settings."""
from __future__ import annotations

import numpy as np

from cvtfem.errors import InputError


def make_stepper(method: str, fun, t0: float, y0, t_end: float, rtol: float, atol: float, h: float = 0.0,
                 jac=None, n2: int = 0, first_step: float = 0.0, error_check: int = 0, *, events=None,
                 jac_sparsity=None, stall_steps: int = 0, stall_h: float = 0.0, switch=None, split=None,
                 options: dict | None = None):
    """The :class:`~cvtfem.integrate.stepping.Stepping` of a run from ``(t0, y0)`` to ``t_end``.

    ``method``: any registered name (``h > 0``: fixed step for playground methods, first step for scipy's
    and for methods run adaptive with rtol/atol); ``n2``: second-order pairs ``x = [u, v, ...]``;
    ``first_step > 0`` (a resumed run: the step size saved at the checkpoint) overrides ``h`` as the first
    step of adaptive methods; ``error_check``: local-error check of fixed steps every that many steps;
    ``events``: ``(indicators, direction, terminal)``; ``switch``: ``switch(t, x, fired) -> x or None`` at events;
    ``stall_steps``/``stall_h``: the stall guard; ``split``: the model's stiff split (``strang-friction``);
    ``options``: the method's own (the scene's ``solver.options``, :func:`check_method_options`).
    """
    from cvtfem.integrate import METHODS, SCIPY_METHODS
    from cvtfem.integrate.stepping import Stepping, make_engine
    from cvtfem.integrate.system import as_system

    if method not in METHODS and method not in SCIPY_METHODS:
        raise InputError("solver.method", method, "must be one of " + ", ".join(
            tuple(SCIPY_METHODS) + tuple(sorted(METHODS))) + " for `cvtfem run`")
    options = check_method_options(method, options or {})
    y0 = np.asarray(y0, float)
    system = as_system(fun, y0, n2=n2, jac=jac, jac_sparsity=jac_sparsity, events=events, switch=switch,
                       split=split)
    native = method in METHODS
    start = (first_step or None) if native else (first_step or h or None)
    try:
        engine = make_engine(method, system, t0, y0, t_end, rtol, atol, (h or None) if native else None,
                             None, error_check, first_step=None if native and h else start, options=options)
    except InputError as err:  # name the scene key, not the engine's argument
        if err.where in options:
            raise InputError("solver.options", f"{err.where}={options[err.where]}", err.rule) from None
        if err.where != "method":
            raise
        if "no error estimate" not in err.rule:     # e.g. strang-friction on a model without a stiff split
            raise InputError("solver.method", method, err.rule) from None
        raise InputError("solver.h", h, f"must be a positive fixed step for {method!r} (it has no error "
                         "estimate, so no adaptive steps)") from None
    return Stepping(engine, t0, y0, t_end, stall_steps=stall_steps, stall_h=stall_h)


def check_method_options(method: str, options: dict) -> dict:
    """``options`` if ``method`` accepts each of them, else an :class:`InputError` naming ``solver.options`` (a scene's
    option is never ignored)."""
    from cvtfem.integrate.methods import method_options

    accepted = method_options(method)
    for key, value in options.items():
        if key not in accepted:
            raise InputError("solver.options", f"{key}={value}", f"must be an option of {method!r}: "
                             + (", ".join(sorted(accepted)) if accepted else "it takes none"))
    return options
