"""``cvtfem study``: writes PNG/CSV, bad input exits 2 (one real subprocess, the rest in-process)."""
import csv

import numpy as np

from cvtfem.cli import main


def test_study_order_subprocess_writes_png_and_csv(cli, tmp_path):
    out = cli("study", "order", "--methods", "rk4,gbs:stages=2", "--hs", "0.2:0.05:3",
              "--png", str(tmp_path / "o.png"), "--csv", str(tmp_path / "o.csv"))
    assert out.returncode == 0, out.stderr
    rows = list(csv.DictReader(open(tmp_path / "o.csv")))
    p = [float(r["p_eff"]) for r in rows if r["label"] == "rk4" and r["p_eff"] != "nan"]
    assert abs(p[-1] - 4) < 0.3
    assert (tmp_path / "o.png").stat().st_size > 10_000


def test_study_work_fixed_steps(tmp_path, capsys):
    code = main(["study", "work", "--problem", "oscillator", "--methods", "rk4", "--steps", "0.1,0.05",
                 "--repeats", "1", "--png", str(tmp_path / "w.png"), "--csv", str(tmp_path / "w.csv")])
    assert code == 0
    err = [float(r["error"]) for r in csv.DictReader(open(tmp_path / "w.csv"))]
    assert abs(np.log2(err[0] / err[1]) - 4) < 0.3
    assert (tmp_path / "w.png").exists()


def test_study_stability_png(tmp_path):
    assert main(["study", "stability", "--methods", "rk4,trapezoidal", "--n", "61",
                 "--png", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "s.png").stat().st_size > 5_000


def test_study_bad_input_exits_2(capsys):
    assert main(["study", "work", "--problem", "nonsense"]) == 2
    assert "`--problem`" in capsys.readouterr().err
    assert main(["study", "work", "--problem", "oscillator", "--methods", "rk4", "--rtols", "1e-6"]) == 2
    assert "`method`" in capsys.readouterr().err      # rk4 has no error estimate


def test_method_spec_booleans():
    """``proportional=false`` reaches the method as a boolean (it used to arrive as the string 'false')."""
    from cvtfem.commands.study import parse_method

    assert parse_method("radau5:proportional=false") == ("radau5:proportional=false", "radau5", {"proportional": False})
    assert parse_method("sw24:proportional=True:d=0.5")[2] == {"proportional": True, "d": 0.5}
