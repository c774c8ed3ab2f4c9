"""Hard cases of the chain with impact at contact onset (issue 13 deliverable 7 for ``effects.contact = "impact"``):
entry at high speed (6000 rpm, and one pin end thrown at the sheave at 5 m/s), stable with its energy balance closed,
and an unstable run that fails loudly naming time, pin and coordinate (docs/chain.md, "Impact at contact onset")."""
import re
from dataclasses import fields

import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.machines.chain_cvt import ChainCVT
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene

#: 10-45 s each at load ~10: slow (the default run's budget goes to tests/machines/test_chain_impact.py)
pytestmark = [pytest.mark.hard, pytest.mark.slow]


def _impact_scene(**regime):
    scene = load_scene("chain-S2").replace({"cvt": {"effects": {"contact": "impact"}}})
    return scene.replace({"cvt": {"regime": regime}}) if regime else scene


def _radau(model, x0, t_end, rtol, t_eval=None):
    return solve(model, (0.0, t_end), x0, method="Radau", rtol=rtol, atol=1e-3 * rtol, n2=model.n2, jac=model.jac,
                 jac_sparsity=model.jac_sparsity, t_eval=t_eval)


def _balance(model, x0, x1):
    """``E(t) - E(0) - (W_in - W_out + W_clamp - W_diss)`` over the input work (impact losses are in ``W_diss``)."""
    W = model.split(x1)[3]
    return (model.energy(x1) - model.energy(x0) - (W[0] - W[1] + W[3] - W[2])) / W[0]


