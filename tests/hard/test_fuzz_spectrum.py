"""`cvtfem spectrum` with every excitation source on mutated CVT sheave shaft presets: a result or one line with
exit 2 (input) or 3 (numerics), never a traceback or a hang (the checks of test_fuzz_commands.py)."""
from __future__ import annotations

import contextlib
import copy
import json
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cvtfem.scene.loader import preset_text, resolve_presets
from tests.hard.test_fuzz_commands import _main, _mutate

pytestmark = pytest.mark.hard

BASE = resolve_presets(tomllib.loads(preset_text("cvt_sheave_shaft")))
ARGS = ["--speeds", "0:3000rpm:3", "--node", "4", "--orders", "14", "--chain", "0.06:84:0.008:0.01:0.5",
        "--link-harmonics", "1", "--ripple", "4:2:5", "--n-freqs", "10", "--n-modes", "6", "--json", "s.json"]


def _check(data):
    doc = copy.deepcopy(BASE)
    for _ in range(data.draw(st.integers(1, 2))):
        _mutate(doc, data)
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        try:
            Path("s.toml").write_text(tomli_w.dumps(doc))
        except (TypeError, ValueError, OverflowError):   # not representable in TOML: nothing to test
            return
        code, _ = _main(["spectrum", "s.toml", *ARGS], doc)
        if code == 0:
            d = json.loads(Path("s.json").read_text())
            assert np.isfinite(np.array(d["line_erp_w"], dtype=float)).all()


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(data=st.data())
def test_spectrum_on_mutated_presets(data):
    _check(data)


@pytest.mark.slow
@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_spectrum_on_mutated_presets_long(data):
    _check(data)
