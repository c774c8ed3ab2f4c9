"""Hard cases of the running chain (issue 13, deliverable 7): the S2 chain on two rigid sheaves
(``ChainCVT``, preset ``chain-S2``: 84 pins, H1 Hertz contact at the pin ends, ``tanh`` friction) at a
grazing contact onset, at 6000 rpm (pins entering the arcs fast, pins leaving them), at zero slip with a
friction eigenvalue near -1e8 1/s, and with its links through zero tension; each stays stable with its
energy balance closed, or fails loudly naming time, pin and coordinate (docs/hard-cases.md, "Chain")."""
import re
from dataclasses import replace

import h5py
import numpy as np
import pytest

from cvtfem.errors import NumericalError
from cvtfem.integrate import solve
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import load_scene

pytestmark = pytest.mark.hard

#: Friction saturation speed (m/s) that puts the stiffest friction eigenvalue of the reference state near -1e8 1/s.
V0_STIFF = 3.35e-4


def _radau(model, x0, t_end, rtol, t_eval=None):
    """Radau (scipy, the preset's method) with the analytic sparse Jacobian; ``atol = 1e-3 rtol``."""
    return solve(model, (0.0, t_end), x0, method="Radau", rtol=rtol, atol=1e-3 * rtol, n2=model.n2, jac=model.jac,
                 jac_sparsity=model.jac_sparsity, t_eval=t_eval)


def _balance(model, x0, x1):
    """``E(t) - E(0) - (W_in - W_out + W_clamp - W_diss)`` over the input work (the work integrals' balance)."""
    W = model.split(x1)[3]
    return (model.energy(x1) - model.energy(x0) - (W[0] - W[1] + W[3] - W[2])) / W[0]


def _series(model, res, name):
    """Output ``name`` at every sample of ``res``, (samples, size)."""
    return np.array([model.outputs(t, y)[name] for t, y in zip(res.t, res.y.T)])


@pytest.fixture(scope="module")
def reference():
    """The chain-S2 preset (3500 rpm, 200 N m, ratio 2.4) and its quasi-static running start."""
    model = chain_loop(load_scene("chain-S2"))
    return model, model.start()[0]


@pytest.fixture(scope="module")
def high_speed():
    """The preset at 6000 rpm input: 0.4 ms from its quasi-static start (Radau rtol 1e-3), sampled every 1 us."""
    scene = load_scene("chain-S2").replace({"cvt": {"regime": {"input_speed": 6000 * np.pi / 30}}})
    model = chain_loop(scene)
    x0 = model.start()[0]
    res = _radau(model, x0, 4e-4, 1e-3, t_eval=np.linspace(0.0, 4e-4, 401))
    return model, x0, res, _series(model, res, "contact.penetration"), _series(model, res, "contact.normal_force")


def _switches(force):
    """Per pin end and shaft: the sample indices where the contact switches on or off, ``(on, off)`` lists."""
    on = force > 0
    change = np.diff(on.astype(int), axis=0)
    return ([np.flatnonzero(change[:, k] == 1) for k in range(force.shape[1])],
            [np.flatnonzero(change[:, k] == -1) for k in range(force.shape[1])])


