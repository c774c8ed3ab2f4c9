"""Method registry: name -> class, resolved from :mod:`cvtfem.methods_registry` (the one list).

``METHODS`` maps the playground's names to :class:`~cvtfem.integrate.base.Stepper` classes,
``SCIPY_METHODS`` scipy's names to ``scipy.integrate.OdeSolver`` classes (read-only live views).
:func:`register_method` adds a method at run time: ``solve``, ``cvtfem run`` (the scene's
``solver.method``) and resume then know it.
"""
from __future__ import annotations

import importlib
import warnings
from types import MappingProxyType

from scipy.integrate import OdeSolver

from cvtfem import methods_registry
from cvtfem.errors import InputError
from cvtfem.integrate.base import Stepper

__all__ = ["METHODS", "SCIPY_METHODS", "register_method", "unregister_method", "all_options", "check_options",
           "parse_options", "method_options", "IgnoredOptionWarning"]

_NATIVE: dict[str, type] = {}
_SCIPY: dict[str, type] = {}
METHODS = MappingProxyType(_NATIVE)
SCIPY_METHODS = MappingProxyType(_SCIPY)


class IgnoredOptionWarning(UserWarning):
    """An option was given that the chosen method does not use."""


def _add(name: str, cls: type) -> None:
    if isinstance(cls, type) and issubclass(cls, Stepper):
        _NATIVE[name] = cls
    elif isinstance(cls, type) and issubclass(cls, OdeSolver):
        _SCIPY[name] = cls
    else:
        raise InputError("method", cls, "must be a cvtfem.integrate Stepper or a scipy.integrate.OdeSolver class")


def register_method(cls: type, name: str | None = None) -> str:
    """Make ``cls`` (a :class:`Stepper` subclass or a scipy ``OdeSolver`` class) available as
    ``name`` (default ``cls.name``) everywhere: :func:`~cvtfem.integrate.solve`, the scene key
    ``solver.method`` and resumed runs. Returns the name."""
    name = getattr(cls, "name", None) if name is None else name
    if not isinstance(name, str) or not name:
        raise InputError("name", name, "must be a non-empty method name")
    if name in _NATIVE or name in _SCIPY:
        if (_NATIVE.get(name) or _SCIPY.get(name)) is cls:
            return name
        raise InputError("name", name, "is already a registered method")
    _add(name, cls)
    methods_registry.register_name(name, cls)
    return name


def unregister_method(name: str) -> None:
    """Remove a method added by :func:`register_method` (a plug-in unloaded, a test's method)."""
    methods_registry.unregister_name(name)
    _NATIVE.pop(name, None)
    _SCIPY.pop(name, None)


def _resolve(spec) -> type:
    if not isinstance(spec, str):
        return spec
    module, attr = spec.split(":")
    return getattr(importlib.import_module(module), attr)


for _name, _spec in methods_registry.specs().items():
    _add(_name, _resolve(_spec))


def all_options() -> frozenset[str]:
    """Union of the options every native method accepts (an unknown option is an error)."""
    out = set()
    for cls in METHODS.values():
        out |= cls.OPTIONS
    return frozenset(out)


def parse_options(pairs, where: str, example: str = "stages=2") -> dict:
    """``["stages=2", "proportional=false", "scheme=imex-rk4"]`` -> ``{"stages": 2, "proportional": False,
    "scheme": "imex-rk4"}``: numbers become int or float, ``true``/``false`` booleans; ``where`` names the argument or
    key in the error of a pair without ``=``."""
    opts = {}
    for pair in pairs:
        key, sep, val = pair.partition("=")
        key, val = key.strip(), val.strip()
        if not sep or not key:
            raise InputError(where, pair, f"options must be key=value, e.g. {example}")
        for conv in (int, float):
            try:
                opts[key] = conv(val)
                break
            except ValueError:
                continue
        else:
            opts[key] = {"true": True, "false": False}.get(val.lower(), val)
    return opts


def method_options(method: str) -> frozenset[str]:
    """The options the native method ``method`` accepts (none for scipy's methods: ``cvtfem run`` passes them none)."""
    return METHODS[method].OPTIONS if method in METHODS else frozenset()


def check_options(method: str, accepted: frozenset, options: dict) -> dict:
    """The options ``method`` uses; unknown ones raise, ignored ones warn."""
    known = all_options()
    for key in options:
        if key not in known:
            raise InputError(key, options[key], f"is not an option of any method; known: {sorted(known)}")
    use = {k: v for k, v in options.items() if k in accepted}
    for key in sorted(set(options) - set(use)):
        warnings.warn(f"option `{key}` is ignored by method {method!r} (it accepts {sorted(accepted)})",
                      IgnoredOptionWarning, stacklevel=4)
    return use
