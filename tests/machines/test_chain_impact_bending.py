"""Impact at contact onset on the bending-pin chains (contact-models digest §3, C2): S3 (mirrored, 5 coordinates per
pin) and A1 (whole pin, 10 coordinates, each end on its own sheave).  The impulse acts in the generalized coordinates
(``M dv = e G^T P``, ``n . G v+ = 0``), so the pin end's inertia comes from the model's mass matrix: checked against
closed forms from the digests' mass matrices (S3 §3.4, A1's raw Hermite mass §4.4), with the C2 conditions, the
kinetic energy and momentum balances through the jump, S3 against S2 where the two coincide, and short runs."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.chain.pin_impact import end_compliance, end_geometry, friction_coefficient
from cvtfem.elements.contact.impact import FREE, SLIDING, STUCK
from cvtfem.errors import InputError
from cvtfem.machines.chain_impact_cvt import ImpactChainACVT, ImpactChainCVT
from cvtfem.machines.cvt import chain_loop, layout
from cvtfem.scene.loader import load_scene

K = np.array([0.0, 0.0, 1.0])
S3_IMPACT = {"cvt": {"model": "chain-S3", "effects": {"contact": "impact", "pin_bending": True}}}
A1_IMPACT = {"cvt": {"effects": {"contact": "impact"}}}


@pytest.fixture(scope="module")
def s3():
    model = chain_loop(load_scene("chain-S2").replace(S3_IMPACT))
    return model, model.initial_state()


@pytest.fixture(scope="module")
def a1():
    model = chain_loop(load_scene("chain-A1").replace(A1_IMPACT))
    return model, model.initial_state()


def _hermite_inverse_masses(m_p, l):
    """Inverse raw mass blocks of a pin (digest chain-models-1 §4.4): in-plane over ``(u_far, u_near, u'_far,
    u'_near)`` of one component, axial over ``(u_31, u_32)``; their end rows are the ends' inverse masses."""
    Mr = m_p / 420 * np.array([[156, 54, 22 * l, -13 * l], [54, 156, 13 * l, -22 * l],
                               [22 * l, 13 * l, 4 * l ** 2, -3 * l ** 2], [-13 * l, -22 * l, -3 * l ** 2, 4 * l ** 2]])
    return np.linalg.inv(Mr)[:2, :2], np.linalg.inv(m_p / 6 * np.array([[2.0, 1.0], [1.0, 2.0]]))


def _inputs(model, x, end, shaft):
    """Local position/rate inputs ``X`` (1, 9) of ``(end, shaft)`` through the model's contact map."""
    cols, coef = model._contact_map(np.array([end]), np.array([shaft]))
    return (coef * np.concatenate([x[:2 * model.n2], model._constants])[cols]).sum(axis=2)


def _approaching(model, x, seed, n=12, speed=0.3):
    """``x`` with random chain/shaft/sheave velocities and ``n`` (end, shaft) pairs near their sheave given a relative
    velocity into the face (the least-norm change of that pin's velocities that sets ``w``; one end per pin): every
    other one straight in with its slip kept, the others ``w = -A P`` for a sticking impulse ``P`` inside the friction
    cone."""
    rng = np.random.default_rng(seed)
    x = x.copy()
    n2, nc = model.n2, model.family.size
    x[n2:n2 + nc] += rng.normal(0.0, speed, nc)
    x[n2 + nc:2 * n2] += rng.normal(0.0, 0.05, 4)
    e = model.events(0.0, x).reshape(-1, 2)
    near = np.argwhere(e > -5e-4)
    near = near[rng.permutation(len(near))]
    pairs = near[np.unique(model.pin_of(near[:, 0]), return_index=True)[1]][:n]     # one end per pin
    assert len(pairs) == n
    f, ends = friction_coefficient(model.contact), model.ends_per_contact
    for i, (end, shaft) in enumerate(pairs):
        w, normal, G, MinvGt = model.impact_map(x, end, shaft)
        if i % 2:
            target = w + (-np.sum(normal * w) - rng.uniform(0.05, 2.0)) * normal
        else:
            t = np.cross(normal, rng.normal(size=3))
            P = rng.uniform(1e-5, 1e-3) * (normal + 0.9 * f * rng.uniform() * t / np.linalg.norm(t))
            target = -ends * G @ MinvGt @ P
        d = model.family.dof_index[model.pin_of(end)]                   # the pin's velocities only
        x[n2 + d] += G[:, d].T @ np.linalg.solve(G[:, d] @ G[:, d].T, target - w)
    return x, pairs


def _mass(model):
    """The model's mass matrix (chain, shaft spins, sheave coordinates) as a dense array."""
    return np.block([[model.family.mass_matrix().toarray(), np.zeros((model.family.size, 4))],
                     [np.zeros((4, model.family.size)), np.diag(np.concatenate([model.J, model.m_sheave]))]])


def _rigid_modes(model, x, end, shaft):
    """``(turn, axial)`` (n2,): the generalized velocities at ``x`` of a rigid turn of the pin and the shaft about the
    shaft axis (1 rad/s: ``k x (u - c)`` for the pin position, ``k x u`` for its in-plane vectors) and of a rigid axial
    translation of the pin with the sheave it hits (1 m/s; None for a fixed sheave).  ``r^T M v`` is the angular /
    axial momentum of that pin and shaft."""
    n2, (_, iphi, iz, _) = model.n2, model._idx
    d = model.family.dof_index[model.pin_of(end)]
    turn, axial = np.zeros(n2), np.zeros(n2)
    turn[iphi[shaft]] = 1.0
    if isinstance(model, ImpactChainACVT):       # u0; the vectors u1, u2, u3; w0 (mean axial position)
        pos, vectors, ax = d[:2], [d[2:4], d[4:6], d[6:8]], d[8]
        side = model.movable_side[shaft]
        movable = side == (1 if end % 2 else -1)
    else:                                        # u_perp; u' (S3); u3 with z outwards (the mirrored half)
        pos, vectors, ax = d[:2], [d[3:5]] if d.size == 5 else [], d[2]
        side, movable = 1.0, True
    u = x[pos] - model.contact.centres[shaft]
    turn[pos] = [-u[1], u[0]]
    for vec in vectors:
        turn[vec] = [-x[vec[1]], x[vec[0]]]
    axial[ax], axial[iz[shaft]] = 1.0, float(side)
    return turn, (axial if movable else None)


def _with_friction(model, f):
    """``model`` with the friction coefficient ``f`` in its contact kernel."""
    c = model.contact
    if hasattr(c, "pair"):
        return replace(model, contact=replace(c, pair=replace(c.pair, f0=f)))
    return replace(model, contact=replace(c, f0=f))


def test_routing_layout_and_the_start(s3, a1):
    """S3 and A1 with ``contact = "impact"`` build the impact models with one discrete state per pin end and shaft
    (A1: two ends per pin); the start's discrete state is the sign of the penetrations; A2 and A5 are refused by
    name."""
    for (model, x0), cls, ends in ((s3, ImpactChainCVT, 84), (a1, ImpactChainACVT, 168)):
        assert type(model) is cls and model.n_ends == ends and model.n_discrete == 2 * ends
        assert model.size == 2 * model.n2 + model.control.size + 2 * ends + 1 + 4
        state, loss = model.discrete_state(x0)
        assert loss == 0.0 and np.array_equal(state, np.where(model.events(0.0, x0) > 0, SLIDING, FREE))
        assert 30 < (state > 0).sum() < ends
    state = a1[0].discrete_state(a1[1])[0].reshape(-1, 2, 2)      # (pin, far/near, shaft)
    assert np.array_equal(state[:, 0] > 0, state[:, 1] > 0)       # both ends of a pin on the arc
    assert "pin 3 near end, contact state with the driven sheave" == a1[0].state_label(a1[0]._discrete.start + 15)
    scene = load_scene("chain-A1").replace(A1_IMPACT)
    assert layout(scene)[0].discrete == 336
    for model in ("chain-A2", "chain-A5"):
        with pytest.raises(InputError, match=r"cvt\.effects\.contact.*chain-S2, chain-S3, chain-A1"):
            chain_loop(load_scene("chain-A1").replace({"cvt": {"model": model, "effects": {"contact": "impact"}}}))


def test_discrete_block_is_inert(a1):
    """The discrete block has zero rate and the right-hand side reads none of it (A1)."""
    model, x0 = a1
    d = model._discrete
    flip = x0.copy()
    flip[d] = np.arange(d.stop - d.start) % 3
    f0, f1 = model.rhs(0.0, x0), model.rhs(0.0, flip)
    assert not f1[d].any() and np.array_equal(np.delete(f0, np.arange(d.start, d.stop)),
                                              np.delete(f1, np.arange(d.start, d.stop)))
    assert not model.jac_sparsity[d].nnz and not model.jac_sparsity[:, d].nnz


def test_compliance_equals_the_closed_forms_of_the_pin_masses(s3, a1):
    """``A = e G M^-1 G^T`` from the model equals ``diag(a, a, b) + k k / m_z + (k x arm)(k x arm) / J`` with the pin
    ends' inverse masses of the digests' mass matrices: S3 (§3.4: ``[[6, 15/l], [15/l, 45/l^2]] / m_p``, both ends)
    ``a = 12 / m_p``, ``b = 6 / m_p``, and the per-end ``m_z / 2``, ``J / 2``; A1 the end rows of the raw Hermite mass
    (§4.4) ``a = 16 / m_p``, ``b = 4 / m_p``, the whole ``J`` and the movable sheave's ``m_z`` (a fixed sheave: none).
    A1's impulse at one end moves the other end by the off-diagonal terms (``-4 / m_p``, ``-2 / m_p``)."""
    for model, x0 in (s3, a1):
        x, pairs = _approaching(model, x0, 1)
        for end, shaft in pairs:
            w, normal, G, MinvGt = model.impact_map(x, end, shaft)
            arm, _ = end_geometry(model.contact, _inputs(model, x, end, shaft), np.array([shaft]))
            pin = model.pin_of(end)
            m_p = model.family.geom.m_eff[pin]
            if isinstance(model, ImpactChainACVT):
                inplane, axial = _hermite_inverse_masses(m_p, model.family.geom.l)
                movable = model.movable_side[shaft] == (1 if end % 2 else -1)
                A_closed = end_compliance(inplane[0, 0], axial[0, 0], model.m_sheave[shaft] if movable else np.inf,
                                          model.J[shaft], arm)[0]
            else:
                A_closed = end_compliance(12 / m_p, 6 / m_p, model.m_sheave[shaft] / 2, model.J[shaft] / 2, arm)[0]
            A = model.ends_per_contact * G @ MinvGt
            np.testing.assert_allclose(A, A_closed, rtol=1e-10, atol=1e-10 * np.abs(A_closed).max())
    # A1: the impulse on one end moves both ends by the columns of the raw inverse mass (the ends are coupled)
    model, x0 = a1
    nc = model.family.size
    x, pairs = _approaching(model, x0, 5, n=6)
    for end, shaft in pairs:
        pin, hit, side = model.pin_of(end), end % 2, (1 if end % 2 else -1)
        P = np.array([0.3, -0.2, 1.0]) * 1e-3                              # mirrored frame of the end
        far, near = model.family.chain.to_raw((model.impact_map(x, end, shaft)[3] @ P)[:nc])[:2]
        jumps = np.stack([far[pin], near[pin]])                           # (far, near) x (x1, x2, x3) global
        inplane, axial = _hermite_inverse_masses(model.family.geom.m_eff[pin], model.family.geom.l)
        np.testing.assert_allclose(jumps[:, :2], np.outer(inplane[:, hit], P[:2]), rtol=1e-10,
                                   atol=1e-12 * np.abs(jumps).max())
        np.testing.assert_allclose(jumps[:, 2], axial[:, hit] * side * P[2], rtol=1e-10)


def test_both_ends_of_an_a1_pin_hit_together_settle_to_the_joint_inelastic_impact(a1):
    """Both ends of an A1 pin fire on one shaft at once (frictionless): the mass matrix couples them, so single impacts
    in turn throw the first end off its face again (at 57 % of its approach speed here); the switch solves them
    together, and the velocities after equal the joint inelastic impact ``v+ = v- + M^-1 [G_1^T n_1, G_2^T n_2] P_n``
    with ``K P_n = -(n . w-)``, ``K_ij = n_i . G_i M^-1 G_j^T n_j`` (both ``P_n > 0``) to 1e-8; the loss is ``P_n . K
    P_n / 2``, the model's energy drop. With friction: neither end approaches after, the impulses lie in their cones,
    the energy drops by the loss."""
    model, x0 = a1
    smooth = _with_friction(model, 0.0)
    n2 = smooth.n2
    e = smooth.events(0.0, x0).reshape(-1, 2, 2)                          # (pin, far/near, shaft)
    pin, shaft = [(p, k) for p, k in np.argwhere((e > -5e-4).all(axis=1)) if p % 3 == 1][0]
    ends = np.array([2 * pin, 2 * pin + 1])
    x = x0.copy()
    d = smooth.family.dof_index[pin]
    maps = [smooth.impact_map(x, end, shaft) for end in ends]
    G = np.vstack([m[2][:, d] for m in maps])
    target = np.concatenate([m[0] - (m[1] @ m[0] + speed) * m[1] for m, speed in zip(maps, (0.4, 0.7))])
    x[n2 + d] += G.T @ np.linalg.solve(G @ G.T, target - np.concatenate([m[0] for m in maps]))
    maps = [smooth.impact_map(x, end, shaft) for end in ends]
    N = [m[2].T @ m[1] for m in maps]                                      # G_i^T n_i (n2,)
    MinvN = [m[3] @ m[1] for m in maps]                                    # M^-1 G_i^T n_i
    K = np.array([[N[i] @ MinvN[j] for j in range(2)] for i in range(2)])
    vn = np.array([m[1] @ m[0] for m in maps])
    assert np.all(vn < 0)
    Pn = np.linalg.solve(K, -vn)
    assert np.all(Pn > 0)
    v_joint = x[n2:2 * n2] + MinvN[0] * Pn[0] + MinvN[1] * Pn[1]
    fired = np.zeros(smooth.n_discrete, bool)
    fired[2 * ends + shaft] = True
    x1 = smooth.switch(0.0, x, fired)
    np.testing.assert_allclose(x1[n2:2 * n2], v_joint, rtol=0, atol=1e-8 * np.abs(v_joint - x[n2:2 * n2]).max())
    loss = smooth.discrete_state(x1)[1]
    assert loss == pytest.approx(0.5 * Pn @ K @ Pn, rel=1e-7)
    assert smooth.energy(x) - smooth.energy(x1) == pytest.approx(loss, rel=1e-7)
    one_pass = smooth.impact(x, ends, [shaft, shaft])[0]                   # single impacts in turn: the second
    w, normal = smooth.impact_map(one_pass, ends[0], shaft)[:2]            # throws the first off its face
    assert normal @ w > 0.25 * abs(vn[0])
    # with friction (f = 0.1): neither end approaches after, each impulse in its cone, the loss the energy drop
    x2, P, _, dT = model.joint_impacts(0.0, x, ends, [shaft, shaft])
    f = friction_coefficient(model.contact)
    for end, P_end in zip(ends, P):
        w, normal = model.impact_map(x2, end, shaft)[:2]
        assert normal @ w > -1e-8 * abs(vn).max()
        Pn = P_end @ normal
        assert Pn > 0 and np.linalg.norm(P_end - Pn * normal) <= f * Pn * (1 + 1e-9)
    assert dT < 0 and model.energy(x2) - model.energy(x) == pytest.approx(dT, rel=1e-7)


def test_impulse_satisfies_c2_and_takes_the_closed_form_energy(s3, a1):
    """On random approaching ends of S3 and A1: no normal relative velocity after the impact, the impulse in the
    friction cone opposing the slip, the stick check (stuck exactly when the stick impulse satisfies (1.301)), no
    relative velocity after a stuck impact, the kinetic energy change ``(e / 2) P . (w- + w+) <= 0`` equal to the
    model's energy difference, and the loss in the state and in the dissipated work."""
    for model, x0 in (s3, a1):
        f, e = friction_coefficient(model.contact), model.ends_per_contact
        x, pairs = _approaching(model, x0, 2, n=20)
        states = []
        for end, shaft in pairs:
            x1, [(P, state, dT, w0, w1)] = model.impact(x, [end], [shaft])
            _, normal, G, MinvGt = model.impact_map(x, end, shaft)
            A = e * G @ MinvGt
            Pn, Pt = P @ normal, P - (P @ normal) * normal
            assert w0 @ normal < 0 and abs(w1 @ normal) < 1e-12 * np.linalg.norm(w0)
            np.testing.assert_allclose(G @ x1[model.n2:2 * model.n2], w1, rtol=0, atol=1e-14 * np.linalg.norm(w0))
            assert Pn > 0 and np.linalg.norm(Pt) <= f * Pn * (1 + 1e-12)
            wt = w0 - (w0 @ normal) * normal
            assert Pt @ wt <= 1e-15
            P_st = -np.linalg.solve(A, w0)
            Pst_n = P_st @ normal
            Pst_t = P_st - Pst_n * normal
            assert (state == STUCK) == (np.linalg.norm(Pst_t) <= f * Pst_n and Pst_t @ wt <= 0)
            if state == STUCK:
                np.testing.assert_allclose(w1, 0.0, atol=1e-12 * np.linalg.norm(w0))
            else:
                assert state == SLIDING and np.allclose(Pt, -f * Pn * wt / np.linalg.norm(wt), rtol=1e-12)
            assert dT < 0 and dT == pytest.approx(e / 2 * P @ (w0 + w1), rel=1e-12)
            assert model.energy(x1) - model.energy(x) == pytest.approx(dT, rel=1e-9)
            state_after, loss = model.discrete_state(x1)
            assert state_after[2 * end + shaft] == state and loss == pytest.approx(-dT, rel=1e-14)
            assert model.split(x1)[3][2] - model.split(x)[3][2] == pytest.approx(-dT, rel=1e-12)
            states.append(state)
        assert STUCK in states and SLIDING in states


def test_frictionless_loss_is_the_inelastic_normal_closed_form(s3, a1):
    """f = 0: the kinetic energy lost is ``(e / 2) (n . w-)^2 / (n . A n)``."""
    for model, x0 in (s3, a1):
        smooth = _with_friction(model, 0.0)
        x, pairs = _approaching(smooth, x0, 3, n=6)
        e = smooth.ends_per_contact
        for end, shaft in pairs:
            w, normal, G, MinvGt = smooth.impact_map(x, end, shaft)
            _, [(P, state, dT, _, _)] = smooth.impact(x, [end], [shaft])
            assert state == SLIDING
            assert -dT == pytest.approx(e / 2 * (normal @ w) ** 2 / (normal @ (e * G @ MinvGt) @ normal), rel=1e-12)


def test_momentum_of_pin_and_shaft_is_conserved_through_the_impulse(s3, a1):
    """The impulse is internal between the pin and its shaft: the angular momentum about the shaft axis of the pin and
    the shaft (sheave inertia included) and, against a movable sheave, the axial momentum of the pin and that sheave are
    conserved (``r^T M v`` over the rigid modes ``r``: the pin's jump cancels the shaft's, or the sheave's, to 1e-9 of
    it or of the impulse's moment, the round-off of the shaft's spin momentum); nothing but that pin, shaft and sheave
    moves. Against A1's fixed sheave the axial momentum changes by the impulse's axial part (the ground takes it)."""
    for model, x0 in (s3, a1):
        M = _mass(model)
        n2, (_, iphi, iz, _) = model.n2, model._idx
        x, pairs = _approaching(model, x0, 4, n=16)
        fixed = 0
        for end, shaft in pairs:
            x1, [(P, *_)] = model.impact(x, [end], [shaft])
            v0, v1 = x[n2:2 * n2], x1[n2:2 * n2]
            assert set(np.flatnonzero(v1 != v0)) <= set(model.family.dof_index[model.pin_of(end)]) | {iz[shaft],
                                                                                                   iphi[shaft]}
            turn, axial = _rigid_modes(model, x, end, shaft)
            dp = M @ (v1 - v0)                   # momentum jumps (1e-16 of the shaft's spin momentum in round-off)
            arm = np.linalg.norm(_inputs(model, x, end, shaft)[0, :2] - model.contact.centres[shaft])
            assert abs(turn @ dp) <= 1e-9 * max(abs(dp[iphi[shaft]]), arm * np.linalg.norm(P))
            if axial is not None:
                assert abs(dp[iz[shaft]]) > 0.5 * np.linalg.norm(P) and abs(axial @ dp) <= 1e-9 * abs(dp[iz[shaft]])
            else:                                # A1's fixed sheave: the pin's axial momentum changes by the impulse
                fixed += 1
                mean_axial = np.zeros(n2)
                mean_axial[model.family.dof_index[model.pin_of(end), 8]] = 1.0
                side = 1 if end % 2 else -1
                assert mean_axial @ M @ (v1 - v0) == pytest.approx(side * P[2], rel=1e-10)
        assert fixed > 0 if isinstance(model, ImpactChainACVT) else fixed == 0


def test_s3_agrees_with_s2_where_they_coincide(s3):
    """On a flat face (normal along the axis) the sliding C2 impulse ``P_n (n - f tau-)`` has
    ``P_n = -n . w / (n . A n)`` in both S2 and S3 (their pin ends share the axial inertia ``m_p / 6`` per end; only the
    in-plane one differs, ``m_p / 2`` against ``m_p / 12``, and on a flat face it does not enter): from the same state
    (S3's bending coordinates at rest) both give the same impulse, the same sheave and shaft jumps, the same axial pin
    jump and the same change of the pin's in-plane momentum; the in-plane end velocity after differs by the masses."""
    model3, x3 = s3
    s2 = chain_loop(load_scene("chain-S2").replace({"cvt": {"effects": {"contact": "impact"}}}))
    flat = Sheave("conical", 0.0, w=model3.contact.faces[0].w)
    m3 = replace(model3, contact=replace(model3.contact, faces=(flat, flat)))
    m2 = replace(s2, contact=replace(s2.contact, faces=(flat, flat)))
    fam3, fam2 = m3.family, m2.family
    n, n2, nc = fam3.n, m3.n2, fam3.size
    M3, M2 = _mass(m3), _mass(m2)
    rng = np.random.default_rng(7)
    for _ in range(6):
        x = x3.copy()
        x[fam3.dof_index[:, 3:5]] = x[n2 + fam3.dof_index[:, 3:5]] = 0.0     # S3's bending at rest
        pin, shaft = int(rng.integers(n)), int(rng.integers(2))
        v_in = rng.uniform(0.2, 1.0)                                          # axial approach, slip >= 0.5 of it
        slip = rng.normal(size=2)
        x[n2 + fam3.dof_index[pin, :2]] = rng.uniform(0.5, 2.0) * v_in * slip / np.linalg.norm(slip)
        x[n2 + fam3.dof_index[pin, 2]] = v_in                                # outwards, onto the sheave
        x[n2 + nc:2 * n2] = rng.normal(0.0, 0.05, 4)
        # S2's coordinates are S3's first three per pin (u_perp pin-major, then u3): the same state
        y = np.concatenate([x[:3 * n], x[nc:n2 + 3 * n], x[n2 + nc:]])
        assert y.size == m2.size
        w3, normal = m3.impact_map(x, pin, shaft)[:2]
        np.testing.assert_allclose(m2.impact_map(y, pin, shaft)[0], w3, rtol=1e-12)
        np.testing.assert_allclose(normal, [0.0, 0.0, -1.0], atol=1e-15)
        x1, [(P3, st3, _, _, _)] = m3.impact(x, [pin], [shaft])
        y1, [(P2, st2, _, _, _)] = m2.impact(y, [pin], [shaft])
        assert st2 == st3 == SLIDING
        np.testing.assert_allclose(P3, P2, rtol=1e-12)
        dx, dy = (x1 - x)[n2:2 * n2], (y1 - y)[m2.n2:2 * m2.n2]
        np.testing.assert_allclose(dx[nc:], dy[fam2.size:], rtol=1e-12, atol=1e-15)       # shafts, sheaves
        assert dx[fam3.dof_index[pin, 2]] == pytest.approx(dy[fam2.dof_index[pin, 2]], rel=1e-12)
        dp3, dp2 = (M3 @ dx)[fam3.dof_index[pin, :2]], (M2 @ dy)[fam2.dof_index[pin, :2]]
        np.testing.assert_allclose(dp3, dp2, rtol=1e-12)
        np.testing.assert_allclose(dp3, 2 * P3[:2], rtol=1e-12)
        m_p = fam3.geom.m_eff[pin]                          # in-plane end jumps: 12 P / m_p, 2 P / m_p
        np.testing.assert_allclose(dx[fam3.dof_index[pin, :2]], 12 * P3[:2] / m_p, rtol=1e-10)
        np.testing.assert_allclose(dy[fam2.dof_index[pin, :2]], 2 * P2[:2] / m_p, rtol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("scene_text, until", [
    ('preset = "chain-S2"\n[cvt]\nmodel = "chain-S3"\n[cvt.effects]\ncontact = "impact"\npin_bending = true\n', 4e-4),
    ('preset = "chain-A1"\n[cvt.effects]\ncontact = "impact"\n', 2e-4),
], ids=["S3", "A1"])
def test_cvtfem_run_closes_the_energy_balance_with_the_impact_losses(cli, tmp_path, scene_text, until):
    """`cvtfem run` of S3 (rock4) and A1 (Radau) with impacts from the quasi-static start, rtol 1e-4: pins entering the
    arcs hit their sheaves (a loss that only grows), the discrete state agrees with the penetrations (an end in contact
    is not off the face by more than the hysteresis, a free end does not penetrate), and the work integrals close the
    energy balance (input = output + damping + friction + impact losses + change of energy - clamping work) to 1e-6 of
    the input work."""
    import h5py

    from cvtfem.machines.chain_impact_cvt import HYSTERESIS

    scene_file, h5 = tmp_path / "impact.toml", tmp_path / "impact.h5"
    scene_file.write_text(scene_text + "[solver]\nrtol = 1e-4\natol = 1e-7\n")
    r = cli("run", str(scene_file), "--until", str(until), "--results", str(h5), timeout=600)
    assert r.returncode == 0, r.stderr
    with h5py.File(h5) as f:
        s = f["series"]
        W, E, loss = s["work"][-1], s["energy"][:], s["contact.impact_loss"][:].ravel()
        state, pen = s["contact.state"][-1], s["contact.penetration"][-1]
    # zero rate between events, carried by rock4's stage recurrence to round-off only (test_chain_impact.py)
    assert loss[-1] > 0 and np.all(np.diff(loss) >= -1e-12 * loss.max()) and W[2] > loss[-1]
    assert set(np.unique(state)) <= {FREE, SLIDING, STUCK}
    assert np.all(pen[state != FREE] > -HYSTERESIS) and np.all(pen[state == FREE] <= 0)
    assert W[0] > 10.0 and abs(W[0] - W[1] - W[2] + W[3] - (E[-1] - E[0])) < 1e-6 * W[0]