def test_grazing_contact_onset(reference):
    """The most loaded pin end (pin 80 on the driving sheave) put exactly on the sheave face (penetration 0)
    with zero normal velocity, its axial spring pushing it in: the penetration crosses zero tangentially.
    Radau (rtol 1e-6) steps through it: no NaN, the force grows from zero without a jump (in time as
    ``t^3``: penetration ``~ t^2``, Hertz ``N ~ Delta^1.5``), the contact closes once and stays closed, the
    step count stays within 3x that of the undisturbed start (the extra steps follow the pin's excited axial
    vibration, 11 us period), and the work integrals close the energy balance."""
    model, x0 = reference
    out0 = model.outputs(0.0, x0)
    k = int(np.argmax(out0["contact.normal_force"]))
    pin = k // 2
    x = x0.copy()
    x[model.family.dof_index[pin, 2]] -= out0["contact.penetration"][k]
    out = model.outputs(0.0, x)
    assert out["contact.penetration"][k] == 0.0 and out["contact.normal_force"][k] == 0.0
    # normal velocity and acceleration of the penetration along the flow: zero and positive (grazing, moving in)
    f = model.rhs(0.0, x)
    h = 1e-9
    pen = [model.outputs(0.0, x + s * h * f)["contact.penetration"][k] for s in (-1, 1)]
    assert abs(pen[1] - pen[0]) / (2 * h) < 1e-6      # m/s (pins enter the arc at ~0.3 m/s)
    assert model.state_label(model.n2 + model.family.dof_index[pin, 2]) == f"pin {pin}, du3/dt"
    assert f[model.n2 + model.family.dof_index[pin, 2]] > 1e5   # u3'' > 0 (m/s^2) toward the sheave
    t_eval = np.concatenate([np.linspace(0.0, 2e-6, 41)[:-1], np.linspace(2e-6, 5e-5, 481)])
    base = _radau(model, x0, 5e-5, 1e-6)
    res = _radau(model, x, 5e-5, 1e-6, t_eval=t_eval)
    assert base.status == 0 and res.status == 0, res.message
    assert np.isfinite(res.y).all()
    N = _series(model, res, "contact.normal_force")[:, k]
    P = _series(model, res, "contact.penetration")[:, k]
    on, off = _switches(N[:, None])
    assert len(on[0]) == 1 and len(off[0]) == 0 and N[0] == 0.0 and N[1] > 0.0
    # onset: log-log slope of N(t) over 0.2..0.6 us is 3 (t^2 penetration), less the cosine's bend (~1 %)
    early = (res.t >= 2e-7 - 1e-15) & (res.t <= 6e-7 + 1e-15)
    slope = np.polyfit(np.log(res.t[early]), np.log(N[early]), 1)[0]
    balance = _balance(model, x, res.y[:, -1])
    print(f"grazing: N slope {slope:.3f}, steps {res.stats['nsteps']} vs {base.stats['nsteps']}, "
          f"largest N {N.max():.0f} N, penetration {P.max() * 1e6:.1f} um, balance {balance:.2e}")
    assert slope == pytest.approx(3.0, abs=0.1)
    assert res.stats["nsteps"] <= 3 * base.stats["nsteps"]
    assert abs(balance) < 1e-6


def test_entry_at_high_speed(high_speed):
    """6000 rpm input (chain speed 23 m/s): pins enter the arcs with a normal approach speed of a few
    tenths of m/s; the run stays bounded (finite, penetration below 2x the quasi-static largest, ratio
    within 2 % of 2.4) and the work integrals close the energy balance."""
    model, x0, res, P, N = high_speed
    assert res.status == 0 and np.isfinite(res.y).all()
    on, _ = _switches(N)
    rate = np.gradient(P, res.t, axis=0)
    entries = [(k, i) for k in range(N.shape[1]) for i in on[k]]
    speeds = np.array([rate[i + 1, k] for k, i in entries])
    print(f"6000 rpm: {len(entries)} entries, approach speeds {np.round(speeds, 3)} m/s, largest penetration "
          f"{P.max() * 1e6:.1f} um (start {P[0].max() * 1e6:.1f}), balance {_balance(model, x0, res.y[:, -1]):.2e}")
    assert len(entries) >= 2 and np.all(speeds > 0.1)
    assert P.max() < 2 * P[0].max()
    assert model.outputs(res.t[-1], res.y[:, -1])["ratio"] == pytest.approx(2.4, rel=0.02)
    assert abs(_balance(model, x0, res.y[:, -1])) < 1e-6


def test_pin_leaving_the_arc(high_speed):
    """Pins leaving the arcs at 6000 rpm: each contact opens once (no on/off chatter at 1 us sampling, a
    tenth of the pin's axial period), and the force before it opens is what the Hertz law gives for the
    penetration left after one sample at the exit speed, ``c (|Delta'| dt)^1.5``: it goes to zero
    continuously."""
    model, _, res, P, N = high_speed
    on, off = _switches(N)
    assert all(len(a) + len(b) <= 1 for a, b in zip(on, off))      # no contact switches twice in 0.4 ms
    exits = [(k, i) for k in range(N.shape[1]) for i in off[k]]
    assert len(exits) >= 2
    dt = res.t[1] - res.t[0]
    for k, i in exits:
        speed = -(P[i + 1, k] - P[i - 1, k]) / (2 * dt)
        bound = model.contact.c[k % 2] * (speed * dt) ** 1.5
        print(f"exit of pin {k // 2} from shaft {k % 2 + 1}: speed {speed:.3f} m/s, last force {N[i, k]:.3g} N "
              f"(bound {bound:.3g} N, largest {N[:, k].max():.4g} N)")
        assert 0 < N[i, k] <= 1.5 * bound and N[i, k] < 0.01 * N[:, k].max()


