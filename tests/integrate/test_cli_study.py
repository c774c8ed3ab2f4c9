"""``cvtfem study``: runs in a subprocess, writes PNG/CSV, bad input exits 2."""
import csv

import numpy as np


def test_study_order_writes_png_and_csv(cli, tmp_path):
    out = cli("study", "order", "--methods", "rk4,gbs:stages=2", "--hs", "0.2:0.05:3",
              "--png", str(tmp_path / "o.png"), "--csv", str(tmp_path / "o.csv"))
    assert out.returncode == 0, out.stderr
    rows = list(csv.DictReader(open(tmp_path / "o.csv")))
    p = [float(r["p_eff"]) for r in rows if r["label"] == "rk4" and r["p_eff"] != "nan"]
    assert abs(p[-1] - 4) < 0.3
    assert (tmp_path / "o.png").stat().st_size > 10_000


def test_study_work_fixed_steps(cli, tmp_path):
    out = cli("study", "work", "--problem", "oscillator", "--methods", "rk4", "--steps", "0.1,0.05",
              "--repeats", "1", "--png", str(tmp_path / "w.png"), "--csv", str(tmp_path / "w.csv"))
    assert out.returncode == 0, out.stderr
    err = [float(r["error"]) for r in csv.DictReader(open(tmp_path / "w.csv"))]
    assert abs(np.log2(err[0] / err[1]) - 4) < 0.3


def test_study_stability_png(cli, tmp_path):
    out = cli("study", "stability", "--methods", "rk4,trapezoidal", "--n", "61", "--png", str(tmp_path / "s.png"))
    assert out.returncode == 0 and (tmp_path / "s.png").exists()


def test_study_bad_input_exits_2(cli):
    out = cli("study", "work", "--problem", "nonsense")
    assert out.returncode == 2 and "`--problem`" in out.stderr
    out = cli("study", "work", "--problem", "oscillator", "--methods", "rk4", "--rtols", "1e-6")
    assert out.returncode == 2 and "`method`" in out.stderr      # rk4 has no error estimate
