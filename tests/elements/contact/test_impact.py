"""Impact at contact onset (contact-models digest §3, §10.4 item 5)."""
from __future__ import annotations

import numpy as np
import pytest

from cvtfem.elements.contact.impact import (FREE, SLIDING, STUCK, impact_compliance, impact_impulse,
                                            impact_jumps)

K = np.array([0.0, 0.0, 1.0])


def _plane_hit(theta, f, v=3.0, m=0.01):
    """Point of mass m hitting the fixed plane z = 0 with v- = v(-k cos theta + i sin theta)."""
    th = np.atleast_1d(theta)
    v_minus = v * np.stack([np.sin(th), 0 * th, -np.cos(th)], -1)
    A = np.broadcast_to(np.eye(3) / m, th.shape + (3, 3))
    P, state = impact_impulse(v_minus, np.broadcast_to(K, v_minus.shape), A, f)
    return v_minus, v_minus + P / m, P, state


def test_worked_example_stick_below_the_self_locking_angle_slide_above():
    """Digest §3: slide-only would give v+ = v (sin theta - f cos theta) i, reversed for
    theta < arctan f; the algorithm sticks there (v+ = 0) and slides above with that v+."""
    f, v = 0.3, 3.0
    lock = np.arctan(f)
    theta = np.array([0.0, 0.5 * lock, 0.99 * lock, 1.01 * lock, 0.5, 1.2])
    v_minus, v_plus, P, state = _plane_hit(theta, f, v)
    below = theta < lock
    assert np.array_equal(state, np.where(below, STUCK, SLIDING))
    assert np.allclose(v_plus[below], 0.0, atol=1e-15 * v)
    expected = v * (np.sin(theta) - f * np.cos(theta))
    assert np.allclose(v_plus[~below, 0], expected[~below], rtol=1e-14)
    assert np.allclose(v_plus[~below, 1:], 0.0, atol=1e-15 * v)
    assert np.all(v_plus[:, 0] >= 0.0)   # never reversed


def test_separating_contact_gets_no_impulse():
    v_minus = np.array([[1.0, 0.0, 0.5], [0.3, 0.2, 0.0]])
    P, state = impact_impulse(v_minus, np.broadcast_to(K, (2, 3)), np.broadcast_to(np.eye(3), (2, 3, 3)), 0.1)
    assert np.array_equal(P, np.zeros((2, 3)))
    assert np.array_equal(state, [FREE, FREE])


