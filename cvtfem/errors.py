"""Exceptions shared by every layer.

A :class:`CvtfemError` is an *expected* failure with a message meant for a user:
``cli.py`` prints it without a traceback and exits with :attr:`exit_code`.
"""
from __future__ import annotations

from typing import Any


#: Longest representation of an offending value that an :class:`InputError` message quotes, characters.
MAX_SHOWN = 200


class CvtfemError(Exception):
    """Base of all expected, user-facing failures."""

    exit_code = 1


class InputError(CvtfemError, ValueError):
    """Bad input: a scene key, a CLI argument or a function argument.

    Parameters
    ----------
    where : str
        Key path (``cvt.chain.n_pins``) or argument name (``--speeds``).
    value : Any
        The offending value as given.
    rule : str
        What is allowed, phrased as a rule ("must be positive").
    hint : str, optional
        A fix, e.g. a "did you mean" suggestion.
    """

    exit_code = 2

    def __init__(self, where: str, value: Any, rule: str, hint: str = "") -> None:
        self.where, self.value, self.rule, self.hint = where, value, rule, hint
        shown = repr(value)
        if len(shown) > MAX_SHOWN:
            shown = f"{shown[:MAX_SHOWN - 20]}... ({len(shown)} characters)"
        text = f"`{where}` {rule}, got {shown}"
        if hint:
            text += f" ({hint})"
        super().__init__(" ".join(text.splitlines()))  # one line, whatever the value holds


class NumericalError(CvtfemError, RuntimeError):
    """A numerical failure (divergence, NaN, step underflow) with where and why.

    Parameters
    ----------
    message : str
        What failed and why.
    t : float, optional
        Simulated time of the failure, s.
    component : str, optional
        The element, state or solver part that failed.
    """

    exit_code = 3

    def __init__(self, message: str, t: float | None = None, component: str = "") -> None:
        self.t, self.component = t, component
        parts = [message]
        if t is not None:
            parts.append(f"at t = {t:.6g} s")
        if component:
            parts.append(f"in {component}")
        super().__init__(", ".join(parts))