def test_friction_eigenvalue_near_minus_1e8_at_zero_slip(reference):
    """``v0 = 3.35e-4 m/s`` at the quasi-static start (no slip): the most negative eigenvalue of the
    Jacobian is the friction damping of the most loaded pin end, ``-2 f0 N / v0 (cos^2 g / m + sin^2 g / m3)``
    (both pin ends, the regularised law's slope ``f0 N / v0`` in the face's tangent plane, which is tilted
    by the wedge angle ``g`` between the in-plane mass ``m`` and the axial mass ``m3``): -1.048e8 1/s.
    Radau and the trapezoidal rule run 50 us stably with the energy balance closed; RK4 at h = 10 us (``h lambda = -1e3``) is
    stopped by the growth guard naming time and component."""
    base, x0 = reference
    model = replace(base, contact=replace(base.contact, v0=V0_STIFF))
    out = model.outputs(0.0, x0)
    assert out["contact.slip_speed"].max() < 1e-12
    k = int(np.argmax(out["contact.normal_force"]))
    pin, shaft = divmod(k, 2)
    d = model.family.dof_index[pin]
    M = model.family.mass_matrix().toarray()
    r = np.linalg.norm(x0[d[:2]] - model.contact.centres[shaft])
    g = np.arctan(model.contact.faces[shaft].tan_gamma(r))
    c = 2 * model.contact.f0 * out["contact.normal_force"][k] / V0_STIFF
    predicted = -c * (np.cos(g) ** 2 / M[d[0], d[0]] + np.sin(g) ** 2 / M[d[2], d[2]])
    lam = np.linalg.eigvals(model.jac(0.0, x0).toarray())
    print(f"friction eigenvalue {lam.real.min():.5g} 1/s, predicted {predicted:.5g} 1/s")
    assert lam.real.min() == pytest.approx(predicted, rel=1e-3)
    assert -2e8 < predicted < -5e7
    for method in ("Radau", "trapezoidal"):                 # scipy's, and the project's (A-stable) adaptive
        res = solve(model, (0.0, 5e-5), x0, method=method, rtol=1e-3, atol=1e-6, n2=model.n2, jac=model.jac,
                    jac_sparsity=model.jac_sparsity)
        assert res.status == 0 and np.isfinite(res.y).all(), method
        assert abs(_balance(model, x0, res.y[:, -1])) < 1e-6, method
    rk4 = solve(model, (0.0, 1e-4), x0, method="rk4", h=1e-5, n2=model.n2)
    assert rk4.status == -1
    assert "instability (rk4)" in rk4.message and "at t = " in rk4.message and "component " in rk4.message
    assert np.isfinite(rk4.y).all()


def test_unstable_chain_run_fails_naming_time_pin_and_coordinate(cli, tmp_path, reference):
    """The stiff-friction chain (``cvt.friction.v0`` as above) with RK4 at a fixed 10 us step through
    ``cvtfem run``: exit 3, one line on stderr naming the time, the pin (at or next to a sheave contact at
    the start: pin 6, the first span pin after the driving arc) and the coordinate, no traceback; the
    results file says "failed" with that message and keeps its finite rows."""
    scene = tmp_path / "unstable.toml"
    scene.write_text(f'preset = "chain-S2"\n[solver]\nmethod = "rk4"\nh = 1e-5\n[cvt.friction]\nv0 = {V0_STIFF}\n',
                     encoding="utf-8")
    h5 = tmp_path / "u.h5"
    r = cli("run", str(scene), "--until", "1e-3", "--results", str(h5), timeout=300)
    lines = r.stderr.strip().splitlines()
    print(r.stderr)
    assert r.returncode == 3 and len(lines) == 1 and "Traceback" not in r.stderr
    line = lines[0]
    assert "instability (rk4)" in line and "at t = 5e-05 s" in line and "chain model chain-S2" in line
    named = re.search(r"pin (\d+), du[123]/dt", line)
    assert named, line
    model, x0 = reference
    touching = model.outputs(0.0, x0)["contact.normal_force"].reshape(-1, 2).max(axis=1) > 0
    assert touching[(int(named[1]) + np.arange(-1, 2)) % model.family.n].any()
    with h5py.File(h5) as f:
        assert f.attrs["status"] == "failed" and "pin " in f.attrs["message"]
        s = f["series"]
        assert len(s["time"]) >= 1 and all(np.isfinite(s[name][:]).all() for name in s)


