"""Read-only nested view of validated scene data."""
from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any


def freeze(value: Any) -> Any:
    """Turn dicts into :class:`Node` and lists into tuples, recursively."""
    if isinstance(value, Mapping):
        return Node(value)
    if isinstance(value, (list, tuple)):
        return tuple(freeze(v) for v in value)
    return value


def thaw(value: Any) -> Any:
    """Inverse of :func:`freeze`: plain dicts and lists (for TOML/JSON writers)."""
    if isinstance(value, Mapping):
        return {k: thaw(v) for k, v in value.items()}
    if isinstance(value, tuple):
        return [thaw(v) for v in value]
    return value


class Node(Mapping[str, Any]):
    """Immutable mapping with attribute access: ``scene.cvt.chain.n_pins``."""

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, Any]) -> None:
        object.__setattr__(self, "_data", {k: freeze(v) for k, v in data.items()})

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __getattr__(self, key: str) -> Any:
        try:
            return self._data[key]
        except KeyError:
            raise AttributeError(key) from None

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError("scene data is immutable; build a new scene with overrides")

    def __hash__(self) -> int:
        return hash(tuple(sorted((k, v) for k, v in self._data.items() if not isinstance(v, Node))))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Mapping) and dict(self.items()) == dict(other.items())

    def __repr__(self) -> str:
        return f"Node({self._data!r})"

    def get_path(self, path: str) -> Any:
        """Value at a dotted key path, e.g. ``"cvt.chain.n_pins"``."""
        node: Any = self
        for part in path.split("."):
            node = node[part]
        return node