def test_entry_at_6000_rpm_with_impacts():
    """6000 rpm input (chain speed 23 m/s), 0.4 ms from the quasi-static start (Radau rtol 1e-3): pins enter the arcs
    with impacts (events), each leaves its end with no normal approach; the run stays bounded (finite, ratio within
    2 % of 2.4, the discrete state equal to the penetrations' signs) and the energy balance closes to 1e-6."""
    model = chain_loop(_impact_scene(input_speed=6000 * np.pi / 30))
    x0 = model.start()[0]
    res = _radau(model, x0, 4e-4, 1e-3)
    assert res.status == 0 and np.isfinite(res.y).all(), res.message
    x1 = res.y[:, -1]
    hits = [(k, t, y) for k, (ts, ys) in enumerate(zip(res.t_events, res.y_events)) for t, y in zip(ts, ys)]
    approach = []
    for k, _, y in hits:
        w, normal, _, _ = model.impact_map(y, k // 2, k % 2)
        if w @ normal < 0:                                   # an onset (a release has w . n >= 0)
            after = model.switch(0.0, y, np.arange(len(res.t_events)) == k)
            w1, _, _, _ = model.impact_map(after, k // 2, k % 2)
            approach.append(-(w @ normal))
            assert abs(w1 @ normal) < 1e-12 * np.linalg.norm(w)
    state, loss = model.discrete_state(x1)
    balance = _balance(model, x0, x1)
    print(f"6000 rpm: {len(hits)} events, {len(approach)} impacts at normal speeds {np.round(approach, 3)} m/s, "
          f"impact loss {loss * 1e3:.3f} mJ, balance {balance:.2e}")
    assert len(approach) >= 2 and loss > 0
    assert np.array_equal(state > 0, model.events(4e-4, x1) > 0)
    assert model.outputs(4e-4, x1)["ratio"] == pytest.approx(2.4, rel=0.02)
    assert abs(balance) < 1e-6


def test_pin_thrown_at_the_sheave_at_55_m_s_does_not_tunnel():
    """The free pin end nearest to the driving sheave (41 um off) thrown at it along the normal at 55 m/s (the digest's
    top entry speed; its axial spring, ~160 kHz, would stop it after 55 um): the event fires where the end reaches the
    face (penetration 0 to 1e-12 m at the event), the impulse leaves no normal approach, the end then leaves the face
    again on its spring with a penetration below 1 um (touch and leave: its discrete state is free again), and the
    energy balance closes to 1e-6 with the impact's loss in it.  The same throw without impact (H1 alone) goes into
    the face and bounces.  The impact run takes rtol 1e-8: the dissipated work (8.8 J, the throw's kinetic energy) is
    24 times the input work the balance is measured against, and at rtol 1e-6 its quadrature alone errs by 1.2e-6 of
    it (inclined face; 7e-7 at 1e-7, 1e-8 at 1e-8)."""
    model = chain_loop(_impact_scene())
    x0 = model.start()[0]
    gap = model.events(0.0, x0).reshape(-1, 2)[:, 0]
    free = np.flatnonzero((gap < 0) & (gap > -1e-3))
    end = int(free[np.argmax(gap[free])])
    n2, dof, k = model.n2, model.family.dof_index[end, :3], 2 * end
    x = x0.copy()
    w, normal, _, _ = model.impact_map(x, end, 0)
    x[n2 + dof] += (-55.0 - w @ normal) * normal
    t_end = 5e-6
    t_eval = np.linspace(0.0, t_end, 501)
    res = _radau(model, x, t_end, 1e-8, t_eval=t_eval)
    assert res.status == 0 and np.isfinite(res.y).all(), res.message
    assert len(res.t_events[k]) >= 1
    y_hit = res.y_events[k][0]
    assert abs(model.events(res.t_events[k][0], y_hit)[k]) < 1e-12
    w0, _, _, _ = model.impact_map(y_hit, end, 0)
    w1, normal, _, _ = model.impact_map(model.switch(0.0, y_hit, np.arange(2 * model.family.n) == k), end, 0)
    assert w0 @ normal < -10.0 and abs(w1 @ normal) < 1e-12 * np.linalg.norm(w0)
    pen = np.array([model.events(t, y)[k] for t, y in zip(res.t, res.y.T)])
    h1 = ChainCVT(**{f.name: getattr(model, f.name) for f in fields(ChainCVT)})
    cut = slice(model._discrete.start, model._discrete.stop)
    rh = _radau(h1, np.delete(x, np.arange(cut.start, cut.stop)), t_end, 1e-6, t_eval=t_eval)
    assert rh.status == 0
    pen_h1 = np.array([model.events(t, np.insert(y, cut.start, np.zeros(cut.stop - cut.start)))[k]
                       for t, y in zip(rh.t, rh.y.T)])
    loss = model.discrete_state(res.y[:, -1])[1]
    balance = _balance(model, x, res.y[:, -1])
    print(f"thrown at 55 m/s: {len(res.t_events[k])} events at {np.round(res.t_events[k] * 1e6, 3)} us, normal speed "
          f"{-(w0 @ normal):.2f} m/s at the hit, impact loss {loss * 1e3:.3f} mJ, largest penetration "
          f"{pen.max() * 1e6:.3f} um with impact, {pen_h1.max() * 1e6:.3f} um with H1 alone, balance {balance:.2e}")
    assert pen.max() < 1e-6 and loss > 0
    assert model.discrete_state(res.y[:, -1])[0][k] == 0            # touched and left: free again
    assert pen_h1.max() > 2 * max(pen.max(), 1e-7)
    assert abs(balance) < 1e-6


def test_unstable_impact_run_fails_naming_time_pin_and_coordinate(cli, tmp_path):
    """The impact chain with RK4 at a fixed 10 us step (far beyond its stability limit) through ``cvtfem run``: exit
    3, one line on stderr naming the time, the chain model and a pin coordinate, no traceback."""
    scene = tmp_path / "unstable.toml"
    scene.write_text('preset = "chain-S2"\n[cvt.effects]\ncontact = "impact"\n[solver]\nmethod = "rk4"\nh = 1e-5\n',
                     encoding="utf-8")
    r = cli("run", str(scene), "--until", "1e-3", "--results", str(tmp_path / "u.h5"), timeout=300)
    lines = r.stderr.strip().splitlines()
    print(r.stderr)
    assert r.returncode == 3 and len(lines) == 1 and "Traceback" not in r.stderr
    assert "at t = " in lines[0] and "chain model chain-S2" in lines[0]
    assert re.search(r"pin (\d+), (du[123]/dt|u[123])", lines[0]), lines[0]


def test_interrupted_impact_run_resumes_bitwise(tmp_path):
    """A Radau run of the impact chain (0.3 ms, checkpoints every 0.1 ms) stopped after its first checkpoint and
    resumed: the discrete contact state, the impact loss and every other series equal the uninterrupted run's bit for
    bit (the checkpoint holds the state with its discrete block and the event locator's memory), with the impacts after
    the checkpoint located again by the resumed run."""
    from cvtfem.analysis.run import resume_run, run_scene
    from cvtfem.io.results import read_results
    from tests.hard.test_resume import _difference, _interrupted, _series_equal

    scene = _impact_scene().replace({"solver": {"method": "Radau", "rtol": 1e-4, "atol": 1e-7},
                                     "output": {"checkpoint_interval": 1e-4, "step": 1e-5}})
    run_scene(scene, until=3e-4, results=tmp_path / "ref.h5", show_progress=False)
    _interrupted(scene, tmp_path / "r.h5", 1, 3e-4)
    resume_run(tmp_path / "r.h5", show_progress=False)
    ref, res = read_results(tmp_path / "ref.h5"), read_results(tmp_path / "r.h5")
    assert _series_equal(ref, res), _difference(ref, res)
    loss = np.asarray(ref.series["contact.impact_loss"]).ravel()
    t = np.asarray(ref.time)
    print(f"impact loss {loss[t <= 1e-4][-1] * 1e3:.4f} mJ at the checkpoint, {loss[-1] * 1e3:.4f} mJ at the end")
    assert loss[t <= 1e-4][-1] < loss[-1]


def test_ten_ms_of_impacts_without_zeno():
    """10 ms of the impact chain with the preset's rock4 (rtol 1e-3): without the indicator's hysteresis an end left at
    ``Delta = 0`` by its impact crossed zero again in round-off and was hit four times within 1e-11 s (a Zeno failure
    at 7.3 ms); with it the run goes through, every end is hit at most once per entry (no two events of one end closer
    than 1 us), and the energy balance closes to 1e-5 of the input work."""
    model = chain_loop(_impact_scene())
    x0 = model.start()[0]
    res = solve(model, (0.0, 10e-3), x0, method="rock4", rtol=1e-3, atol=1e-6, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity)
    assert res.status == 0, res.message
    gaps = [np.diff(t).min() for t in res.t_events if len(t) > 1]
    n_events = sum(len(t) for t in res.t_events)
    balance = _balance(model, x0, res.y[:, -1])
    print(f"10 ms: {n_events} events, closest two of one end {min(gaps) * 1e6:.2f} us apart, balance {balance:.2e}")
    assert n_events > 30 and min(gaps) > 1e-6
    assert abs(balance) < 1e-5