def test_links_through_zero_tension(reference):
    """The clamping forces dropped to 1 N per sheave from the running state: the sheaves open, the pins
    leave the arcs (~0.1 ms) and the released ring's links pass through zero tension into compression (the
    S2 link law is bilateral); the run finishes without NaN and the work integrals close the energy balance.
    A quasi-static start at (almost) no clamping has no balance to find: it fails loudly."""
    model, x0 = reference
    slack = model.with_clamping([1.0, 1.0])
    res = _radau(slack, x0, 1.6e-4, 1e-4, t_eval=np.linspace(0.0, 1.6e-4, 17))
    assert res.status == 0 and np.isfinite(res.y).all()
    T = _series(slack, res, "chain.link_tension")
    crossed = (T.max(axis=0) > 0) & (T.min(axis=0) < 0)
    print(f"released: {crossed.sum()} links through zero tension, tension {T.min():.0f}..{T.max():.0f} N, "
          f"balance {_balance(slack, x0, res.y[:, -1]):.2e}")
    assert crossed.sum() == model.family.n
    assert np.all(_series(slack, res, "contact.normal_force")[-1] == 0.0)
    assert abs(_balance(slack, x0, res.y[:, -1])) < 1e-6
    with pytest.raises(NumericalError, match=r"quasi-static solve .* residual .* in ChainCVT.static_state"):
        model.with_clamping([1e-3, 1e-3]).static_state(2.4, 1.0)


