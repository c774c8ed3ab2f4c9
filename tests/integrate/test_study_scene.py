"""Scene-backed study problem (``cvtfem.analysis.study_problem``, ``cvtfem study work --scene``)."""
import csv
import dataclasses

import numpy as np

from cvtfem.analysis.study_problem import scene_problem
from cvtfem.cli import main
from cvtfem.integrate import solve


def test_scene_problem_structure_and_error_metric():
    """band-4dof closed loop: n2 = 4, outputs at the reference state equal the preset's targets
    (ratio 2.4, 3500 rpm) within 1 % (still settling at 10 ms); a tighter Radau run is closer to the reference."""
    p = scene_problem("band-4dof", 0.01, ref_rtol=1e-9)
    assert p.n2 == 4 and p.jac is not None
    ratio, w1, _, work = p.y_ref
    assert abs(ratio / 2.4 - 1) < 1e-2 and abs(w1 / (3500 * np.pi / 30) - 1) < 1e-2
    assert 0.9 < work < 1.0                    # output/input work: efficiency below 1
    errs = [p.error(solve(**p.solve_kwargs(), method="Radau", rtol=r, atol=1e-2 * r)) for r in (1e-4, 1e-7)]
    assert errs[1] < errs[0] / 10
    res = solve(**p.solve_kwargs(), method="Radau", rtol=1e-4, atol=1e-6)
    assert p.error(dataclasses.replace(res, status=-1)) == np.inf        # failed runs: no error
    assert p.error(dataclasses.replace(res, t=res.t[:-1], y=res.y[:, :-1])) == np.inf   # t_end missed


def test_study_work_on_a_scene(tmp_path, capsys):
    code = main(["study", "work", "--scene", "band-4dof", "--until", "0.01", "--methods", "trapezoidal,Radau",
                 "--rtols", "1e-3,1e-5", "--repeats", "1", "--png", str(tmp_path / "w.png"),
                 "--csv", str(tmp_path / "w.csv")])
    assert code == 0
    rows = list(csv.DictReader(open(tmp_path / "w.csv")))
    err = {(r["method"], float(r["rtol"])): float(r["error"]) for r in rows}
    for m in ("trapezoidal", "Radau"):
        assert err[(m, 1e-5)] < err[(m, 1e-3)] < 1e-3
    assert (tmp_path / "w.png").stat().st_size > 10_000
