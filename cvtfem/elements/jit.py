"""numba's ``njit`` for the compiled kernels of the element families, or an identity decorator without numba
(``HAVE_NUMBA`` false: the families then use their numpy twins, or the kernels run as plain Python)."""
from __future__ import annotations

try:
    from numba import njit
    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - exercised only without numba
    HAVE_NUMBA = False

    def njit(*args, **kwargs):  # noqa: D103 - identity decorator
        return (lambda f: f) if not args or not callable(args[0]) else args[0]

__all__ = ["njit", "HAVE_NUMBA"]
