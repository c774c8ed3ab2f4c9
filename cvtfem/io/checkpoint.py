"""Checkpoints inside a results file: the full state a killed run needs to continue.

Layout (created with the results file, before it switches to SWMR mode, since datasets cannot be
created afterwards)::

    /checkpoint/slots   (2, 2 + size) float64, rows [seq, payload..., crc32 of seq + payload]
                        attrs names, sizes: the payload fields in order

A checkpoint is written into slot ``seq % 2`` in one write and flushed; the other slot keeps
the previous one.  A run killed in the middle of a write leaves a slot whose CRC does not
match; :func:`read_latest` returns the valid slot with the highest ``seq``.  The payload is
opaque here (named float vectors); the run driver decides what goes in (state, step size,
counters, output position).
"""
from __future__ import annotations

import zlib
from collections.abc import Mapping
from dataclasses import dataclass

import h5py
import numpy as np

__all__ = ["Layout", "create", "write", "read_latest", "GROUP"]

GROUP = "checkpoint"
SLOTS = 2


@dataclass(frozen=True)
class Layout:
    """Named float fields of a checkpoint payload, ``((name, size), ...)``."""

    fields: tuple[tuple[str, int], ...]

    @property
    def size(self) -> int:
        return sum(n for _, n in self.fields)

    def pack(self, values: Mapping[str, object]) -> np.ndarray:
        parts = []
        for name, n in self.fields:
            v = np.asarray(values[name], dtype=float).ravel()
            if v.size != n:
                raise ValueError(f"checkpoint field {name!r} has {v.size} values, the layout says {n}")
            parts.append(v)
        return np.concatenate(parts) if parts else np.zeros(0)

    def unpack(self, vec: np.ndarray) -> dict[str, np.ndarray]:
        out, i = {}, 0
        for name, n in self.fields:
            out[name] = np.array(vec[i:i + n])
            i += n
        return out

    @classmethod
    def from_attrs(cls, attrs: Mapping[str, object]) -> Layout:
        names = [n.decode() if isinstance(n, bytes) else str(n) for n in attrs["names"]]
        return cls(tuple(zip(names, (int(s) for s in attrs["sizes"]))))


def _crc(head: np.ndarray) -> float:
    return float(zlib.crc32(np.ascontiguousarray(head, dtype="<f8").tobytes()))


def create(f: h5py.File, layout: Layout) -> None:
    """Pre-create the checkpoint slots (call before ``swmr_mode = True``); both start invalid."""
    g = f.create_group(GROUP)
    d = g.create_dataset("slots", data=np.full((SLOTS, layout.size + 2), np.nan))
    d.attrs.update(names=[n for n, _ in layout.fields], sizes=[s for _, s in layout.fields],
                   doc="Full run state for `cvtfem run --resume`: rows [seq, payload..., crc32].")


def write(f: h5py.File, layout: Layout, seq: int, values: Mapping[str, object]) -> None:
    """Store checkpoint number ``seq`` (>= 1) in slot ``seq % 2`` and flush it to disk."""
    head = np.concatenate([[float(seq)], layout.pack(values)])
    d = f[GROUP]["slots"]
    d[seq % SLOTS] = np.concatenate([head, [_crc(head)]])
    d.flush()
    f.flush()


def read_latest(f: h5py.File) -> tuple[int, dict[str, np.ndarray]] | None:
    """``(seq, fields)`` of the newest intact checkpoint of an open file, None without one."""
    if GROUP not in f or "slots" not in f[GROUP]:
        return None
    d = f[GROUP]["slots"]
    if f.swmr_mode:
        d.refresh()
    layout = Layout.from_attrs(d.attrs)
    best: tuple[int, dict[str, np.ndarray]] | None = None
    for row in np.asarray(d[()]):
        head, crc = row[:-1], row[-1]
        if not (np.isfinite(head[0]) and head[0] >= 1) or _crc(head) != crc:
            continue
        seq = int(head[0])
        if best is None or seq > best[0]:
            best = (seq, layout.unpack(head[1:]))
    return best