@pytest.mark.slow
def test_grazing_onset_of_a_whole_arc(reference):
    """Every pin end on the driving arc (11) put on the face with zero normal velocity at once: Radau
    (rtol 1e-6) steps through, each contact closes once, the energy balance closes (~6 s)."""
    model, x0 = reference
    out = model.outputs(0.0, x0)
    arc = [k for k in np.flatnonzero(out["contact.normal_force"] > 0) if k % 2 == 0]
    x = x0.copy()
    for k in arc:
        x[model.family.dof_index[k // 2, 2]] -= out["contact.penetration"][k]
    assert np.all(model.outputs(0.0, x)["contact.normal_force"][arc] == 0.0)
    base = _radau(model, x0, 5e-5, 1e-6)
    res = _radau(model, x, 5e-5, 1e-6, t_eval=np.linspace(0.0, 5e-5, 501))
    assert res.status == 0 and np.isfinite(res.y).all()
    on, off = _switches(_series(model, res, "contact.normal_force")[:, arc])
    assert all(len(a) == 1 for a in on) and not any(len(b) for b in off)
    print(f"arc grazing: {len(arc)} pin ends, steps {res.stats['nsteps']} vs {base.stats['nsteps']}, "
          f"balance {_balance(model, x, res.y[:, -1]):.2e}")
    assert res.stats["nsteps"] <= 5 * base.stats["nsteps"]
    assert abs(_balance(model, x, res.y[:, -1])) < 1e-6


def test_state_labels_name_every_state_once(reference):
    """``state_label`` is one-to-one over the state: each pin coordinate and velocity, the shafts, loops and
    work integrals (so a failure message names one state); a free S3 chain labels its five per-pin coordinates."""
    from cvtfem.elements.chain.geometry import REFERENCE_SECTION, chain_geometry
    from cvtfem.elements.chain.symmetric import ChainS3
    from cvtfem.machines.chain import FreeChain

    model, _ = reference
    labels = [model.state_label(i) for i in range(model.size)]
    assert len(set(labels)) == model.size
    d = model.family.dof_index
    assert labels[d[17, 2]] == "pin 17, u3" and labels[model.n2 + d[17, 0]] == "pin 17, du1/dt"
    assert labels[model.family.size + 1] == "driven shaft, phi" and labels[-2] == "work: dissipated"
    n = 6
    family = ChainS3(chain_geometry(n, 0.033, 0.009, 12, 1.4e9, n * 0.0179, REFERENCE_SECTION, c_pin=2.0e8,
                                    closed=False))
    free = FreeChain(family, np.zeros(family.size))
    free_labels = [free.state_label(i) for i in range(free.size)]
    assert len(set(free_labels)) == free.size
    assert free_labels[family.dof_index[4, 4]] == "pin 4, u'2"
    assert free_labels[free.n2 + family.dof_index[4, 3]] == "pin 4, du'1/dt"


def test_failure_without_a_component_names_the_fastest_pin_state(reference):
    """A stepper failure that names no component (step-size underflow, scipy's messages): ``cvtfem run`` adds
    the fastest state at the last accepted step; a pin end pushed 5 um further into the sheave (Hertz force
    +~40 %, pin axial acceleration ~1e5 m/s^2) is the one named."""
    from types import SimpleNamespace

    from cvtfem.analysis.run import _failure

    model, x0 = reference
    k = int(np.argmax(model.outputs(0.0, x0)["contact.normal_force"]))
    x = x0.copy()
    x[model.family.dof_index[k // 2, 2]] += 5e-6
    run = SimpleNamespace(message="step size underflow (h = 1e-15 s) at t = 0 s", t=0.0, x=x)
    text = _failure(model, "Radau", run, 1e-3, 1e-6)
    assert text.startswith("Radau failed: step size underflow")
    assert f"fastest state: component {model.n2 + model.family.dof_index[k // 2, 2]} (pin {k // 2}, du3/dt)" in text


@pytest.mark.slow
def test_entries_and_exits_over_two_ms_at_high_speed():
    """6000 rpm for 2 ms (about five pitches per arc end, 1 us samples, Radau rtol 1e-3): every pin end
    that enters or leaves an arc switches once, each exit's last force obeys the Hertz bound of
    :func:`test_pin_leaving_the_arc`, every state stays finite, the energy balance closes (~10 s)."""
    scene = load_scene("chain-S2").replace({"cvt": {"regime": {"input_speed": 6000 * np.pi / 30}}})
    model = chain_loop(scene)
    x0 = model.start()[0]
    res = _radau(model, x0, 2e-3, 1e-3, t_eval=np.linspace(0.0, 2e-3, 2001))
    assert res.status == 0 and np.isfinite(res.y).all()
    P, N = _series(model, res, "contact.penetration"), _series(model, res, "contact.normal_force")
    on, off = _switches(N)
    assert all(len(a) <= 1 and len(b) <= 1 for a, b in zip(on, off))
    exits = [(k, i) for k in range(N.shape[1]) for i in off[k]]
    dt = res.t[1] - res.t[0]
    worst = 0.0
    for k, i in exits:
        speed = -(P[i + 1, k] - P[i - 1, k]) / (2 * dt)
        worst = max(worst, N[i, k] / (model.contact.c[k % 2] * (speed * dt) ** 1.5))
    print(f"2 ms at 6000 rpm: {sum(map(len, on))} entries, {len(exits)} exits, last force / Hertz bound at most "
          f"{worst:.2f}, {res.stats['nsteps']} steps, balance {_balance(model, x0, res.y[:, -1]):.2e}")
    assert len(exits) >= 8 and worst <= 1.5
    assert abs(_balance(model, x0, res.y[:, -1])) < 1e-6


@pytest.mark.slow
def test_rk4_beyond_its_friction_limit_is_bounded_and_warned(cli, tmp_path):
    """The preset (``v0 = 0.02 m/s``: friction eigenvalue -1.75e6 1/s) with RK4 at a fixed 2 us step,
    ``h lambda = -3.5`` beyond RK4's real stability limit -2.79: the saturating friction law keeps the run
    bounded (no growth-guard stop, finite results, exit 0), so its only alarm is the local-error monitor's
    warning line (estimate > 1 x the tolerance) (~5 s)."""
    scene = tmp_path / "rk4.toml"
    scene.write_text('preset = "chain-S2"\n[solver]\nmethod = "rk4"\nh = 2e-6\n', encoding="utf-8")
    h5 = tmp_path / "r.h5"
    r = cli("run", str(scene), "--until", "3e-3", "--results", str(h5), timeout=600)
    assert r.returncode == 0, r.stderr
    assert "fixed step too large for the tolerance: estimated local error" in r.stderr
    with h5py.File(h5) as f:
        assert f.attrs["status"] == "finished" and f["stats"].attrs["solver_err_check_max"] > 1.0
        assert all(np.isfinite(f["series"][name][:]).all() for name in f["series"])
