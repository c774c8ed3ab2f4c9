"""`cvtfem run`: results file, summary JSON, progress-free CI runs, clear errors."""
import json

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.io.results import read_results
from cvtfem.scene.loader import load_scene


def test_run_writes_results_and_summary(cli, tmp_path):
    out, js = tmp_path / "r.h5", tmp_path / "s.json"
    proc = cli("run", "band-4dof", "--until", "0.05", "--results", str(out), "--summary-json", str(js))
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    for key in ("simulated_time_s", "wall_time_s", "ratio", "input_speed_rpm", "output_speed_rpm", "efficiency",
                "solver"):
        assert key in s
    assert s["simulated_time_s"] == pytest.approx(0.05)
    assert s["solver"]["name"] == "BDF" and s["solver"]["nfev"] > 0  # the band-4dof preset's method
    from cvtfem.elements.band.compressible_kernel import HAVE_NUMBA
    assert s["solver"]["kernel"] == ("numba" if HAVE_NUMBA else "numpy")  # which right-hand side ran
    assert f"{s['solver']['kernel']} right-hand side" in proc.stdout
    cpu = s["process_cpu_time_s"]                          # the stepping's CPU time, printed beside the wall time
    assert 0 < cpu and f"{cpu:.3g} s CPU in this process" in proc.stdout
    assert read_results(out).stats["process_cpu_time_s"] == cpu
    assert s["ratio"] == pytest.approx(2.4, rel=0.01)
    assert s["input_speed_rpm"] == pytest.approx(3500, rel=0.01)
    assert 0.9 < s["efficiency"] < 1.0
    r = read_results(out)
    assert r.attrs["status"] == "finished"
    assert r.time[-1] == pytest.approx(0.05) and len(r.time) == 51
    assert r.units["driving.speed"] == "rad/s"
    # efficiency series = output over input power, and the works integrate the powers
    P = r.series["power"]
    assert r.series["efficiency"][:, 0] == pytest.approx(P[:, 1] / P[:, 0])
    W = r.series["work"]
    assert W[-1, 0] == pytest.approx(np.trapezoid(P[:, 0], r.time), rel=1e-3)


def test_chain_model_without_a_time_run_is_refused(cli):
    proc = cli("run", "chain-S3-refined,shafts-elastic", "--results", "none")      # S3 + H2 on elastic shafts: not yet
    assert proc.returncode == 2
    assert "cvt.effects.shaft_elasticity" in proc.stderr and "chain-S3" in proc.stderr and "chain-A5" in proc.stderr
    assert len(proc.stderr.splitlines()) == 1
    proc = cli("run", "band-1dof", "--results", "none")
    assert proc.returncode == 2 and "static" in proc.stderr


def test_bad_until_is_an_input_error(cli):
    proc = cli("run", "band-4dof", "--until", "-1", "--results", "none")
    assert proc.returncode == 2 and "--until" in proc.stderr


def test_compressible_run_records_normal_force(tmp_path):
    scene = load_scene("band-6+2n", {"cvt": {"ritz_order": 2, "quadrature_nodes": 8}, "output": {"step": 5e-4}})
    s = run_scene(scene, until=2e-3, results=tmp_path / "n.h5", show_progress=False)
    r = read_results(tmp_path / "n.h5")
    N = r.series["band.normal_force"]
    assert N.shape == (5, 16)
    assert np.all(N > 0) and np.ptp(N[-1, :8]) > 0.2 * N[-1, :8].mean()
    assert s.n_coordinates == 10


def _run_json(cli, tmp_path, name, solver_toml):
    scene, js = tmp_path / f"{name}.toml", tmp_path / f"{name}.json"
    scene.write_text('preset = "band-4dof"\n[solver]\n' + solver_toml)
    proc = cli("run", str(scene), "--until", "0.05", "--results", "none", "--summary-json", str(js))
    assert proc.returncode == 0, proc.stderr
    return json.loads(js.read_text())


@pytest.mark.parametrize("name, solver_toml", [
    ("trapezoidal", 'method = "trapezoidal"\n'),          # adaptive, the preset's rtol 1e-3 / atol 1e-5
    ("rk4", 'method = "rk4"\nh = 1e-5\n')])               # explicit, fixed step
def test_cvtfem_integrate_methods_match_the_bdf_preset(cli, tmp_path, name, solver_toml):
    """`cvtfem run` with cvtfem.integrate methods (through CvtfemSolver) ends, after the start-up
    transient of 0.05 s (ratio 2.40442, not yet 2.4), where the preset's BDF ends.  Both control the
    local error to rtol = 1e-3 and the loops contract, so final values agree well within rtol / 10 =
    1e-4 (measured: trapezoidal 2e-6, rk4 h = 1e-5 1e-6, BDF vs Radau at rtol 1e-9 2.5e-6).  RK4 at
    h = 1e-5 is inside its stability limit for the friction (at h = 2e-5 the ratio is off by 2e-3)."""
    ref = _run_json(cli, tmp_path, "bdf", "")
    s = _run_json(cli, tmp_path, name, solver_toml)
    assert ref["solver"]["name"] == "BDF" and s["solver"]["name"] == name
    for key in ("ratio", "input_speed_rpm", "output_speed_rpm"):
        assert s[key] == pytest.approx(ref[key], rel=1e-4), key
    assert abs(s["ratio"] / 2.4 - 1) > 1e-3  # still in the transient: the comparison is not trivially at target
    if name == "rk4":
        assert s["solver"]["steps"] == 5000     # fixed step: 0.05 s / 1e-5 s


def test_dumka3_run_matches_the_bdf_preset(cli, tmp_path):
    """`cvtfem run` with DUMKA3 (adaptive, automatic polynomial, the preset's rtol 1e-3) ends where
    the preset's BDF ends, within rtol / 10 like the other cvtfem.integrate methods."""
    ref = _run_json(cli, tmp_path, "bdf", "")
    s = _run_json(cli, tmp_path, "dumka3", 'method = "dumka3"\n')
    assert s["solver"]["name"] == "dumka3"
    for key in ("ratio", "input_speed_rpm", "output_speed_rpm"):
        assert s[key] == pytest.approx(ref[key], rel=1e-4), key
