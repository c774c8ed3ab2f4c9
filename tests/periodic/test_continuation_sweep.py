"""Sweeps that follow the branch through folds (issue 18, deliverable 2): a hardening one-sided stop."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from cvtfem.elements.torsional import GAP, build_network
from cvtfem.errors import InputError, NumericalError
from cvtfem.periodic.continuation import continuation
from cvtfem.periodic.hb import solve_periodic
from cvtfem.periodic.response import SAMPLES, response_sweep
from cvtfem.periodic.stability import floquet

N, M = 16, 1024   # M = 64 N: with M = 8 N the AFT sampling of the contact kink puts spurious fold pairs on the nose


def stop_oscillator(scale: float = 1.0):
    """1-DOF on a soft spring (1 N/m) hitting a one-sided stop (4 N/m) after 0.5 m; times scaled by ``scale``."""
    c = scale
    return build_network([1.0], [0.05 * c], [0], [-1], [4.0 * c ** 2], law=[GAP], k_in=[1.0 * c ** 2], h=[0.5],
                         orders=(1,), Q=[[0.06 * c ** 2]])


def amplitude(sol) -> float:
    return float(np.ptp(sol.displacements(SAMPLES)) / 2)


def natural_sweep(net, omegas, a0=None) -> np.ndarray:
    """Independent reference: Newton at each frequency from the previous solution (no arclength);
    amplitudes, NaN where Newton fails (past a fold, where the branch it followed ends)."""
    out, a = [], a0
    for w in omegas:
        sol = solve_periodic(net, w, N, samples=M, a0=a)
        out.append(amplitude(sol) if sol.converged else np.nan)
        a = sol.a if sol.converged else None
    return np.array(out)


def branch_end(amp: np.ndarray, factor: float) -> int:
    """Index of the last point before the amplitude jumps by ``factor`` (or Newton fails)."""
    ratio = amp[1:] / amp[:-1]
    return int(np.argmax(~((ratio > min(factor, 1 / factor)) & (ratio < max(factor, 1 / factor)))))


@pytest.fixture(scope="module")
def up():
    return response_sweep(stop_oscillator(), np.linspace(0.6, 1.8, 25), N, samples=M)


def test_defaults_reach_the_end_of_the_resonance():
    # main: the default max_steps = 400 with ds_max = 0.1 stopped near the top of the resonance
    branch = continuation(stop_oscillator(), 0.6, 1.8, N, samples=M)
    assert branch.message == "reached omega_stop" and branch.omega[-1] >= 1.8
    assert len(branch.turning_points) == 2 and branch.steps < 400


def test_upward_sweep_stays_on_the_upper_branch_to_its_fold(up):
    net = stop_oscillator()
    w, amp = up.omega, up.amplitudes()[:, 0]
    t_up, t_low = np.flatnonzero(up.turning)
    fold_up, fold_low = up.branch.fold_omega
    assert fold_low < fold_up
    # independent fold estimate: natural sweeps in steps of 1e-3 rad/s from both sides; the upper branch
    # ends (jumps down) within one step above the continuation's fold, the lower one within one step below
    ws = np.concatenate([np.arange(0.9, 1.1, 0.01), np.arange(1.10, 1.19, 1e-3)])
    a_up = natural_sweep(net, ws)
    jump = branch_end(a_up, 0.8)
    assert ws[jump] <= fold_up < ws[jump + 1]
    wd = np.concatenate([np.arange(1.3, 1.1, -0.01), np.arange(1.10, 1.00, -1e-3)])
    a_low = natural_sweep(net, wd)
    drop = branch_end(a_low, 1.5)
    assert wd[drop + 1] < fold_low <= wd[drop]
    # the swept points: every requested frequency up to the fold on the upper (stable) branch, equal to the
    # natural sweep's there; then the unstable middle branch and the lower branch
    before = np.arange(t_up)
    assert np.all(np.diff(w[before]) > 0) and up.stable[before].all()
    for k in before[w[before] >= 0.9]:
        j = np.argmin(abs(ws - w[k]))
        assert ws[j] == pytest.approx(w[k], abs=1e-9) and amp[k] == pytest.approx(a_up[j], rel=1e-7)
    middle = np.arange(t_up + 1, t_low)
    assert np.all(np.diff(w[t_up:t_low + 1]) < 0) and not up.stable[middle].any()
    after = np.arange(t_low + 1, len(w))
    assert np.all(np.diff(w[t_low:]) > 0) and up.stable[after].all()
    for k in after[w[after] <= 1.3]:
        j = np.argmin(abs(wd - w[k]))
        assert wd[j] == pytest.approx(w[k], abs=1e-9) and amp[k] == pytest.approx(a_low[j], rel=1e-7)
    # three solutions at each requested frequency between the folds, ordered upper > middle > lower
    for target in (1.1, 1.15):
        at = np.flatnonzero(np.isclose(w, target, atol=1e-12))
        assert len(at) == 3 and amp[at[0]] > amp[at[1]] > amp[at[2]]
        assert list(up.stable[at]) == [True, False, True]


def test_downward_sweep_returns_the_lower_branch(up):
    down = response_sweep(stop_oscillator(), np.linspace(1.8, 0.6, 25), N, samples=M, stability=False)
    assert np.allclose(down.branch.fold_omega[::-1], up.branch.fold_omega, rtol=1e-7)
    w, amp = down.omega, down.amplitudes()[:, 0]
    t_low = int(np.flatnonzero(down.turning)[0])
    assert w[t_low] == pytest.approx(min(up.branch.fold_omega))
    assert np.all(np.diff(w[:t_low + 1]) < 0)
    w_up, amp_up = up.omega, up.amplitudes()[:, 0]
    for k in range(t_low):  # on the way down: the lower branch of the upward sweep, point by point
        same = np.flatnonzero(np.isclose(w_up, w[k], atol=1e-12))[-1]
        assert amp[k] == pytest.approx(amp_up[same], rel=1e-7)
    assert not np.isfinite(down.floquet_max).any()


def test_stability_flips_at_the_folds_where_one_multiplier_crosses_plus_one(up):
    branch = up.branch
    for t in branch.turning_points:
        before, fold, after = (floquet(branch.solutions[k], rtol=1e-10).multipliers for k in (t - 1, t, t + 1))
        assert abs(fold[np.argmin(abs(fold - 1))] - 1) < 2e-3       # saddle-node: a multiplier at +1
        stable = [bool(np.abs(m).max() < 1) for m in (before, after)]
        assert stable[0] != stable[1]
        unstable = after if stable[0] else before
        out = unstable[np.abs(unstable) > 1]
        assert len(out) == 1 and abs(out[0].imag) < 1e-9 and out[0].real > 1


def test_linear_network_gives_the_closed_form_frf_and_is_stable():
    m, b, k = np.array([1.0, 2.0]), np.array([0.05, 0.02]), np.array([3.0, 1.5])
    net = build_network(m, b, [0, 1], [1, -1], k, orders=(1,), Q=[[0.7], [0.0]])
    omegas = np.linspace(0.3, 2.5, 23)
    sweep = response_sweep(net, omegas, 3)
    assert np.allclose(sweep.omega, omegas) and sweep.requested.all() and not sweep.turning.any()
    K = np.array([[k[0], -k[0]], [-k[0], k[0] + k[1]]])
    for w, sol in zip(omegas, sweep.nonlinear):
        x = np.linalg.solve(K - w ** 2 * np.diag(m) + 1j * w * np.diag(b), [0.7, 0.0])
        assert np.allclose(2 * sol.a[:, 4], x, rtol=1e-9, atol=1e-12)
    assert sweep.stable.all()


def test_continuation_that_cannot_finish_says_where():
    with pytest.raises(NumericalError, match="max_steps = 5 steps"):
        continuation(stop_oscillator(), 0.6, 1.8, N, samples=M, max_steps=5)


def test_continuation_without_excitation_is_an_input_error():
    """No load (or only zero amplitudes): the response is zero everywhere and there is no branch to scale and follow
    (the fuzzer's `periodic` on engine_gear_train without its loads divided 0 by 0); the key is named."""
    unloaded = build_network([1.0], [0.05], [0], [-1], [4.0], law=[GAP], k_in=[1.0], h=[0.5], orders=(1,), Q=[[0.0]])
    with pytest.raises(InputError, match="torsional.load"):
        continuation(unloaded, 0.6, 1.8, N, samples=M)


SCENE = """
title = "hardening one-sided stop"
[periodic]
harmonics = 16
samples = 1024
[[torsional.disk]]
name = "mass"
inertia = 1.0
radius = 1.0
damping = {d!r}
[[torsional.link]]
kind = "gap"
a = "mass"
b = "ground"
stiffness = {k_out!r}
gap_stiffness = {k_in!r}
clearance = 0.5
[[torsional.load]]
disk = "mass"
orders = [1]
amplitudes = [{q!r}]
"""


@pytest.fixture
def scene(tmp_path):
    c = 2 * np.pi * 10   # the oscillator with its gap frequency at 10 Hz
    path = tmp_path / "stop.toml"
    path.write_text(SCENE.format(d=0.05 * c, k_out=4 * c ** 2, k_in=c ** 2, q=0.06 * c ** 2))
    return path


def test_cli_sweeps_down_through_both_folds_with_stability_in_json_and_csv(cli, scene, tmp_path):
    out = cli("periodic", str(scene), "--sweep", "18:6:13", "--json", str(tmp_path / "s.json"),
              "--csv", str(tmp_path / "s.csv"), "--png", str(tmp_path / "s.png"))
    assert out.returncode == 0 and out.stderr == "", out.stderr
    data = json.loads((tmp_path / "s.json").read_text())
    points = data["points"]
    f = np.array([p["frequency"] for p in points])
    assert f[0] == pytest.approx(18.0) and f[-1] == pytest.approx(6.0)
    turns = [k for k, p in enumerate(points) if p["turning_point"]]
    assert len(turns) == 2 and f[turns[0]] == pytest.approx(10.56688, abs=1e-4)
    assert f[turns[1]] == pytest.approx(11.69974, abs=1e-4)
    assert [x["frequency"] for x in data["folds"]] == pytest.approx(f[turns].tolist())
    for p in points:
        assert p["stable"] == (p["floquet_max_modulus"] < 1) and p["amplitude"]["mass"] > 0
    assert not any(p["stable"] for p in points[turns[0] + 1:turns[1]])
    assert all(p["stable"] for p in points[:turns[0]] + points[turns[1] + 1:])
    rows = list(csv.DictReader((tmp_path / "s.csv").open()))
    assert len(rows) == len(points)
    assert [float(r["floquet_max_modulus"]) for r in rows] == [p["floquet_max_modulus"] for p in points]
    assert [int(r["turning_point"]) for r in rows] == [int(p["turning_point"]) for p in points]
    assert (tmp_path / "s.png").stat().st_size > 10_000


def test_cli_warns_once_when_the_sweep_starts_inside_the_fold_range(cli, scene):
    out = cli("periodic", str(scene), "--sweep", "11:6:6", "--no-stability")
    assert out.returncode == 0
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "warning" in lines[0] and "11 Hz" in lines[0] and "multi-valued" in lines[0]
    clean = cli("periodic", str(scene), "--sweep", "6:9:4", "--no-stability")
    assert clean.returncode == 0 and clean.stderr == ""


@pytest.mark.slow
def test_time_integration_settles_on_the_stable_branches_and_leaves_the_unstable_one(up):
    from cvtfem.periodic.transient import steady_state

    net = stop_oscillator()
    at = np.flatnonzero(np.isclose(up.omega, 1.1, atol=1e-12))      # upper, middle, lower
    amp = up.amplitudes()[at, 0]

    def settle(k, factor=1.0):
        ss = steady_state(net, 1.1, rtol=1e-9, atol=1e-12, tol=1e-7, y0=up.nonlinear[k].state() * factor)
        return float(np.ptp(ss.x) / 2)

    assert settle(at[0]) == pytest.approx(amp[0], rel=1e-4)         # HB truncation N = 16: 1.2e-5 seen
    assert settle(at[2]) == pytest.approx(amp[2], rel=1e-4)
    assert settle(at[1], 1.01) == pytest.approx(amp[0], rel=1e-4)   # a 1 % push off the middle branch
    assert settle(at[1], 0.99) == pytest.approx(amp[2], rel=1e-4)   # falls to either stable one


def test_sweep_ending_inside_the_fold_range_names_the_fold_beyond(up):
    sweep = response_sweep(stop_oscillator(), np.linspace(0.9, 1.1, 3), N, samples=M, stability=False)
    assert not sweep.turning.any() and len(sweep.warnings) == 1
    fold_hz = max(up.branch.fold_omega) / (2 * np.pi)
    assert "ends at" in sweep.warnings[0] and f"{fold_hz:.6g} Hz" in sweep.warnings[0]


def test_requested_frequencies_must_be_monotonic():
    with pytest.raises(InputError, match="strictly increasing or decreasing"):
        response_sweep(stop_oscillator(), [1.0, 2.0, 1.5], N)
