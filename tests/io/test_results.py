"""Results files: round trip, incremental flushing, a run killed half-way stays readable."""
from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.io.results import ResultsWriter, read_results
from cvtfem.outputs import OutputSpec

SPECS = (OutputSpec("x", "m", "position"), OutputSpec("f", "N", "three forces", 3))

WRITER_SCRIPT = """
import sys, time
from cvtfem.io.results import ResultsWriter
from cvtfem.outputs import OutputSpec
w = ResultsWriter(sys.argv[1], "title = 'killed'\\n", "run",
                  [OutputSpec("x", "m", "position"), OutputSpec("f", "N", "forces", 3)], flush_interval=0.02)
i = 0
while True:
    w.append(1e-3 * i, {"x": i, "f": [i, -i, 2 * i]})
    if i == 50:
        print("flushed", flush=True)
    i += 1
    time.sleep(2e-4)
"""


def test_round_trip(tmp_path):
    path = tmp_path / "r.h5"
    with ResultsWriter(path, "title = 'x'\n", "run", SPECS) as w:
        for i in range(1000):
            w.append(0.01 * i, {"x": np.sin(0.01 * i), "f": [i, 2 * i, 3 * i]})
        w.set_stats({"nfev": 123, "method": "rk4"})
        w.add_array("modes", np.eye(3), unit="-", doc="identity")
    res = read_results(path)
    assert res.attrs["status"] == "finished"
    assert res.time.shape == (1000,) and res.series["f"].shape == (1000, 3)
    np.testing.assert_array_equal(res.series["x"][:, 0], np.sin(0.01 * np.arange(1000)))
    assert res.units["f"] == "N" and res.stats["nfev"] == 123 and res.scene_toml == "title = 'x'\n"


def test_failed_run_records_reason(tmp_path):
    path = tmp_path / "r.h5"
    with pytest.raises(ZeroDivisionError):
        with ResultsWriter(path, "", "run", SPECS) as w:
            w.append(0.0, {"x": 1.0, "f": [1, 2, 3]})
            raise ZeroDivisionError("boom")
    res = read_results(path)
    assert res.attrs["status"] == "failed" and "boom" in res.attrs["message"]
    assert res.time.size == 1  # what was written before the failure is kept


def test_never_overwrites(tmp_path):
    path = tmp_path / "r.h5"
    ResultsWriter(path, "", "run", SPECS).close()
    with pytest.raises(InputError, match="must not exist already"):
        ResultsWriter(path, "", "run", SPECS)


def test_killed_writer_leaves_readable_file(tmp_path, cli):
    path = tmp_path / "killed.h5"
    proc = subprocess.Popen([sys.executable, "-c", WRITER_SCRIPT, str(path)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "flushed"
    time.sleep(0.5)  # let it write and flush many more rows
    proc.kill()
    proc.wait(timeout=10)
    res = read_results(path)
    assert res.attrs["status"] == "running"  # never closed
    n = res.time.size
    assert n > 50
    i = np.arange(n)
    np.testing.assert_allclose(res.time, 1e-3 * i)  # every complete row is consistent
    np.testing.assert_array_equal(res.series["f"], np.column_stack([i, -i, 2 * i]))
    shown = cli("show", str(path))
    assert shown.returncode == 0 and "killed" in shown.stdout and f"rows: {n}" in shown.stdout


def test_show_rejects_non_hdf5(tmp_path, cli):
    bad = tmp_path / "x.h5"
    bad.write_text("not hdf5")
    res = cli("show", str(bad))
    assert res.returncode == 2 and "readable HDF5" in res.stderr and "Traceback" not in res.stderr
