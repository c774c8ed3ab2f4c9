"""Method registry: name -> stepper class (immutable mapping built at import)."""
from __future__ import annotations

from types import MappingProxyType

from cvtfem.integrate import dumka3, extrapolation, rk, rock, stabilized, theta, wmethods

__all__ = ["METHODS", "SCIPY_METHODS", "UNAVAILABLE", "all_options"]

METHODS = MappingProxyType({cls.name: cls for cls in (
    rk.Euler, rk.RK4, rk.DOPRI45, rk.DOPRI56, rk.DOPRI78,
    extrapolation.EulerExtrapolation, extrapolation.GBS, extrapolation.GBSSmooth,
    wmethods.SW24, wmethods.W1, wmethods.W1Extrapolation,
    theta.Theta, theta.Trapezoidal, theta.ImplicitEuler,
    stabilized.RKC, rock.ROCK2, rock.ROCK4, dumka3.DUMKA3)})
SCIPY_METHODS = frozenset({"RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA"})
#: Names from the issue that are not implemented, with the reason (shown in the InputError);
#: empty since DUMKA3 exists (kept for the driver's check).
UNAVAILABLE: MappingProxyType = MappingProxyType({})


def all_options() -> frozenset[str]:
    """Union of the options every method accepts (an unknown option is an error)."""
    out = set()
    for cls in METHODS.values():
        out |= cls.OPTIONS
    return frozenset(out)
