"""Declarative scene schema: the single source of truth for every scene key.

A schema is a tree of :class:`Table` (a TOML table), :class:`TableArray`
(a TOML array of tables, ``[[shaft]]``) and :class:`Key` (a leaf value).
Each key carries its type, SI unit, default (or :data:`REQUIRED`), allowed
range or choices and a one-line description.  :func:`validate` checks a
parsed TOML document against the tree and fills defaults; ``docs.py``
renders the same tree to Markdown.
"""
from __future__ import annotations

import difflib
import math
import unicodedata
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from cvtfem.errors import InputError


class _Required:
    def __repr__(self) -> str:
        return "required"


REQUIRED: Any = _Required()
"""Marker for a key without a default."""

#: Scalar and list types a :class:`Key` may declare.
TYPES = ("float", "int", "bool", "str", "float[]", "int[]", "str[]")
#: Magnitudes a float key may take besides 0 (SI units: no quantity of these machines comes near either end).
TINY, HUGE = 1e-30, 1e30
#: Longest string value a scene key takes (titles, descriptions, names), characters.
MAX_STRING = 1000

Check = Callable[[Mapping[str, Any], str], None]
"""Cross-field check: ``check(validated_table, path)`` raises :class:`InputError`."""


@dataclass(frozen=True)
class Key:
    """One leaf value of a scene.

    Parameters
    ----------
    name : str
        TOML key.
    type : str
        One of :data:`TYPES`.
    doc : str
        One-line description.
    unit : str
        SI unit ("-" for dimensionless, "" for non-numeric).
    default : Any
        Value used when the key is absent, or :data:`REQUIRED`.
    gt, ge, lt, le : float, optional
        Exclusive / inclusive bounds of each number (each element for lists).
    choices : tuple, optional
        Allowed values.
    length : int, optional
        Exact length of a list value.
    """

    name: str
    type: str
    doc: str
    unit: str = "-"
    default: Any = REQUIRED
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    choices: tuple[Any, ...] | None = None
    length: int | None = None

    def __post_init__(self) -> None:
        if self.type not in TYPES:
            raise TypeError(f"schema key {self.name!r}: unknown type {self.type!r}")

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def allowed(self) -> str:
        """Human-readable rule of what is allowed."""
        parts = []
        if self.choices is not None:
            parts.append("one of " + ", ".join(repr(c) for c in self.choices))
        bounds = []
        if self.gt is not None:
            bounds.append(f"> {self.gt:g}")
        if self.ge is not None:
            bounds.append(f">= {self.ge:g}")
        if self.lt is not None:
            bounds.append(f"< {self.lt:g}")
        if self.le is not None:
            bounds.append(f"<= {self.le:g}")
        if bounds:
            parts.append(" and ".join(bounds))
        if self.length is not None:
            parts.append(f"length {self.length}")
        return "; ".join(parts) if parts else "any"


@dataclass(frozen=True)
class Table:
    """A TOML table of keys and sub-tables.

    Parameters
    ----------
    name : str
        TOML name ("" for the document root).
    doc : str
        One-line description.
    items : tuple
        Keys, tables and table arrays, in documentation order.
    optional : bool
        If True an absent table stays absent (``None``); otherwise it is
        created from the defaults of its keys.
    checks : tuple of callables
        Cross-field checks run after the table's keys are validated.
    """

    name: str
    doc: str
    items: tuple[Key | Table | TableArray, ...]
    optional: bool = False
    checks: tuple[Check, ...] = field(default=(), compare=False)

    def child(self, name: str) -> Key | Table | TableArray | None:
        for item in self.items:
            if item.name == name:
                return item
        return None


@dataclass(frozen=True)
class TableArray:
    """A TOML array of tables (``[[shaft]]``); each entry follows ``item``."""

    name: str
    doc: str
    item: Table
    min_items: int = 0
    checks: tuple[Check, ...] = field(default=(), compare=False)


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _type_name(value: Any) -> str:
    return {bool: "bool", int: "int", float: "float", str: "str", list: "array",
            dict: "table"}.get(type(value), type(value).__name__)


