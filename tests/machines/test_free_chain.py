"""The free discrete chain through the Model protocol (issue 13: the chain as a model family)."""
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from cvtfem.assembly.model import Model
from cvtfem.elements.chain.asymmetric import ChainA1
from cvtfem.elements.chain.geometry import REFERENCE_SECTION, chain_geometry, ring_positions
from cvtfem.elements.chain.per_plate import ChainPerPlate
from cvtfem.errors import InputError
from cvtfem.elements.chain.symmetric import ChainDamping, ChainS1, ChainS2, ChainS3
from cvtfem.integrate import solve
from cvtfem.machines.chain import FreeChain, FreeChainA

C_LINK, PITCH = 1.4e9, 0.009


def _open_chain(Family, n=10):
    g = chain_geometry(n, 0.033, PITCH, 12, C_LINK, n * 0.0179, REFERENCE_SECTION, c_pin=2.0e8, closed=False)
    fam = Family(g)
    x = np.stack([np.arange(n) * PITCH, np.zeros(n)], axis=1)
    return fam, FreeChain(fam, fam.join(x, np.full(n, g.l / 2), np.zeros((n, 2))))


def _ring(Family, n=8, damping=ChainDamping()):
    g = chain_geometry(n, 0.033, PITCH, 12, C_LINK, n * 0.0179, REFERENCE_SECTION, c_pin=2.0e8)
    fam = Family(g, damping)
    x, _ = ring_positions(g.L)
    rng = np.random.default_rng(3)
    v0 = fam.join(rng.normal(0.0, 0.05, (n, 2)), rng.normal(0.0, 0.05, n), rng.normal(0.0, 0.5, (n, 2)))
    return fam, FreeChain(fam, fam.join(x, np.full(n, g.l / 2), np.zeros((n, 2))), v0)


@pytest.mark.parametrize("Family", [ChainS1, ChainS2])
def test_linearised_straight_chain_has_the_spring_mass_frequencies(Family):
    """About a straight, unstretched open chain the in-line stiffness is the link stiffness c between
    neighbours: the free-free spring-mass chain (masses m_eff, an independent tridiagonal model) gives
    the longitudinal frequencies, to 1e-9 relative."""
    fam, model = _open_chain(Family)
    lin = model.linearize(model.initial_state())
    w2 = sla.eigh(lin.K.toarray(), lin.M.toarray(), eigvals_only=True)
    n, m = fam.n, fam.geom.m_eff
    lap = np.diag(np.r_[1.0, np.full(n - 2, 2.0), 1.0]) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1)
    ref = sla.eigh(C_LINK * lap, np.diag(m), eigvals_only=True)
    for value in ref[1:]:
        assert np.min(np.abs(w2 - value)) <= 1e-9 * value
    assert np.allclose(lin.G.toarray(), 0.0) and abs(ref[0]) < 1e-6 * ref[-1]   # the rigid translation


def _assert_jacobian_matches_differences(model, x):
    """``jac`` has nothing outside ``jac_sparsity`` and equals coloured differences to 1e-5 of its largest entry."""
    J = model.jac(0.0, x)
    outside = J.multiply(sp.csr_matrix(~model.jac_sparsity.toarray()))
    assert outside.nnz == 0 or np.abs(outside.data).max() == 0.0
    fd = model.fd_jac(0.0, x).toarray()
    scale = np.abs(J.toarray()).max()
    assert np.abs(fd - J.toarray()).max() <= 1e-5 * scale


@pytest.mark.parametrize("Family", [ChainS1, ChainS2, ChainS3])
def test_protocol_jacobian_and_its_pattern(Family):
    fam, model = _ring(Family, damping=ChainDamping(beta_link=1e-6, b_joint=1e-4))
    assert isinstance(model, Model)
    x = model.initial_state() + 1e-5 * np.random.default_rng(1).standard_normal(model.size)
    _assert_jacobian_matches_differences(model, x)


@pytest.mark.parametrize("Family", [ChainS1, ChainS2, ChainS3])
def test_free_ring_conserves_energy_through_solve(Family):
    """A closed ring with random initial velocities, no dissipation: solve(model) (dopri78, rtol 1e-10)
    keeps the energy to 1e-8 relative and the linear momentum to round-off over 20 periods of the
    highest in-line link mode."""
    fam, model = _ring(Family)
    period = 2 * np.pi / (2 * np.sqrt(C_LINK / fam.geom.m_eff.min()))
    res = solve(model, (0.0, 20 * period), model.initial_state(), method="dopri78", rtol=1e-10, atol=1e-14)
    assert res.success
    E = np.array([model.energy(x) for x in res.y.T])
    assert np.abs(E - E[0]).max() <= 1e-8 * E[0]
    p = np.array([fam.linear_momentum(x[model.n2:]) for x in res.y.T])
    assert np.abs(p - p[0]).max() <= 1e-12 * np.abs(fam.geom.m_eff).sum() * 0.05


