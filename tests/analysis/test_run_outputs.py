"""Run outputs: the results file holds, at every sample, the outputs of the reference numpy path."""
import math

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.io.results import read_results
from cvtfem.machines.band_cvt import BandCVT
from cvtfem.scene.loader import load_scene


def reference_outputs(loop, t, x):
    """Outputs as computed before the compiled energies (issue 12): the model's numpy kinetic and elastic
    energies, the powers rebuilt from the loads, the mean normal force by ``mean``."""
    _, info = loop.evaluate(t, x)
    q, v, _, W = loop.split(x)
    N = np.asarray(info["N"])
    w, M, F = info["w"], info["M"], info["F"]
    P = np.array([M[0] * w[0], -M[1] * w[1], info["dissipation"], info["clamp_power"]])
    out = {"band.span_angle": q[0], "band.slip_speed": info["slip"], "band.slip_max": info["slip_max"],
           "band.mean_normal_force": N.mean(axis=-1) if N.ndim == 2 else N,
           "driving.speed": w[0], "driving.torque": M[0], "driving.clamping_force": F[0],
           "driven.speed": w[1], "driven.torque": M[1], "driven.clamping_force": F[1],
           "control.ratio_estimate": info["ratio_estimate"], "control.resistance": info["resistance"],
           "efficiency": P[1] / P[0] if P[0] else 0.0, "ratio": w[0] / w[1] if w[1] else math.nan,
           "power": P, "work": W, "energy": loop.model.kinetic_energy(q, v) + loop.model.elastic_energy(q)}
    if N.ndim == 2:
        out["band.normal_force"] = N.ravel()
    return out


@pytest.mark.parametrize("name", ["band-4dof", "band-6+2n", "band-6+2n+8"])
def test_results_file_holds_the_reference_outputs(name, tmp_path, monkeypatch):
    """Every series at every sample of a short run equals the reference to 1e-12 relative (per sample)."""
    calls = []
    fast = BandCVT.outputs

    def recording(loop, t, x):
        calls.append((loop, t, np.array(x)))
        return fast(loop, t, x)

    monkeypatch.setattr(BandCVT, "outputs", recording)
    run_scene(load_scene(name), until=0.02, results=tmp_path / "r.h5", show_progress=False)
    res = read_results(tmp_path / "r.h5")
    assert res.time.size == 21
    samples = calls[-21:]  # the calls before the run only name the outputs
    for i, (loop, t, x) in enumerate(samples):
        assert res.time[i] == t
        ref = reference_outputs(loop, t, x)
        assert set(ref) == set(res.series)
        for key, value in ref.items():
            value = np.asarray(value, float).ravel()
            assert np.abs(res.series[key][i] - value).max() <= 1e-12 * np.abs(value).max(), (key, i)
    energy = res.series["energy"][:, 0]
    assert energy.min() > 0 and np.ptp(energy) > 0  # the energy series is exercised, not constant


def test_the_last_sample_is_written_when_the_end_is_a_round_off_multiple_of_the_step(tmp_path):
    """``--until 3e-4`` at an output step of 1e-4: ``arange`` gives 3.0000000000000003e-4 as the last sample; the
    run writes it at t_end (the stepper lands on t_end exactly) and its summary covers the whole span."""
    scene = load_scene("band-4dof", {"output": {"step": 1e-4}})
    run_scene(scene, until=3e-4, results=tmp_path / "r.h5", show_progress=False)
    res = read_results(tmp_path / "r.h5")
    assert res.time.tolist() == [0.0, 1e-4, 2e-4, 3e-4]