def _random_impacts(n, seed):
    """Pin ends touching a cone sheave (gamma = 10 deg) of a constrained sheave, random velocities."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0, 2 * np.pi, n)
    r = rng.uniform(0.036, 0.088, n)
    e_r = np.stack([np.cos(phi), np.sin(phi), 0 * phi], -1)
    rho = r[:, None] * e_r
    gamma = np.radians(10.0)
    normal = np.cos(gamma) * K + np.sin(gamma) * e_r
    m_p, m, J = rng.uniform(2e-3, 8e-3, n), rng.uniform(1.0, 3.0, n), rng.uniform(2e-3, 1e-2, n)
    v_pin = rng.normal(size=(n, 3)) * 10.0
    zd, phid = rng.normal(size=n) * 0.1, rng.normal(size=n) * 300.0
    v_s = K * zd[:, None] + np.cross(K, rho) * phid[:, None]
    v_r = v_pin - v_s
    v_r -= np.maximum(np.sum(v_r * normal, axis=1), 0.0)[:, None] * normal * 1.5   # approaching
    v_pin = v_s + v_r
    f = rng.uniform(0.05, 0.4, n)
    return dict(rho=rho, normal=normal, m_p=m_p, m=m, J=J, v_pin=v_pin, zd=zd, phid=phid, v_r=v_r, f=f)


def test_random_impacts_conserve_axial_momenta_lose_energy_and_stop_the_normal_approach():
    """k-momentum and angular momentum about the shaft are conserved, v_r+ . n = 0, kinetic energy
    never grows, and (1.301) holds for the realised tangential impulse (|P_t| <= f P_n, P_t . v_r,t- <= 0)."""
    n = 2000
    d = _random_impacts(n, 11)
    A = impact_compliance(d["m_p"], d["m"], d["J"], d["rho"])
    P, state = impact_impulse(d["v_r"], d["normal"], A, d["f"])
    assert set(np.unique(state)) == {SLIDING, STUCK}
    dv, dzd, dphid = impact_jumps(P, d["m_p"], d["m"], d["J"], d["rho"])
    v1, zd1, phid1 = d["v_pin"] + dv, d["zd"] + dzd, d["phid"] + dphid
    Mp = d["m_p"][:, None, None] * (np.eye(3) - 2 / 3 * np.outer(K, K))
    mom = lambda v, zd: np.einsum("nij,nj->ni", Mp, v)[:, 2] + d["m"] * zd              # noqa: E731
    ang = lambda v, phid: np.cross(d["rho"], np.einsum("nij,nj->ni", Mp, v))[:, 2] + d["J"] * phid  # noqa: E731
    energy = lambda v, zd, phid: 0.5 * (np.einsum("ni,nij,nj->n", v, Mp, v) + d["m"] * zd ** 2  # noqa: E731
                                        + d["J"] * phid ** 2)
    scale_p = d["m_p"] * 10.0 + d["m"] * 0.1
    assert np.allclose(mom(v1, zd1), mom(d["v_pin"], d["zd"]), rtol=0, atol=1e-13 * scale_p)
    scale_l = d["J"] * 300.0 + 0.088 * d["m_p"] * 10
    assert np.allclose(ang(v1, phid1), ang(d["v_pin"], d["phid"]), rtol=0, atol=1e-13 * scale_l)
    # relative velocity after the jumps agrees with A P
    v_s1 = K * zd1[:, None] + np.cross(K, d["rho"]) * phid1[:, None]
    v_r1 = v1 - v_s1
    assert np.allclose(v_r1, d["v_r"] + np.einsum("nij,nj->ni", A, P), rtol=0, atol=1e-12 * 30)
    assert np.allclose(np.sum(v_r1 * d["normal"], axis=1), 0.0, atol=1e-12 * 30)
    assert np.allclose(v_r1[state == STUCK], 0.0, atol=1e-12 * 30)
    T0, T1 = energy(d["v_pin"], d["zd"], d["phid"]), energy(v1, zd1, phid1)
    assert np.all(T1 <= T0 * (1 + 1e-13))
    Pn = np.sum(P * d["normal"], axis=1)
    Pt = P - Pn[:, None] * d["normal"]
    vt = d["v_r"] - np.sum(d["v_r"] * d["normal"], axis=1)[:, None] * d["normal"]
    assert np.all(Pn > 0.0)
    assert np.all(np.linalg.norm(Pt, axis=1) <= d["f"] * Pn * (1 + 1e-12))
    assert np.all(np.sum(Pt * vt, axis=1) <= 1e-12 * np.linalg.norm(Pt, axis=1) * np.linalg.norm(vt, axis=1))


def test_batched_equals_one_at_a_time():
    d = _random_impacts(50, 5)
    A = impact_compliance(d["m_p"], d["m"], d["J"], d["rho"])
    P, state = impact_impulse(d["v_r"], d["normal"], A, d["f"])
    for i in range(0, 50, 7):
        Pi, si = impact_impulse(d["v_r"][i:i + 1], d["normal"][i:i + 1], A[i:i + 1], d["f"][i])
        assert np.allclose(Pi[0], P[i], rtol=1e-13, atol=0) and si[0] == state[i]


@pytest.mark.parametrize("speed", [55.0, 1e4])
def test_high_speed_normal_impact_is_finite_and_sticks(speed):
    """Normal entry (tau- = 0) at chain speed and far above: finite impulse, v_r+ = 0."""
    v_minus = np.array([[0.0, 0.0, -speed]])
    A = impact_compliance(5e-3, 2.0, 5e-3, np.array([[0.06, 0.0, 0.0]]))
    with np.errstate(all="raise"):
        P, state = impact_impulse(v_minus, K[None], A, 0.1)
    assert state[0] == STUCK
    assert np.allclose(v_minus + np.einsum("nij,nj->ni", A, P), 0.0, atol=1e-13 * speed)
