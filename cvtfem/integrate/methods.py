"""Method registry: name -> stepper class (immutable mapping built at import)."""
from __future__ import annotations

from types import MappingProxyType

from cvtfem.integrate import extrapolation, rk, rock, stabilized, theta, wmethods

__all__ = ["METHODS", "SCIPY_METHODS", "UNAVAILABLE", "all_options"]

METHODS = MappingProxyType({cls.name: cls for cls in (
    rk.Euler, rk.RK4, rk.DOPRI45, rk.DOPRI56, rk.DOPRI78,
    extrapolation.EulerExtrapolation, extrapolation.GBS, extrapolation.GBSSmooth,
    wmethods.SW24, wmethods.W1, wmethods.W1Extrapolation,
    theta.Theta, theta.Trapezoidal, theta.ImplicitEuler,
    stabilized.RKC, rock.ROCK2, rock.ROCK4)})
SCIPY_METHODS = frozenset({"RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA"})
#: Names from the issue that are not implemented, with the reason (shown in the InputError).
_TABLES = ("its stability polynomials come from published coefficient tables ({}) that are "
           "not vendored in cvtfem yet; use 'rkc' (analytic coefficients) meanwhile")
UNAVAILABLE = MappingProxyType({
    "dumka3": _TABLES.format("Medovikov 1998, 14 polynomials; the public port is GPL-3"),
})


def all_options() -> frozenset[str]:
    """Union of the options every method accepts (an unknown option is an error)."""
    out = set()
    for cls in METHODS.values():
        out |= cls.OPTIONS
    return frozenset(out)
