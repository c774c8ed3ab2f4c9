"""Issue 18: every analysis command on mutated presets ends in a result or in one line with exit 2 (input)
or 3 (numerics) — never a traceback, never a hang, never a non-finite value in a results file of a run
that exits 0.  A fast profile runs in `make test`, the long one (2,000 examples) in `make test-slow`."""
from __future__ import annotations

import contextlib
import copy
import io
import signal
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cvtfem.cli import main
from cvtfem.scene.loader import preset_text, resolve_presets

pytestmark = pytest.mark.hard

#: Command, preset mutated, cheap arguments.
COMMANDS = {"run": ("band-4dof", ["--until", "0.002", "--results", "r.h5"]),
            "modes": ("friswell_5_9_1", []),
            "campbell": ("friswell_5_9_1", ["--speeds", "0:3000rpm:3"]),
            "periodic": ("engine_gear_train", ["--sweep", "12:13:2", "--harmonics", "6"])}
BASES = {name: resolve_presets(tomllib.loads(preset_text(preset))) for name, (preset, _) in COMMANDS.items()}
VALUES = st.one_of(st.sampled_from([0, -1, 10 ** 9, 1e300, 1e-300, -0.0, "x", True, [1, 2], {"a": 1}]),
                   st.floats(allow_nan=True, allow_infinity=True), st.integers(-10 ** 6, 10 ** 6))
HANG = 60  # s: an example running longer is a hang


def _paths(node):
    if isinstance(node, dict):
        for key, value in node.items():
            yield node, key
            yield from _paths(value)
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield node, i
            yield from _paths(value)


def _mutate(doc, data):
    pairs = list(_paths(doc))
    container, key = pairs[data.draw(st.integers(0, len(pairs) - 1))]
    value = container[key]
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    action = data.draw(st.sampled_from(["value", "sign", "scale", "zero", "delete"]))
    if action == "value":
        container[key] = data.draw(VALUES)
    elif action == "sign" and number:
        container[key] = -value
    elif action == "scale" and number:
        container[key] = type(value)(value * 10 ** data.draw(st.integers(-12, 12)))
    elif action == "zero" and number:
        container[key] = type(value)(0)
    elif action == "delete" and isinstance(container, dict):
        del container[key]


class _Hang(Exception):
    pass


def _alarm(*_):
    raise _Hang


def _check(data):
    command = data.draw(st.sampled_from(sorted(COMMANDS)))
    doc = copy.deepcopy(BASES[command])
    for _ in range(data.draw(st.integers(1, 2))):
        _mutate(doc, data)
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        try:
            Path("s.toml").write_text(tomli_w.dumps(doc))
        except (TypeError, ValueError, OverflowError):   # not representable in TOML: nothing to test
            return
        err = io.StringIO()
        previous = signal.signal(signal.SIGALRM, _alarm)
        signal.alarm(HANG)
        try:
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
                code = main([command, "s.toml", *COMMANDS[command][1]])
        except _Hang:
            pytest.fail(f"{command} hung (> {HANG} s) on {doc}")
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)
        lines = err.getvalue().strip().splitlines()
        assert code in (0, 2, 3), (command, code, err.getvalue()[-2000:])
        if code:
            assert len(lines) == 1 and lines[0].startswith(f"cvtfem {command}: error: "), (command, lines)
        if command == "run" and code == 0:
            from cvtfem.io.results import read_results

            series = read_results("r.h5").series
            assert all(np.isfinite(v).all() for v in series.values()), command


@settings(max_examples=24, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(data=st.data())
def test_commands_on_mutated_presets(data):
    _check(data)


@pytest.mark.slow
@settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_commands_on_mutated_presets_long(data):
    _check(data)


