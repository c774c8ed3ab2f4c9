"""Impact at contact onset on the running S2 chain (contact-models digest §3, C2): the impulse through the model's mass
matrix and contact map against the digest's closed form, the C2 conditions, the kinetic energy and momentum balance
through the jump, the event located on a closed-form onset, the discrete state, and the energy balance of a run."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.chain.pin_impact import (end_geometry, gap_indicators, pin_end_impulses, relative_velocity_map,
                                              symmetric_compliance)
from cvtfem.elements.chain.sheave_contact import SheaveContact
from cvtfem.elements.contact.impact import FREE, SLIDING, STUCK
from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.machines.chain_impact_cvt import ImpactChainCVT
from cvtfem.machines.cvt import chain_loop, chain_refusal, layout
from cvtfem.scene.loader import load_scene

K = np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def scene():
    return load_scene("chain-S2").replace({"cvt": {"effects": {"contact": "impact"}}})


@pytest.fixture(scope="module")
def model(scene):
    return chain_loop(scene)


@pytest.fixture(scope="module")
def x0(model):
    return model.initial_state()


def _approaching(model, x, seed, n=12, speed=0.3):
    """``x`` with random pin-end/sheave/shaft velocities added and ``n`` (end, shaft) pairs near their sheave whose
    relative velocity points into the face; returns the state and the pairs."""
    rng = np.random.default_rng(seed)
    x = x.copy()
    n2, nc = model.n2, model.family.size
    x[n2:n2 + nc] += rng.normal(0.0, speed, nc)
    x[n2 + nc:2 * n2] += rng.normal(0.0, 0.05, 4)
    e = model.events(0.0, x).reshape(-1, 2)
    near = np.argwhere(e > -5e-4)
    pairs = near[rng.choice(len(near), n, replace=False)]
    for i, (end, shaft) in enumerate(pairs):
        w, normal, G, MinvGt = model.impact_map(x, end, shaft)
        if i % 2:   # into the face along the normal (random approach speed), slip kept
            target = w + (-np.sum(normal * w) - rng.uniform(0.05, 2.0)) * normal
        else:       # w = -A P for a sticking impulse P inside the friction cone (A mixes normal and tangent)
            t = np.cross(normal, rng.normal(size=3))
            P = rng.uniform(1e-5, 1e-3) * (normal + 0.9 * model.contact.f0 * rng.uniform() * t / np.linalg.norm(t))
            target = -2 * G @ MinvGt @ P
        x[n2 + model.family.dof_index[end, :3]] += target - w     # the pin end's velocity enters w as it is
    return x, pairs


def test_scene_routing_and_what_impact_refuses(scene, model, x0):
    assert isinstance(model, ImpactChainCVT)
    n = model.family.n
    assert model.size == 2 * model.n2 + model.control.size + 2 * n + 1 + 4
    parts = layout(scene)
    assert sum(p.n1 for p in parts) == model.size - 2 * model.n2 and parts[0].discrete == 2 * n
    s1 = load_scene("chain-S1").replace({"cvt": {"effects": {"contact": "impact"}}})
    assert "no axial inertia" in str(chain_refusal(s1))
    a2 = load_scene("chain-A1").replace({"cvt": {"model": "chain-A2", "effects": {"contact": "impact"}}})
    with pytest.raises(InputError, match=r"cvt\.effects\.contact.*chain-S2, chain-S3, chain-A1"):
        chain_loop(a2)
    # the discrete state at the start: the ends that penetrate, and nothing lost yet
    state, loss = model.discrete_state(x0)
    assert loss == 0.0 and np.array_equal(state, np.where(model.events(0.0, x0) > 0, SLIDING, FREE))
    assert 30 < (state > 0).sum() < 2 * n
    o = model.outputs(0.0, x0)
    assert np.array_equal(o["contact.state"], state) and o["contact.impact_loss"] == 0.0


def test_jacobian_on_its_pattern_and_the_discrete_block_inert(model, x0):
    """``jac`` equals central differences on chain, shaft, sheave and loop columns and is zero off ``jac_sparsity``;
    the discrete block (contact state, impact loss) has zero rate and no column the right-hand side reads."""
    from tests.machines.chain_checks import assert_jacobian_on_pattern, perturbed

    x = perturbed(model, x0)
    assert_jacobian_on_pattern(model, x)
    d = model._discrete
    assert not model.jac_sparsity[d].nnz and not model.jac_sparsity[:, d].nnz
    x_flip = x.copy()
    x_flip[d] = np.arange(d.stop - d.start) % 3
    assert np.array_equal(np.delete(model.rhs(0.0, x_flip), np.arange(d.start, d.stop)),
                          np.delete(model.rhs(0.0, x), np.arange(d.start, d.stop)))
    assert not model.rhs(0.0, x_flip)[d].any()


def test_compliance_equals_the_digest_closed_form(model, x0):
    """``A = 2 G M^-1 G^T`` from the model's mass matrix and contact map equals (1.304) with the per-end masses of the
    mirrored pin (m_p/2, axially m_p/6), the sheave pair (m_z/2) and the shaft (J/2)."""
    x, pairs = _approaching(model, x0, 1)
    for end, shaft in pairs:
        _, _, G, MinvGt = model.impact_map(x, end, shaft)
        q = x[:model.n2]
        cols, coef = model._contact_map(np.array([end]), np.array([shaft]))
        X = (coef * np.concatenate([q, x[model.n2:2 * model.n2]])[cols]).sum(axis=2)
        arm, _ = end_geometry(model.contact, X, np.array([shaft]))
        A_closed = symmetric_compliance(model.family.m[end], model.m_sheave[shaft], model.J[shaft], arm)[0]
        np.testing.assert_allclose(2 * G @ MinvGt, A_closed, rtol=1e-12, atol=1e-12 * np.abs(A_closed).max())


def test_impulse_satisfies_c2_and_takes_the_closed_form_energy(model, x0):
    """On random approaching states: the normal relative velocity is zero after the impact, the impulse lies in the
    friction cone and opposes the slip, a stuck end has no relative velocity after it, the stick check holds (stuck
    exactly when the sticking impulse satisfies (1.301): in the cone, not along the slip), and the kinetic energy
    drops by ``P . (w- + w+)`` (the model's energy before minus after, to round-off)."""
    f = model.contact.f0
    x, pairs = _approaching(model, x0, 2, n=20)
    states = []
    for end, shaft in pairs:
        x1, [(P, state, dT, w0, w1)] = model.impact(x, [end], [shaft])
        _, normal, G, MinvGt = model.impact_map(x, end, shaft)
        A = 2 * G @ MinvGt
        Pn, Pt = P @ normal, P - (P @ normal) * normal
        assert w0 @ normal < 0 and abs(w1 @ normal) < 1e-12 * np.linalg.norm(w0)
        assert Pn > 0 and np.linalg.norm(Pt) <= f * Pn * (1 + 1e-12)
        wt = w0 - (w0 @ normal) * normal
        assert Pt @ wt <= 1e-15
        P_st = -np.linalg.solve(A, w0)
        Pst_n = P_st @ normal
        Pst_t = P_st - Pst_n * normal          # (1.301): |tau| <= 1 and tau . tau- >= 0 for tau = -Pt / (f Pn)
        assert (state == STUCK) == (np.linalg.norm(Pst_t) <= f * Pst_n and Pst_t @ wt <= 0)
        if state == STUCK:
            np.testing.assert_allclose(w1, 0.0, atol=1e-12 * np.linalg.norm(w0))
        else:
            assert state == SLIDING and np.allclose(Pt, -f * Pn * wt / np.linalg.norm(wt), rtol=1e-12)
        assert dT < 0 and dT == pytest.approx(P @ (w0 + w1), rel=1e-12)
        assert model.energy(x1) - model.energy(x) == pytest.approx(dT, rel=1e-9)
        state_after, loss = model.discrete_state(x1)
        assert state_after[2 * end + shaft] == state and loss == pytest.approx(-dT, rel=1e-14)
        assert model.split(x1)[3][2] - model.split(x)[3][2] == pytest.approx(-dT, rel=1e-12)
        states.append(state)
    assert STUCK in states and SLIDING in states


def test_frictionless_impact_takes_the_normal_velocity_energy(model, x0):
    """f = 0: the loss is ``(n . w-)^2 / (n . A n)``, the inelastic normal impulse's closed form."""
    from dataclasses import replace

    smooth = replace(model, contact=replace(model.contact, f0=0.0))
    x, pairs = _approaching(smooth, x0, 3, n=6)
    for end, shaft in pairs:
        w, normal, G, MinvGt = smooth.impact_map(x, end, shaft)
        A = 2 * G @ MinvGt
        _, [(P, state, dT, _, _)] = smooth.impact(x, [end], [shaft])
        assert state == SLIDING
        assert -dT == pytest.approx((normal @ w) ** 2 / (normal @ A @ normal), rel=1e-12)


def test_momentum_balance_of_pin_and_sheave_through_the_impulse(model, x0):
    """The impulse is internal between the pin and its shaft: the axial momentum ``m_p/3 u3' + m_z z'`` and the angular
    momentum about the shaft axis ``m_p k . (arm x u_perp') + J phi'`` are conserved; nothing else moves."""
    x, pairs = _approaching(model, x0, 4, n=8)
    n2, (nc, iphi, iz, dof) = model.n2, model._idx
    m = model.family.m
    for end, shaft in pairs:
        x1, [(P, *_)] = model.impact(x, [end], [shaft])
        assert np.linalg.norm(P) > 0
        v0, v1 = x[n2:2 * n2], x1[n2:2 * n2]
        changed = np.flatnonzero(v1 != v0)
        assert set(changed) <= set(dof[end]) | {iz[shaft], iphi[shaft]}
        c = model.contact.centres[shaft]

        def momenta(v):
            u, ud = x[dof[end, :2]] - c, v[dof[end, :2]]
            return (m[end] / 3 * v[dof[end, 2]] + model.m_sheave[shaft] * v[iz[shaft]],
                    m[end] * (u[0] * ud[1] - u[1] * ud[0]) + model.J[shaft] * v[iphi[shaft]])
        (a0, l0), (a1, l1) = momenta(v0), momenta(v1)
        assert a1 == pytest.approx(a0, abs=1e-12 * np.linalg.norm(P) * 10)
        assert l1 == pytest.approx(l0, rel=1e-13, abs=1e-12 * np.linalg.norm(P))


def test_impact_stick_example_of_the_digest():
    """Digest §3: a point (isotropic A = E/m) hitting a fixed plane at angle theta from the normal sticks below the
    self-locking angle arctan f and leaves with ``v (sin theta - f cos theta) i`` above it, never reversed."""
    f, v, m = 0.3, 3.0, 0.01
    theta = np.radians([0.0, 5.0, 16.0, 17.5, 30.0, 60.0])
    w = v * np.column_stack([np.sin(theta), 0 * theta, -np.cos(theta)])
    P, state = pin_end_impulses(w, np.tile(K, (len(w), 1)), np.tile(np.eye(3) / m, (len(w), 1, 1)), f)
    w1 = w + P / m
    below = theta < np.arctan(f)
    assert np.array_equal(state, np.where(below, STUCK, SLIDING))
    np.testing.assert_allclose(w1[below], 0.0, atol=1e-15)
    np.testing.assert_allclose(w1[~below, 0], v * (np.sin(theta) - f * np.cos(theta))[~below], rtol=1e-13)


@pytest.mark.parametrize("method", ["Radau", "RK45", "rock4", "trapezoidal", "dopri45", "rodas4"])
def test_event_located_on_a_closed_form_onset(method):
    """A pin end flying radially inwards at c onto a fixed conical sheave, pushed axially at a constant ``a``, meets it
    where ``Delta0 + (c tan g + u3') t + a t^2 / 2 = 0`` (``Delta`` is linear in ``r`` on a cone): the event fires
    there to 1e-9 s (the run's tolerance: 1e-8 relative on positions ~ 0.05 m) with every method named, the impulse
    leaves no normal approach (afterwards ``Delta = a (t - t*)^2 / 2``), and nothing fires again."""
    gamma = np.radians(10.0)
    face = Sheave("conical", gamma, w=0.0165)
    contact = SheaveContact(np.array([[0.2, 0.0], [0.0, 0.0]]), (face, face), np.array([1e10, 1e10]), 0.095, 0.1, 0.5)
    m_pin = 5e-3
    c, axial, a = 20.0, -0.4, 200.0            # radial approach (m/s), axial speed (m/s) and acceleration (m/s^2)
    z = np.array([0.0, 0.0])
    y0 = np.array([0.08, 0.0, 0.0, -c, 0.0, axial])
    y0[2] = -2e-3 - contact._profiles[1](np.array([0.08]))[0][0]     # 2 mm off the face

    def gap(t, y):
        return gap_indicators(contact, y[None, :2], y[2:3], z)[0]

    delta0 = gap(0.0, y0)[1]
    rate = c * np.tan(gamma) + axial
    t_star = 2 * -delta0 / (rate + np.sqrt(rate ** 2 - 2 * a * delta0))   # root of delta0 + rate t + a t^2 / 2
    assert 0 < t_star < 1e-3

    def switch(t, y, fired):
        X = np.concatenate([y[:3], [0.0], y[3:], [0.0, 0.0]])[None]
        arm, normal = end_geometry(contact, X, np.array([1]))
        w = relative_velocity_map(arm)[0] @ X[0, 4:]
        A = symmetric_compliance(m_pin, np.inf, np.inf, arm)
        P, _ = pin_end_impulses(w[None], normal, A, contact.f0)
        y = y.copy()
        y[3:] += 2 * (P[0] + 2 * K * P[0, 2]) / m_pin
        return y

    res = solve(lambda t, y: np.concatenate([y[3:], [0.0, 0.0, a]]), (0.0, 2 * t_star), y0, method=method, rtol=1e-8,
                atol=1e-12, n2=3, events=(gap, np.zeros(2, int), np.zeros(2, bool)), switch=switch)
    assert res.status == 0
    assert len(res.t_events[0]) == 0 and len(res.t_events[1]) == 1
    assert res.t_events[1][0] == pytest.approx(t_star, abs=1e-9)
    # no normal approach left: on the cone (a generator is straight) the end sinks in as a (t - t*)^2 / 2 only
    assert gap(0.0, res.y[:, -1])[1] == pytest.approx(0.5 * a * t_star ** 2, rel=1e-4)


def test_run_events_switch_flags_and_close_the_energy_balance(model, x0):
    """0.2 ms from the quasi-static start (Radau, rtol 1e-6): pins enter the arcs and hit (events with losses), the
    discrete state agrees with the penetrations at the end, and ``E(t) - E(0)`` = input - output + clamping -
    (damping + friction + impact losses) to 1e-8 of the input work."""
    res = solve(model, (0.0, 2e-4), x0, method="Radau", rtol=1e-6, atol=1e-9, n2=model.n2, jac=model.jac,
                jac_sparsity=model.jac_sparsity)
    assert res.status == 0
    x1 = res.y[:, -1]
    n_events = sum(len(t) for t in res.t_events)
    state, loss = model.discrete_state(x1)
    assert n_events >= 1 and loss > 0
    assert np.array_equal(state > 0, model.events(2e-4, x1) > 0)
    W = model.split(x1)[3]
    assert W[0] > 10.0 and W[2] > loss
    assert model.energy(x1) - model.energy(x0) == pytest.approx(W[0] - W[1] + W[3] - W[2], abs=1e-8 * W[0])


def test_cvtfem_run_of_an_impact_scene_closes_the_energy_balance(cli, tmp_path):
    """0.3 ms of the chain-S2 preset with ``effects.contact = "impact"`` through `cvtfem run` (rock4, rtol 1e-4): the
    results carry the discrete state and the impact loss, and the work integrals close the energy balance (input =
    output + damping + friction + impact losses + change of energy - clamping work) to 1e-6 of the input work.  The
    loss has zero rate between events, but rock4's stage recurrence (``(1 + mu) x1 - mu x0 + ...``) carries a constant
    component only to round-off, whose sign depends on the BLAS kernel (-1.1e-19 J on 7.3e-4 J at the last sample
    with OPENBLAS_CORETYPE=Sandybridge): it never falls by more than round-off."""
    import h5py

    scene_file, h5 = tmp_path / "impact.toml", tmp_path / "impact.h5"
    scene_file.write_text('preset = "chain-S2"\n[cvt.effects]\ncontact = "impact"\n[solver]\nrtol = 1e-4\n'
                          'atol = 1e-7\n')
    r = cli("run", str(scene_file), "--until", "3e-4", "--results", str(h5), timeout=600)
    assert r.returncode == 0, r.stderr
    with h5py.File(h5) as f:
        s = f["series"]
        W, E, loss, state = s["work"][-1], s["energy"][:], s["contact.impact_loss"][:], s["contact.state"][:]
    assert loss[-1] > 0 and np.all(np.diff(loss.ravel()) >= -1e-12 * loss.max())
    assert set(np.unique(state)) <= {FREE, SLIDING, STUCK}
    assert W[0] > 10.0 and abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-6 * W[0]
