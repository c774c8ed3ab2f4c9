"""Digests of cvtfem's own sources: what a cached result (a compiled kernel, a study's kept run) was made with."""
from __future__ import annotations

import functools
import hashlib
from pathlib import Path


@functools.lru_cache(maxsize=None)
def sources_digest(root: str, dirs: tuple[str, ...]) -> bytes:
    """SHA-256 over the relative paths and contents of every ``.py`` file under ``root/dir`` for ``dirs``."""
    h = hashlib.sha256()
    base = Path(root)
    for d in dirs:
        for path in sorted((base / d).rglob("*.py")):
            h.update(str(path.relative_to(base)).encode())
            h.update(path.read_bytes())
    return h.digest()
