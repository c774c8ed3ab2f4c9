"""The progress bar shows on a terminal and stays quiet in CI logs."""
from __future__ import annotations

import io
import sys

from cvtfem.io import progress as progress_module


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_quiet_off_terminal_and_in_ci(monkeypatch):
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    monkeypatch.delenv("CI", raising=False)
    assert not progress_module.progress_enabled()
    monkeypatch.setattr(sys, "stderr", _Tty())
    assert progress_module.progress_enabled()
    monkeypatch.setenv("CI", "true")
    assert not progress_module.progress_enabled()


def test_bar_writes_on_terminal(monkeypatch):
    tty = _Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    monkeypatch.delenv("CI", raising=False)
    bar = progress_module.progress(2.0, desc="run")
    bar.update(1.0)
    bar.refresh()
    assert " 50%|" in tty.getvalue() and "1/2 s" in tty.getvalue()
    bar.close()