def test_damped_ring_loses_what_the_rayleigh_forces_take():
    """dE/dt = -2 Phi along a damped run: E(t) + int 2 Phi dt stays at E(0) to 1e-6 of the dissipated energy."""
    fam, model = _ring(ChainS2, damping=ChainDamping(beta_link=2e-7, b_joint=1e-4))
    period = 2 * np.pi / (2 * np.sqrt(C_LINK / fam.geom.m_eff.min()))
    t = np.linspace(0.0, 10 * period, 2001)
    res = solve(model, (0.0, t[-1]), model.initial_state(), method="dopri78", rtol=1e-11, atol=1e-15, t_eval=t)
    E = np.array([model.energy(x) for x in res.y.T])
    D = np.array([model.power(0.0, x)["dissipated"] for x in res.y.T])
    lost = np.concatenate([[0.0], np.cumsum(0.5 * (D[1:] + D[:-1]) * np.diff(t))])   # trapezoid
    assert lost[-1] > 1e-3 * E[0]
    assert np.abs(E + lost - E[0]).max() <= 1e-3 * lost[-1]


# ---------------------------------------------------------------- A family (A1, A3, A4)
A_STIFF = dict(plate_stiffness=1e7, plate_bending_stiffness=0.5, plate_torsion_stiffness=2.0,
               pin_axial_stiffness=5e7, pin_bending_tau=3.0, pin_bending_n=2.0)
A_DAMP = dict(beta_link_ext=2e-6, beta_link_tors=2e-6, beta_link_shear=2e-6, beta_bend=2e-6,
              pin_axial_damping=0.5, joint_damping=1e-3)
A_KINDS = ["A1", "A3", "A4"]
PIN_L, PIN_M = 0.03, 0.01


def _a_family(kind, n, closed, xi, damping=None, **over):
    """An A-family chain with plates at the stations ``xi`` (one row, every link) and equal pitches."""
    e = n if closed else n - 1
    xi = np.tile(xi, (e, 1))
    args = dict(pitch=np.full(e, PITCH), plate_xi=xi, n_plates=np.full(e, xi.shape[1]), pin_length=PIN_L,
                pin_mass=np.full(n, PIN_M), closed=closed, **A_STIFF, **(damping or {}))
    args.update(over)
    if kind == "A1":
        return ChainA1(**args)
    return ChainPerPlate(**{"model": kind, "plate_thickness": 1.5e-3, **args})


def _spinning_ring(kind, n=8, damping=None, stretch=1e-3, spread=0.05, tilt=0.0):
    """A closed ring stretched by ``stretch`` and spinning about k at the speed whose centripetal force the
    plate tension supplies (so the plates stay taut), plus random velocities of every coordinate and random
    pin slopes of size ``tilt``."""
    xi = np.array([-0.8, -0.3, 0.3, 0.8])
    fam = _a_family(kind, n, True, xi, damping)
    ang = 2 * np.pi * np.arange(n) / n
    R = PITCH * (1 + stretch) / (2 * np.sin(np.pi / n))
    centres = R * np.column_stack([np.cos(ang), np.sin(ang)])
    q0 = fam.base.rest_state(centres) if kind != "A1" else fam.rest_state(centres)
    T = 4 * 1e7 * stretch * PITCH                                   # link tension, 4 plates
    speed = np.sqrt(T * PITCH / PIN_M)                               # 2 T sin(pi/n) = m v^2 / R
    v0 = np.zeros(fam.n2)
    v0[fam.dof_index[:, 0]] = -speed * np.sin(ang)
    v0[fam.dof_index[:, 1]] = speed * np.cos(ang)
    rng = np.random.default_rng(5)
    v0 += spread * rng.standard_normal(fam.n2)
    slopes = fam.dof_index[:, 4:8].ravel()
    q0[slopes] += tilt * rng.standard_normal(slopes.size)
    return fam, FreeChainA(fam, q0, v0)