def _check_scalar(key: Key, scalar_type: str, value: Any, where: str) -> Any:
    if scalar_type == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(where, value, f"must be a number ({key.unit or '-'}), not {_type_name(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise InputError(where, value, "must be finite")
        if value != 0.0 and not TINY <= abs(value) <= HUGE:
            raise InputError(where, value, f"must be 0 or of magnitude {TINY:g} .. {HUGE:g} ({key.unit or '-'}): "
                             "beyond that the model's arithmetic overflows or underflows")
    elif scalar_type == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(where, value, f"must be an integer, not {_type_name(value)}")
    elif scalar_type == "bool":
        if not isinstance(value, bool):
            raise InputError(where, value, f"must be true or false, not {_type_name(value)}")
    elif scalar_type == "str":
        if not isinstance(value, str):
            raise InputError(where, value, f"must be a string, not {_type_name(value)}")
        if len(value) > MAX_STRING:
            raise InputError(where, value, f"must be at most {MAX_STRING} characters long ({len(value)} given)")
        if any(unicodedata.category(c) == "Cc" for c in value):
            raise InputError(where, value, "must hold no control characters (terminal escapes, tabs, newlines)")
    if key.choices is not None and value not in key.choices:
        hint = _suggest(str(value), [str(c) for c in key.choices])
        raise InputError(where, value, f"must be {key.allowed()}", hint)
    if scalar_type in ("float", "int"):
        unit = f" {key.unit}" if key.unit not in ("", "-") else ""
        for bound, ok, text in ((key.gt, lambda v, b: v > b, ">"), (key.ge, lambda v, b: v >= b, ">="),
                                (key.lt, lambda v, b: v < b, "<"), (key.le, lambda v, b: v <= b, "<=")):
            if bound is not None and not ok(value, bound):
                raise InputError(where, value, f"must be {text} {bound:g}{unit}")
    return value


def validate_key(key: Key, value: Any, where: str) -> Any:
    """Check one value against its key; returns the normalised value."""
    if key.type.endswith("[]"):
        if not isinstance(value, list):
            raise InputError(where, value, f"must be an array of {key.type[:-2]}, not {_type_name(value)}")
        if key.length is not None and len(value) != key.length:
            raise InputError(where, value, f"must have length {key.length}")
        return tuple(_check_scalar(key, key.type[:-2], v, f"{where}[{i}]") for i, v in enumerate(value))
    return _check_scalar(key, key.type, value, where)


def _suggest(name: str, candidates: list[str]) -> str:
    close = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    return f"did you mean `{close[0]}`?" if close else ""


def validate(schema: Table, data: Mapping[str, Any], path: str = "") -> dict[str, Any]:
    """Validate a parsed TOML table against ``schema`` and fill defaults.

    Parameters
    ----------
    schema : Table
        The schema of this table.
    data : mapping
        Parsed TOML (``tomllib.loads`` output or a sub-table of it).
    path : str
        Key path of this table, used in messages.

    Returns
    -------
    dict
        Validated values: every key of the schema is present (defaults filled,
        lists as tuples); absent optional tables are ``None``.

    Raises
    ------
    InputError
        Naming the key path, the value and what is allowed.
    """
    if not isinstance(data, Mapping):
        raise InputError(path or "scene", data, f"must be a table, not {_type_name(data)}")
    known = [item.name for item in schema.items]
    for name in data:
        if name not in known:
            where = _join(path, name)
            hint = _suggest(name, known) or f"allowed keys here: {', '.join(known)}"
            raise InputError(where, data[name], "is not a known key", hint)
    out: dict[str, Any] = {}
    for item in schema.items:
        where = _join(path, item.name)
        present = item.name in data
        if isinstance(item, Key):
            if present:
                out[item.name] = validate_key(item, data[item.name], where)
            elif item.required:
                raise InputError(where, None, f"is required ({item.doc})")
            else:
                out[item.name] = item.default
        elif isinstance(item, Table):
            if present:
                out[item.name] = validate(item, data[item.name], where)
            else:
                out[item.name] = None if item.optional else validate(item, {}, where)
        else:
            entries = data.get(item.name, [])
            if not isinstance(entries, list) or not all(isinstance(e, Mapping) for e in entries):
                raise InputError(where, entries, f"must be an array of tables (write [[{where}]])")
            if len(entries) < item.min_items:
                raise InputError(where, len(entries), f"needs at least {item.min_items} entries")
            validated = tuple(validate(item.item, e, f"{where}[{i}]") for i, e in enumerate(entries))
            for check in item.checks:
                check(validated, where)  # type: ignore[arg-type]
            out[item.name] = validated
    for check in schema.checks:
        check(out, path)
    return out
