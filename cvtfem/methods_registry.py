"""The one registry of integration-method names (bottom layer: plain data, no numerics).

Every method ``cvtfem.integrate`` can run and the scene schema offers (``solver.method``) is listed
here once, as ``name -> "module:attribute"`` of its class: a ``cvtfem.integrate`` stepper or a
``scipy.integrate.OdeSolver``.  ``cvtfem.integrate.methods`` resolves the classes at import;
``cvtfem.scene`` reads the names without importing any solver.  Methods added at run time go through
:func:`cvtfem.integrate.register_method`, which records them here too.
"""
from __future__ import annotations

from collections.abc import Sequence

__all__ = ["register_name", "unregister_name", "specs", "MethodNames"]

_SPECS: dict[str, object] = {
    "euler": "cvtfem.integrate.rk:Euler",
    "rk4": "cvtfem.integrate.rk:RK4",
    "dopri45": "cvtfem.integrate.rk:DOPRI45",
    "dopri56": "cvtfem.integrate.rk:DOPRI56",
    "dopri78": "cvtfem.integrate.rk:DOPRI78",
    "gbs": "cvtfem.integrate.extrapolation:GBS",
    "gbs-smooth": "cvtfem.integrate.extrapolation:GBSSmooth",
    "euler-extrapolation": "cvtfem.integrate.extrapolation:EulerExtrapolation",
    "sw24": "cvtfem.integrate.wmethods:SW24",
    "w1": "cvtfem.integrate.wmethods:W1",
    "w1-extrapolation": "cvtfem.integrate.wmethods:W1Extrapolation",
    "ros34pw2": "cvtfem.integrate.rosw:ROS34PW2",
    "rodas4": "cvtfem.integrate.rosenbrock:Rodas4",
    "rodas5p": "cvtfem.integrate.rosenbrock:Rodas5P",
    "radau5": "cvtfem.integrate.radau:Radau5",
    "theta": "cvtfem.integrate.theta:Theta",
    "trapezoidal": "cvtfem.integrate.theta:Trapezoidal",
    "implicit-euler": "cvtfem.integrate.theta:ImplicitEuler",
    "dumka3": "cvtfem.integrate.dumka3:DUMKA3",
    "strang-friction": "cvtfem.integrate.imex:StrangFriction",
    "rock2": "cvtfem.integrate.rock:ROCK2",
    "rock4": "cvtfem.integrate.rock:ROCK4",
    "rkc": "cvtfem.integrate.stabilized:RKC",
    "RK23": "scipy.integrate:RK23",
    "RK45": "scipy.integrate:RK45",
    "DOP853": "scipy.integrate:DOP853",
    "Radau": "scipy.integrate:Radau",
    "BDF": "scipy.integrate:BDF",
    "LSODA": "scipy.integrate:LSODA",
}


def register_name(name: str, spec: object) -> None:
    """Record method ``name`` (``spec``: its class, or ``"module:attribute"``); a taken name is an error."""
    if name in _SPECS and _SPECS[name] is not spec:
        raise ValueError(f"integration method {name!r} is already registered")
    _SPECS[name] = spec


def unregister_name(name: str) -> None:
    """Forget a method registered at run time (built-in names stay)."""
    if isinstance(_SPECS.get(name), str):
        raise ValueError(f"integration method {name!r} is built in")
    _SPECS.pop(name, None)


def specs() -> dict[str, object]:
    """A copy of ``name -> spec`` in registration order."""
    return dict(_SPECS)


class MethodNames(Sequence):
    """Live, read-only view of the registered names (the scene schema's ``choices``)."""

    def __getitem__(self, i):
        return tuple(_SPECS)[i]

    def __len__(self) -> int:
        return len(_SPECS)

    def __contains__(self, name) -> bool:
        return name in _SPECS

    def __repr__(self) -> str:
        return f"MethodNames{tuple(_SPECS)!r}"