@pytest.mark.parametrize("kind", A_KINDS)
def test_a_family_straight_chain_has_the_spring_mass_frequencies(kind):
    """Plates at the 2-point Gauss stations load the Hermite pin like its mass (both integrate cubics exactly),
    so about a straight chain along x the in-line motions u_0x = phi (all else 0) are exact modes: every
    eigenpair of the free-free spring-mass chain (masses m, springs sum c^k) is one of the linearised model,
    to 1e-9.  A1 and A3 keeping compressed plates about the unstretched chain; A3 and A4 (tension only)
    about a chain stretched by 1e-4."""
    n = 8
    gauss = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    stretch = 0.0 if kind == "A1" else 1e-4
    over = {} if kind == "A1" else dict(drop_compressed=False) if kind == "A3" else {}
    fam = _a_family(kind, n, False, gauss, **over)
    x = np.column_stack([np.arange(n) * PITCH * (1 + stretch), np.zeros(n)])
    q0 = fam.rest_state(x) if kind == "A1" else fam.base.rest_state(x)
    model = FreeChainA(fam, q0)
    lin = model.linearize(model.initial_state())
    K, M = lin.K.toarray(), lin.M.toarray()
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
    w2 = sla.eigh(K, M, eigvals_only=True)
    lap = np.diag(np.r_[1.0, np.full(n - 2, 2.0), 1.0]) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1)
    ref, modes = sla.eigh(2 * A_STIFF["plate_stiffness"] * lap, PIN_M * np.eye(n))
    for value, phi in zip(ref[1:], modes.T[1:]):
        assert np.min(np.abs(w2 - value)) <= 1e-9 * value
        x = np.zeros(fam.n2)
        x[fam.dof_index[:, 0]] = phi
        assert np.abs(K @ x - value * M @ x).max() <= 1e-9 * value * np.abs(M @ x).max()


@pytest.mark.parametrize("kind", A_KINDS)
def test_a_family_protocol_jacobian_and_its_pattern(kind):
    """Spinning damped ring with random tilts and slopes of 1e-4 (A4: plates in 8 of the 10 states)."""
    fam, model = _spinning_ring(kind, damping=A_DAMP)
    assert isinstance(model, Model)
    x = model.initial_state()
    rng = np.random.default_rng(1)
    x[:model.n2] += 1e-7 * rng.standard_normal(model.n2)
    tilts = fam.dof_index[:, 2:8].ravel()
    x[tilts] += 1e-4 * rng.standard_normal(tilts.size)
    if kind == "A4":
        assert np.unique(fam.outputs(x[:model.n2])["chain.plate_state"]).size >= 6
    _assert_jacobian_matches_differences(model, x)


def _highest_link_period():
    return 2 * np.pi / (2 * np.sqrt(4 * A_STIFF["plate_stiffness"] / PIN_M))


@pytest.mark.parametrize("kind", A_KINDS)
def test_a_family_free_ring_conserves_energy_and_momentum_through_solve(kind):
    """A spinning ring with random velocities, no dissipation, through solve(model) (dopri78, rtol 1e-10):
    energy to 1e-8 relative, linear momentum to round-off, angular momentum about k to 1e-10 relative,
    over 10 periods of the highest in-line link mode; with pin slopes of 1e-4, A4's plates switch between
    line and corner contact on the way."""
    fam, model = _spinning_ring(kind, tilt=1e-4)
    res = solve(model, (0.0, 10 * _highest_link_period()), model.initial_state(), method="dopri78",
                rtol=1e-10, atol=1e-14)
    assert res.success
    E = np.array([model.energy(x) for x in res.y.T])
    assert np.abs(E - E[0]).max() <= 1e-8 * E[0]
    mom = [fam.momentum(x[:model.n2], x[model.n2:]) for x in res.y.T]
    p = np.array([m[0] for m in mom])
    L = np.array([m[1] for m in mom])
    assert np.abs(p - p[0]).max() <= 1e-12 * PIN_M * fam.n_pins * 0.05
    assert np.abs(L - L[0]).max() <= 1e-10 * abs(L[0])
    if kind == "A4":
        states = np.array([fam.outputs(x[:model.n2])["chain.plate_state"] for x in res.y.T])
        assert np.any(states != states[0])                              # line <-> corner contact on the way


