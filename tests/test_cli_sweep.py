"""``cvtfem sweep`` and ``cvtfem report`` through real subprocesses: errors, resume after a kill, reports."""
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from cvtfem.cli import main

SWEEP = ["sweep", "band-4dof", "--until", "0.1", "--workers", "1"]


@pytest.mark.parametrize("args, where", [
    (["--vary", "cvt.regime.torque=1:2"], "`--vary`"),
    (["--vary", "cvt.regime.torque"], "`--vary`"),
    (["--vary", "cvt.regime.torqe=100,200"], "`cvt.regime.torqe` is not a known key"),
    (["--vary", "cvt.regime.torque=100,200", "--scheduler", "tcp://127.0.0.1:9"], "needs --engine dask"),
    (["--vary", "cvt.regime.torque=100,200", "--workers", "0"], "`--workers`"),
    (["--vary", "rotor.speed=0,100", "--analysis", "modes"], "`--until` applies to --analysis run only"),
    ([], "a sweep needs variants"),
])
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, args, where):
    assert main([*SWEEP, *args, "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("cvtfem sweep: error:") and where in err
    assert not (tmp_path / "s" / "index.json").exists()


def test_unreachable_scheduler_is_one_line_exit_2(cli, tmp_path):
    r = cli(*SWEEP, "--vary", "cvt.regime.torque=100,200", "--engine", "dask", "--scheduler", "tcp://127.0.0.1:9",
            "--connect-timeout", "0.5", "--out", str(tmp_path / "s"))
    assert r.returncode == 2 and r.stderr.count("\n") == 1
    assert r.stderr.startswith("cvtfem sweep: error: `--scheduler` must be the address of a running dask scheduler")
    assert not (tmp_path / "s" / "index.json").exists()


def test_sweep_then_report(capsys, tmp_path):
    out = tmp_path / "s"
    args = [*SWEEP, "--vary", "cvt.regime.torque=100:200:2", "--vary", "cvt.regime.ratio=1,2", "--out", str(out)]
    assert main(args) == 0
    assert "sweep of 4 variants (run, local): 4 finished" in capsys.readouterr().out
    index = json.loads((out / "index.json").read_text())
    assert main(args) == 0   # again: nothing reruns
    assert json.loads((out / "index.json").read_text()) == index
    for fmt in ("md", "html"):
        assert main(["report", str(out), "--out", str(tmp_path / f"rep.{fmt}")]) == 0
        text = (tmp_path / f"rep.{fmt}").read_text()
        for e in index["variants"]:
            assert e["id"] in text and f"{e['summary']['efficiency']:.6g}" in text
        assert (tmp_path / "rep_efficiency.png").stat().st_size > 10_000 and "rep_F1_F2.png" in text
    assert main(["report", str(tmp_path), "--out", str(tmp_path / "x.md")]) == 2
    assert "SWEEP_DIR" in capsys.readouterr().err


def test_killed_sweep_resumes_without_rerunning(tmp_path):
    """Kill the sweep process group (parent and pool) after its first finished variant; the same command then
    runs only the rest: the finished variant keeps its results file (mtime) and its index entry."""
    out = tmp_path / "s"
    cmd = [sys.executable, "-m", "cvtfem.cli", *SWEEP[:2], "--until", "0.6", "--workers", "1",
           "--vary", "cvt.regime.torque=100:250:4", "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    finished = []
    try:
        deadline = time.monotonic() + 120
        while not finished and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
            try:
                finished = [e for e in json.loads((out / "index.json").read_text())["variants"]
                            if e["status"] == "finished"]
            except (OSError, json.JSONDecodeError):
                continue
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    index = json.loads((out / "index.json").read_text())
    done = {e["id"]: e for e in index["variants"] if e["status"] == "finished"}
    assert 1 <= len(done) < 4, "the kill came too late to interrupt the sweep"
    mtimes = {vid: (out / e["results"]).stat().st_mtime_ns for vid, e in done.items()}
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    index = json.loads((out / "index.json").read_text())
    assert [e["status"] for e in index["variants"]] == ["finished"] * 4
    for vid, e in done.items():
        again = next(x for x in index["variants"] if x["id"] == vid)
        assert again == e and (out / e["results"]).stat().st_mtime_ns == mtimes[vid]


@pytest.mark.slow
def test_sweep_on_a_dask_local_cluster(cli, tmp_path):
    args = ["--vary", "cvt.regime.torque=100:200:2", "--vary", "cvt.regime.ratio=1,2"]
    r = cli(*SWEEP, *args, "--out", str(tmp_path / "local"))
    d = cli(*SWEEP[:-1], "2", *args, "--engine", "dask", "--out", str(tmp_path / "dask"))
    assert r.returncode == 0 and d.returncode == 0, d.stderr
    assert "4 finished" in d.stdout and d.stderr == ""
    local, dask = (json.loads((tmp_path / k / "index.json").read_text())["variants"] for k in ("local", "dask"))
    assert [e["summary"] for e in local] == [e["summary"] for e in dask]
