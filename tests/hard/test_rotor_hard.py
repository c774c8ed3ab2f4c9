"""Rotor hard cases (issue 7): coincident modes and mode crossings in Campbell tracking,
zero-speed rigid-body modes, extreme stiffness ratios of the supports.

References: Euler-Bernoulli beam frequencies ``w = (beta L)^2 sqrt(E I / (rho A L^4))`` with
``beta L = n pi`` (pinned-pinned) and 4.7300, 7.8532, 10.9956 (free-free); rigid bounce and
rocking of a free shaft on two soft springs ``sqrt(2 k / m)``, ``sqrt(6 k / m)``; the gyroscopic
disk ``Id w^2 -/+ Ip Omega w - k = 0``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem, campbell
from cvtfem.scene.loader import scene_from_dict

pytestmark = pytest.mark.hard

E, RHO, D, L, N_EL = 2.11e11, 7810.0, 0.05, 1.5, 30
AREA, I_AREA = math.pi * D ** 2 / 4, math.pi * D ** 4 / 64
MASS = RHO * AREA * L


def beam(beta_l: float) -> float:
    """Euler-Bernoulli frequency (rad/s) of the shaft for a root ``beta L``."""
    return beta_l ** 2 * math.sqrt(E * I_AREA / (RHO * AREA * L ** 4))


def shaft_problem(k_support: float | None) -> ModalProblem:
    """A uniform Euler-Bernoulli shaft (30 elements, no rotary inertia) on two isotropic supports."""
    data = {"material": [{"name": "steel", "E": E, "G": 8.12e10, "rho": RHO}],
            "shaft": [{"length": L / N_EL, "outer_diameter": D, "material": "steel", "repeat": N_EL}],
            "rotor": {"theory": "euler-bernoulli", "rotary_inertia": False}}
    if k_support is not None:
        data["bearing"] = [{"node": 0, "kxx": k_support, "kyy": k_support},
                           {"node": N_EL, "kxx": k_support, "kyy": k_support}]
    model = build_model(scene_from_dict(data))
    return ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind)


@pytest.mark.parametrize("k_support", [1e12, 1e14, 1e16, 1e18])
def test_very_stiff_supports_give_the_pinned_pinned_spectrum(k_support):
    """Supports 1e4..1e10 x stiffer than the shaft (48 E I / L^3 = 9e6 N/m): n^2 ratios of the
    pinned-pinned beam, every mode kept. (Before the fix the dense solver's rigid-mode threshold,
    1e-6 |lambda|_max, silently dropped the first modes once |lambda|_max reached ~1e9 rad/s.)"""
    modes = shaft_problem(k_support).solve(0.0, 8)
    lateral = modes.wd[np.isin(modes.whirl, ("forward", "backward"))][:6]
    w1 = beam(math.pi)
    # the support spring shortens nothing measurable above 1e12 N/m (static deflection ratio 1e-5)
    assert np.allclose(lateral / w1, [1, 1, 4, 4, 9, 9], rtol=1e-4 if k_support >= 1e14 else 2e-4)


def test_very_soft_supports_rigid_modes_and_free_free_bending():
    """Supports 1e5 x softer than the shaft: the two rigid-body pairs (bounce sqrt(2k/m), rocking
    sqrt(6k/m)) are far below the first free-free bending mode, which is kept exactly."""
    k = 1e2
    modes = shaft_problem(k).solve(0.0, 6)
    # rigid-body formulas hold up to the shaft's compliance, a relative shift of order 1e-5..1e-4
    assert np.allclose(modes.wd[:2], math.sqrt(2 * k / MASS), rtol=1e-4)
    assert np.allclose(modes.wd[2:4], math.sqrt(6 * k / MASS), rtol=1e-4)
    assert np.allclose(modes.wd[4:6], beam(4.730040745), rtol=2e-4)


def test_free_rotor_at_zero_speed_drops_rigid_body_modes():
    """No supports: the rigid-body modes (zero frequency, Jordan pairs perturbed by round-off)
    are excluded and the lowest reported modes are the free-free bending pairs."""
    modes = shaft_problem(None).solve(0.0, 6)
    assert np.all(np.isfinite(modes.eigenvalues))
    expected = [beam(b) for b in (4.730040745, 7.853204624, 10.99560784)]
    assert np.allclose(modes.wd, np.repeat(expected, 2), rtol=5e-4)


def _gyro_disk(Id=0.02, Ip=0.03, k_tilt=2e4, J=0.05, k_phi=4e3):
    """A disk's two tilts (kinds theta1, theta2) with gyroscopic coupling and an independent
    torsion (kind phi): M = diag(Id, Id, J), K = diag(k_tilt, k_tilt, k_phi), G = Ip [[0, 1], [-1, 0]]."""
    M = np.diag([Id, Id, J])
    K = np.diag([k_tilt, k_tilt, k_phi])
    G = np.zeros((3, 3))
    G[0, 1], G[1, 0] = Ip, -Ip
    return ModalProblem(M, K, np.zeros((3, 3)), G, np.array([3, 4, 5]))


def test_campbell_tracks_coincident_pair_and_a_crossing():
    """At rest the two tilt modes coincide (sqrt(k/Id) = 1000 rad/s, an arbitrary basis of a
    double eigenvalue); with spin they split into w = (+/- Ip Omega + sqrt(Ip^2 Omega^2 + 4 Id k)) / (2 Id).
    The backward branch falls through the speed-independent torsion mode sqrt(k_phi/J) = 282.8 rad/s
    at Omega = (k - Id w^2) / (Ip w) = 2168 rad/s. The tracked curves must keep their identity
    through both the degenerate start and the crossing."""
    Id, Ip, k, J, k_phi = 0.02, 0.03, 2e4, 0.05, 4e3
    prob = _gyro_disk(Id, Ip, k, J, k_phi)
    speeds = np.linspace(0.0, 3000.0, 61)
    camp = campbell(prob, speeds, n_modes=3, extra=0)
    w_phi = math.sqrt(k_phi / J)
    root = np.sqrt((Ip * speeds) ** 2 + 4 * Id * k)
    w_b, w_f = (root - Ip * speeds) / (2 * Id), (root + Ip * speeds) / (2 * Id)
    # identify columns at the last speed (well separated), then check whole curves
    col_phi = int(np.argmin(np.abs(camp.wd[-1] - w_phi)))
    col_f = int(np.argmax(camp.wd[-1]))
    col_b = ({0, 1, 2} - {col_phi, col_f}).pop()
    assert np.allclose(camp.wd[:, col_phi], w_phi, rtol=1e-10)
    assert np.allclose(camp.wd[:, col_f], w_f, rtol=1e-9)
    assert np.allclose(camp.wd[:, col_b], w_b, rtol=1e-9)
    assert camp.wd[0, col_f] == pytest.approx(camp.wd[0, col_b], rel=1e-12)   # coincident at rest
    # the backward branch really crosses the torsion line inside the sweep, at the analytic speed
    cross = (k - Id * w_phi ** 2) / (Ip * w_phi)
    assert speeds[0] < cross < speeds[-1]
    before, after = speeds < cross, speeds > cross
    assert np.all(camp.wd[before, col_b] > w_phi) and np.all(camp.wd[after, col_b] < w_phi)
    assert set(camp.whirl[1:, col_f]) == {"forward"} and set(camp.whirl[1:, col_b]) == {"backward"}
    assert set(camp.whirl[:, col_phi]) == {"torsional"}


def test_critically_damped_supports_give_no_spurious_modes():
    """Two isotropic point masses, one critically damped (double real root -w0, split by round-off
    into a pair with Im ~ sqrt(eps) w0), one with damping ratio 0.01: only the latter's x/y pair
    is oscillatory, at w0 sqrt(1 - zeta^2), also when the spectrum spans 1e8 (stiff second mass)."""
    m, k1, k2, zeta = 2.0, 8e4, 8e4 * 1e16, 0.01
    w1, w2 = math.sqrt(k1 / m), math.sqrt(k2 / m)
    M = np.eye(6) * m
    K = np.diag([k1, k1, k2, k2, k2, k2])
    C = np.diag([2 * m * w1] * 2 + [2 * zeta * m * w2] * 2 + [2 * m * w2] * 2)
    kind = np.array([0, 1, 0, 1, 0, 1])          # three nodes' (u1, u2), uncoupled
    modes = ModalProblem(M, K, C, np.zeros((6, 6)), kind).solve(0.0, 2)
    assert len(modes.wd) == 2
    assert np.allclose(modes.wd, w2 * math.sqrt(1 - zeta ** 2), rtol=1e-9)


def test_campbell_of_an_overhung_disk_rotor_keeps_pairs_apart_from_zero_speed():
    """FE rotor with a gyroscopic disk on isotropic bearings: at rest every lateral mode is a
    double eigenvalue (x and y); from the first speed step on, the tracked backward curves fall
    and the forward ones rise monotonically (gyroscopic softening/stiffening) and no tracked
    curve changes its whirl label."""
    data = {"material": [{"name": "steel", "E": E, "G": 8.12e10, "rho": RHO}],
            "shaft": [{"length": 0.05, "outer_diameter": D, "material": "steel", "repeat": 12}],
            "disk": [{"node": 4, "mass": 20.0, "Id": 0.1, "Ip": 0.2}],
            "bearing": [{"node": 0, "kxx": 1e7, "kyy": 1e7}, {"node": 12, "kxx": 1e7, "kyy": 1e7}]}
    model = build_model(scene_from_dict(data))
    prob = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind)
    camp = campbell(prob, np.linspace(0.0, 2000.0, 41), 6)
    assert np.allclose(camp.wd[0, 0::2], camp.wd[0, 1::2], rtol=1e-9)          # coincident at rest
    assert np.all(camp.whirl == camp.whirl[0]) and list(camp.whirl[0]) == ["backward", "forward"] * 3
    step = np.diff(camp.wd, axis=0)
    assert np.all(step[:, 0::2] < 0) and np.all(step[:, 1::2] > 0)
    assert camp.wd[-1, 2] < 0.7 * camp.wd[0, 2] and camp.wd[-1, 3] > 1.3 * camp.wd[0, 3]
