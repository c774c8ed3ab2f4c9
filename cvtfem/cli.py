"""Command line: ``cvtfem COMMAND ...``.

Thin by design: each command lives in ``cvtfem/commands/NAME.py`` with
``add_parser(subparsers)`` (cheap: no heavy imports) and ``run(args) -> int``.
Expected failures (:class:`cvtfem.errors.CvtfemError`) are printed as one
line without a traceback; bad input exits with status 2.
"""
from __future__ import annotations

import argparse
import logging
import sys
from importlib import import_module

from cvtfem import __version__
from cvtfem.commands.paths import check_output_args
from cvtfem.errors import CvtfemError

#: Command modules in ``cvtfem.commands``, in the order ``--help`` lists them.
COMMANDS = ("scenes", "describe", "docs", "show", "run", "modes", "campbell", "response", "spectrum", "render", "sheave",
            "periodic", "sweep", "report", "study", "bench", "demo", "spectrogram", "history", "revolution",
            "rotormaps", "runcampbell", "jacobian")


class _Parser(argparse.ArgumentParser):
    """argparse parser whose errors name the program and exit with status 2."""

    def error(self, message: str) -> None:  # noqa: D401 - argparse API
        # one line whatever the arguments hold: control characters and line separators escaped, as InputError quotes
        shown = "".join(c if c.isprintable() else repr(c)[1:-1] for c in message)
        self.exit(2, f"{self.prog}: error: {shown}\n")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser (one sub-parser per available command)."""
    parser = _Parser(prog="cvtfem", description="Structural dynamics of chain CVTs and drivetrains.")
    parser.add_argument("--version", action="version", version=f"cvtfem {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress messages")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        try:
            module = import_module(f"cvtfem.commands.{name}")
        except ModuleNotFoundError as err:  # a command whose issue has not landed yet
            if err.name != f"cvtfem.commands.{name}":
                raise
            continue
        module.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``cvtfem`` console script; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        check_output_args(args)
        return int(args.func(args) or 0)
    except CvtfemError as err:
        print(f"cvtfem {args.command}: error: {err}", file=sys.stderr)
        return err.exit_code
    except KeyboardInterrupt:
        print(f"cvtfem {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