@pytest.mark.parametrize("kind", A_KINDS)
def test_a_family_damped_ring_loses_what_the_rayleigh_forces_take(kind):
    """dE/dt = -2 Phi along a damped run: E(t) + int 2 Phi dt stays at E(0) to 1e-3 of the dissipated energy
    (trapezoid rule on 1001 points over 5 periods of the highest in-line link mode), and the vibration
    (not the rigid spin, which dissipates nothing) loses more than a tenth of its energy."""
    fam, model = _spinning_ring(kind, damping=A_DAMP)
    t = np.linspace(0.0, 5 * _highest_link_period(), 1001)
    res = solve(model, (0.0, t[-1]), model.initial_state(), method="dopri78", rtol=1e-11, atol=1e-15, t_eval=t)
    E = np.array([model.energy(x) for x in res.y.T])
    D = np.array([model.power(0.0, x)["dissipated"] for x in res.y.T])
    lost = np.concatenate([[0.0], np.cumsum(0.5 * (D[1:] + D[:-1]) * np.diff(t))])
    _, spin = _spinning_ring(kind, damping=A_DAMP, spread=0.0)
    assert lost[-1] > 0.1 * (E[0] - spin.energy(spin.initial_state()))
    assert np.abs(E + lost - E[0]).max() <= 1e-3 * lost[-1]


@pytest.mark.parametrize("kind", ["A3", "A4"])
def test_per_plate_family_forces_are_gradients_and_backends_agree(kind):
    """ChainPerPlate: elastic forces = -grad Pi, dissipative forces = -d Phi/dv (central differences, 1e-6
    of the largest force) on a spinning ring with random pin tilts and slopes (plates in many states); the
    compiled plate forces and plate Jacobians
    (per_plate_kernel) equal the numpy twin (force_jacobians) to 1e-12."""
    fam, model = _spinning_ring(kind, damping=A_DAMP)
    x = model.initial_state()
    tilts = fam.dof_index[:, 2:8].ravel()
    x[tilts] += 1e-4 * np.random.default_rng(1).standard_normal(tilts.size)
    q, v = x[:model.n2], x[model.n2:]
    assert np.unique(fam.outputs(q)["chain.plate_state"]).size >= (6 if kind == "A4" else 2)   # A3: taut and slack
    twin = ChainPerPlate(model=kind, plate_thickness=1.5e-3, use_numba=False, **{
        **dict(pitch=fam.base.L, plate_xi=fam.base.plate_xi, n_plates=np.full(fam.n_pins, 4), pin_length=PIN_L,
               pin_mass=np.full(fam.n_pins, PIN_M)), **A_STIFF, **A_DAMP})
    Q = fam.elastic_forces(q)
    assert np.abs(twin.forces(q, v) - fam.forces(q, v)).max() <= 1e-12 * np.abs(Q).max()
    for a, b in zip(fam.jacobians(q, v), twin.jacobians(q, v)):              # compiled plate Jacobians
        assert np.abs((a - b).toarray()).max() <= 1e-12 * np.abs(b.toarray()).max()
    h, eye = 1e-9, np.eye(model.n2)
    g = np.array([(fam.potential_energy(q + h * e) - fam.potential_energy(q - h * e)) / (2 * h) for e in eye])
    assert np.abs(Q + g).max() <= 1e-6 * np.abs(Q).max()
    Qd = fam.dissipative_forces(q, v)
    gd = np.array([(fam.rayleigh(q, v + 1e-6 * e) - fam.rayleigh(q, v - 1e-6 * e)) / 2e-6 for e in eye])
    assert np.abs(Qd + gd).max() <= 1e-6 * np.abs(Qd).max()


def test_per_plate_family_refuses_bad_input():
    with pytest.raises(InputError, match="model"):
        _a_family("A5", 6, True, np.array([0.0]))
    with pytest.raises(InputError, match="plate_thickness"):
        _a_family("A4", 6, True, np.array([0.0]), plate_thickness=0.0)
    with pytest.raises(InputError, match="plate_bending_stiffness"):
        _a_family("A3", 6, True, np.array([0.0]), plate_bending_stiffness=0.0)


@pytest.mark.parametrize("kind", A_KINDS)
def test_a_family_outputs_match_their_specs(kind):
    """Every declared output comes back with its declared size; A3/A4 link tension = sum of plate tensions,
    which on the spinning ring is the centripetal 2 T sin(pi/n) = m v^2 / R to the ring's 1e-3 stretch."""
    fam, model = _spinning_ring(kind, spread=0.0)
    out = model.outputs(0.0, model.initial_state())
    assert sorted(out) == sorted(s.name for s in model.output_specs)
    for spec in model.output_specs:
        assert np.size(out[spec.name]) == spec.size, spec.name
    T = 4 * A_STIFF["plate_stiffness"] * 1e-3 * PITCH
    assert np.allclose(out["chain.link_tension"], T, rtol=2e-3)
