"""Progress bar for long analyses: shown on a terminal, silent in CI logs."""
from __future__ import annotations

import os
import sys
from typing import Any

from tqdm import tqdm


def progress_enabled() -> bool:
    """True when stderr is a terminal and not in CI (``CI`` environment variable unset)."""
    return sys.stderr.isatty() and not os.environ.get("CI")


def progress(total: float, unit: str = "s", desc: str = "") -> Any:
    """A tqdm bar over ``total`` (simulated seconds or steps); disabled off-terminal.

    Call ``bar.update(delta)`` as the analysis advances and ``bar.close()`` at the end.
    """
    return tqdm(total=total, unit=unit, desc=desc, disable=not progress_enabled(), leave=False, file=sys.stderr,
                bar_format="{desc} {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} {unit} [{elapsed}<{remaining}]")
