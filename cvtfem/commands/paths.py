"""Output paths of every command, checked before any work starts (a failure after an hour of work loses it)."""
from __future__ import annotations

import argparse
import os
from pathlib import Path

from cvtfem.errors import InputError

#: Argument destinations that name an output file, in every command that has them.
OUTPUT_FILES = ("results", "summary_json", "json", "csv", "png", "spectrum_png")
#: Longest file name most file systems take, bytes.
NAME_MAX = 255


def check_output_args(args: argparse.Namespace) -> None:
    """InputError for an output argument of ``args`` that cannot be written (see :func:`check_output_file`)."""
    for dest in OUTPUT_FILES:
        value = getattr(args, dest, None)
        if value is not None and not (dest == "results" and str(value).lower() == "none"):
            check_output_file(f"--{dest.replace('_', '-')}", value)
        if dest.endswith("png") and value is not None and Path(value).suffix.lower() != ".png":
            raise InputError(f"--{dest.replace('_', '-')}", value,
                             "must name a .png file (the figure's format follows the suffix)")
    out = getattr(args, "out", None)
    if out is not None and out != "-":
        (check_output_dir if args.command == "demo" else check_output_file)("--out", out)


def check_output_file(where: str, value: str) -> Path:
    """``value`` as a writable file path: not a folder, its folder creatable and writable, its name not too long."""
    path = Path(value)
    if len(os.fsencode(path.name)) > NAME_MAX:
        raise InputError(where, value, f"must have a file name of at most {NAME_MAX} bytes")
    if path.is_dir() or os.path.basename(value) in ("", ".", ".."):   # "d/" names a folder, existing or not
        raise InputError(where, value, "must be a file path, not a folder")
    _check_creatable(where, value, path.parent)
    if path.exists() and not os.access(path, os.W_OK):
        raise InputError(where, value, "must be a writable file (it exists and is read-only)")
    return path


def check_output_dir(where: str, value: str) -> Path:
    """``value`` as a folder that exists or can be created, and is writable."""
    path = Path(value)
    if path.exists() and not path.is_dir():
        raise InputError(where, value, "must be a folder, not a file")
    _check_creatable(where, value, path)
    return path


def _check_creatable(where: str, value: str, folder: Path) -> None:
    """The nearest existing ancestor of ``folder`` is a writable folder (so ``folder`` can be made)."""
    folder = folder if str(folder) else Path(".")
    ancestor = folder
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise InputError(where, value, f"must lie in a folder, but {str(ancestor)!r} is a file")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise InputError(where, value, f"must lie in a writable folder ({str(ancestor)!r} is not writable)")
