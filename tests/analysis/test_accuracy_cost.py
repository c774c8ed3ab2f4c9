"""The accuracy-cost study on a chain transmission (issue 16; spec numerics-and-periodic section 9)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from cvtfem.analysis import accuracy_cost as ac
from cvtfem.integrate import solve
from cvtfem.scene.loader import load_scene


def test_window_error_is_the_sources_measure():
    p_ref = np.array([0.0, -100.0, -400.0, -200.0])
    assert ac.window_error(p_ref, p_ref) == 0.0
    assert ac.window_error(p_ref + 8.0, p_ref) == pytest.approx(8.0 / 400.0)
    assert ac.window_error(3 * p_ref, 3 * p_ref + 3) == pytest.approx(ac.window_error(p_ref, p_ref + 1))   # scale-free
    assert ac.window_error([np.nan, 0, 0, 0], p_ref) == np.inf
    assert ac.window_error(p_ref[:3], p_ref) == np.inf


@pytest.fixture(scope="module")
def study():
    scene = load_scene("chain-S2")
    problem, report = ac.pin_force_problem(scene, (0.0, 5e-5), 5e-6, ("Radau", 1e-6), ("rodas5p", 1e-6))
    return scene, problem, report


def test_two_references_agree_far_below_the_acceptance(study):
    _, problem, report = study
    assert report["reference_E"] < 1e-6 < ac.ACCEPT_E
    assert report["samples"] == len(problem.t_eval) == 11
    assert report["force_range_N"][0] < -500          # a pin on an arc: compressed by its contacts


def test_global_error_falls_with_the_step_and_matches_the_series(study):
    _, problem, _ = study
    errors = []
    for h in (1e-6, 5e-7):
        res = solve(**problem.solve_kwargs(), method="rk4", h=h, t_eval=problem.t_eval)
        e = problem.error(res)
        p = problem.pin_forces(res.y)[:, problem.pin]
        assert e == ac.window_error(p, problem.p_ref)
        errors.append(e)
    assert errors[1] < errors[0] < 1e-4


def test_friction_eigenvalues_scale_with_one_over_v0(study):
    """At the start state the pins on the arcs stick: the friction slope f0 N / v0 sets the most negative real
    eigenvalues, so dividing v0 by 10 multiplies them by about 10 (section 9.2's attribution)."""
    scene, problem, _ = study
    lam, lam_v0 = ac.spectrum_with_v0(scene, problem.y0)
    assert len(lam) == len(problem.y0)
    ratio = lam_v0.real.min() / lam.real.min()
    assert 9.0 < ratio < 11.0
    assert np.max(np.abs(lam.imag)) == pytest.approx(np.max(np.abs(lam_v0.imag)), rel=0.05)   # axial modes stay


def test_speedups_pick_the_cheapest_accepted_run():
    rows = [{"label": "rk4", "setting": "h=5e-08", "error": 1e-6, "time": 10.0, "nfev": 4},
            {"label": "rk4", "setting": "h=1e-06", "error": 0.01, "time": 1.0, "nfev": 4},
            {"label": "rk4", "setting": "h=4e-06", "error": 0.2, "time": 0.2, "nfev": 4},
            {"label": "x", "setting": "h=1", "error": np.inf, "time": 0.1, "nfev": 4}]
    table = {t["label"]: t for t in ac.speedups(rows, rows[0])}
    assert table["rk4"]["setting"] == "h=1e-06" and table["rk4"]["speedup"] == 10.0
    assert table["x"]["setting"] is None and table["x"]["speedup"] is None


@pytest.mark.parametrize("args,needle", [
    (("--window", "5:1"), "`--window`"),
    (("--steps", "1e-12"), "`--steps`"),
    (("--fixed", "Radau"), "`--fixed`"),
    (("--reference", "Radau"), "`--reference`"),
    (("--spectrum-png", "x.svg"), "`--spectrum-png`"),
])
def test_bad_arguments_are_refused_before_any_work(cli, args, needle):
    res = cli("study", "accuracy-cost", "chain-S2", *args, timeout=60)
    assert res.returncode == 2 and needle in res.stderr and "Traceback" not in res.stderr


@pytest.mark.slow
def test_the_study_from_the_command_line(cli, tmp_path):
    out = {k: tmp_path / f"a.{k}" for k in ("png", "csv", "json")}
    spectrum = tmp_path / "s.png"
    res = cli("study", "accuracy-cost", "chain-S2", "--window", "0:5e-5", "--sample", "5e-6", "--fixed", "rk4",
              "--steps", "5e-8,1e-6", "--adaptive", "rodas5p", "--rtols", "1e-3", "--reference", "Radau:1e-6",
              "--check", "rodas5p:1e-6", "--repeats", "1", "--png", str(out["png"]), "--spectrum-png", str(spectrum),
              "--csv", str(out["csv"]), "--json", str(out["json"]), timeout=600)
    assert res.returncode == 0, res.stderr
    report = json.loads(out["json"].read_text())
    table = {t["label"]: t for t in report["speedups"]}
    assert table["rk4"]["setting"] == "h=1e-06" and table["rk4"]["speedup"] > 5      # 20x fewer steps
    assert table["rodas5p"]["error"] <= ac.ACCEPT_E
    assert out["png"].stat().st_size > 10_000 and spectrum.stat().st_size > 10_000
