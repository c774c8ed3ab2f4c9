"""Checkpoint slots in results files: round trip, torn writes, resume of the rows."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.io import checkpoint as ckpt
from cvtfem.io.results import ResultsWriter, read_results
from cvtfem.outputs import OutputSpec

LAYOUT = ckpt.Layout((("t", 1), ("x", 3)))
SPECS = (OutputSpec("x", "m", "position"),)


def _write(path, n_rows: int, checkpoints: dict[int, int], status: str = "failed"):
    """Rows 0..n_rows-1; checkpoint ``seq`` after row ``checkpoints[seq]``; closed with ``status``."""
    w = ResultsWriter(path, "title = 'c'\n", "run", SPECS, flush_interval=1e9, checkpoint=LAYOUT)
    for i in range(n_rows):
        w.append(0.1 * i, {"x": float(i)})
        for seq, after in checkpoints.items():
            if after == i:
                w.checkpoint(seq, {"t": 0.1 * i, "x": [i, 2 * i, 3 * i]})
    w.close(status)


def test_layout_round_trip():
    vec = LAYOUT.pack({"t": 2.0, "x": [1, 2, 3]})
    assert vec.tolist() == [2.0, 1, 2, 3]
    assert LAYOUT.unpack(vec)["x"].tolist() == [1, 2, 3]
    with pytest.raises(ValueError, match="'x' has 2 values"):
        LAYOUT.pack({"t": 0.0, "x": [1, 2]})


def test_newest_intact_slot_wins(tmp_path):
    path = tmp_path / "c.h5"
    _write(path, 10, {1: 3, 2: 6, 3: 8})
    with h5py.File(path, "r") as f:
        seq, values = ckpt.read_latest(f)
    assert seq == 3 and values["x"].tolist() == [8, 16, 24] and values["rows"][0] == 9
    with h5py.File(path, "r+") as f:  # a write of checkpoint 3 torn by a kill: its CRC fails
        f["checkpoint/slots"][3 % 2, 3] = 12345.0
    with h5py.File(path, "r") as f:
        seq, values = ckpt.read_latest(f)
    assert seq == 2 and values["t"][0] == pytest.approx(0.6) and values["rows"][0] == 7


def test_no_checkpoint_written(tmp_path):
    path = tmp_path / "c.h5"
    _write(path, 4, {})
    with h5py.File(path, "r") as f:
        assert ckpt.read_latest(f) is None
    with pytest.raises(InputError, match="must hold a checkpoint"):
        ResultsWriter.resume(path)


def test_resume_keeps_rows_up_to_checkpoint(tmp_path):
    path = tmp_path / "c.h5"
    _write(path, 10, {1: 3, 2: 6})
    w, seq, values = ResultsWriter.resume(path)
    assert seq == 2 and w.rows == 7 and w.path == path and not (tmp_path / "c.h5.resume-tmp").exists()
    for i in range(7, 12):  # the run continues from the checkpoint
        w.append(0.1 * i, {"x": float(i)})
    w.checkpoint(3, {"t": 1.1, "x": [0, 0, 0]})
    w.close()
    res = read_results(path)
    assert res.attrs["status"] == "finished" and res.attrs["resumed"] == 1
    np.testing.assert_array_equal(res.series["x"][:, 0], np.arange(12))
    with h5py.File(path, "r") as f:
        assert ckpt.read_latest(f)[0] == 3
    with pytest.raises(InputError, match="unfinished run"):
        ResultsWriter.resume(path)


def test_resume_refuses_other_kinds(tmp_path):
    path = tmp_path / "m.h5"
    ResultsWriter(path, "", "modes", SPECS).close("failed")
    with pytest.raises(InputError, match="results file of `cvtfem run`"):
        ResultsWriter.resume(path)
