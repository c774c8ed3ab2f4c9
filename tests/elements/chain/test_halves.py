"""Pin halves (spec chain-models-2 sections 3 and 5): model A5 forces against its energies and Rayleigh
function, mass against quadrature, Jacobian against differences, a tensioned open segment, a free ring,
and the A2 half contact points over A1."""
import numpy as np
import pytest
import scipy.linalg as sl
from scipy.integrate import solve_ivp

from cvtfem.elements.chain.asymmetric import ChainA1, shape_functions
from cvtfem.elements.chain.halves import TERMS, ChainA5, CoupledHalvesA2, ring_state
from cvtfem.errors import InputError

PITCH, PIN_L, H_PIN = 0.009, 0.033, 1.2e-3
PARAMS = dict(plate_stiffness=1e8, plate_bending_stiffness=0.3, plate_thickness=1.5e-3, plate_torsion_stiffness=50.0,
              pin_length=PIN_L, pin_axial_stiffness=2e8, half_bending_tau=1.4, half_bending_n=8.6, h_pin=H_PIN,
              roll_radius=(0.004, 0.005), roll_stiffness=1e11, hole_radius=0.0031, back_radius=0.0024,
              back_extent=0.0025, hole_clearance=5e-4, hole_stiffness=1e11, stopper_stiffness=1e6,
              stopper_play=5e-4)
DAMP = dict(beta_plate_ext=1e-6, beta_plate_shear=2e-6, beta_twist=1e-5, beta_bend=1e-5, half_axial_damping=2.0,
            roll_damping=1e3, joint_damping=0.01)


def chain(n=8, K=2, closed=True, seed=0, **over):
    """An A5 chain with a lacing of ``K`` plates per link shifted by the link number (period 3)."""
    rng = np.random.default_rng(seed)
    d = np.tile(np.linspace(-0.01, 0.01, K), (n, 1)) + 1e-3 * (np.arange(n) % 3)[:, None]
    args = dict(pitch=np.full(n, PITCH), plate_offset=d, n_plates=np.full(n, K),
                plate_mass=0.01 * (1 + 0.1 * rng.random(n)), pin_mass=0.012 * (1 + 0.1 * rng.random(n)),
                closed=closed, **PARAMS)
    args.update(over)
    return ChainA5(**args)


def straight(ch):
    """Straight chain along x1 with touching rolling faces and unstretched plates."""
    x = np.arange(ch.n_pins) * (PITCH - 2 * H_PIN)
    return ch.rest_state(np.column_stack([x, np.zeros_like(x)]), np.tile([1.0, 0.0], (ch.n_pins, 1)))


def random_state(ch, rng, amp=3e-6):
    """Ring (closed) or straight segment (open) with stretched plates and pressed rolling faces (4 um, 2 um),
    randomly perturbed (m; rad for slopes)."""
    if ch.closed:
        q = ring_state(ch, stretch=4e-6, overlap=2e-6)
    else:
        q = straight(ch)
        u, w, qp = ch.split(q)
        u[1, 0, :, 0] += 2e-6 * np.arange(ch.n_pins)
        u[0, 0, :, 0] += 2e-6 * np.arange(ch.n_pins) + 2e-6
    return q + amp * rng.standard_normal(ch.n2)


def grad(fun, x, h):
    """Central differences (exact for the quadratic Rayleigh function up to round-off)."""
    out = np.empty(x.size)
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        out[i] = (fun(x + e) - fun(x - e)) / (2 * h)
    return out


def relative_error(a, b):
    return np.abs(a - b).max() / np.abs(a).max()


CASES = [("A4", closed, term) for closed in (True, False) for term in TERMS] + [("A3", True, "plates"),
                                                                              ("A3-keep", True, "plates")]


@pytest.mark.parametrize("model,closed,term", CASES)
def test_elastic_forces_are_minus_energy_gradient(model, closed, term):
    """One energy term at a time, so that a small term is not hidden by a large one (the plate law only
    changes the plate term)."""
    ch = chain(plate_model=model, closed=closed, stopper_play=1e-6)
    q = random_state(ch, np.random.default_rng(1))
    Q = ch.elastic_forces(q, (term,))
    assert np.abs(Q).max() > 0
    assert relative_error(Q, -grad(lambda x: ch.potential_energy(x, (term,)), q, 1e-9)) < 1e-6


def test_every_contact_and_stopper_force_is_a_gradient():
    """Hole contacts closed (zero clearance, ring of 8 at 45 degrees), stoppers engaged (no play), rolling tie on."""
    ch = chain(hole_clearance=0.0, stopper_play=0.0, roll_tie=1e9)
    rng = np.random.default_rng(2)
    q = ring_state(ch, overlap=1e-6) + 2e-6 * rng.standard_normal(ch.n2)
    assert ch.outputs(q)["chain.roll_force"].max() > 0
    parts = ch.potential_parts(q)
    assert parts["contacts"] > 0 and parts["stoppers"] > 0
    for term in ("contacts", "stoppers"):
        Q = ch.elastic_forces(q, (term,))
        assert relative_error(Q, -grad(lambda x: ch.potential_energy(x, (term,)), q, 1e-9)) < 1e-6


@pytest.mark.parametrize("closed", [True, False])
def test_dissipative_forces_are_minus_rayleigh_gradient(closed):
    ch = chain(closed=closed, **DAMP)
    rng = np.random.default_rng(3)
    q, v = random_state(ch, rng), 0.05 * rng.standard_normal(ch.n2)
    Qd = ch.dissipative_forces(q, v)
    assert relative_error(Qd, -grad(lambda x: ch.rayleigh(q, x), v, 1e-4)) < 1e-6
    assert -v @ Qd == pytest.approx(2 * ch.rayleigh(q, v), rel=1e-12)          # Euler: Phi is quadratic in v


def test_friction_only_dissipates_and_its_power_is_reported():
    ch = chain(friction_coefficient=0.1, friction_speed=1e-3, friction_law="smooth")
    rng = np.random.default_rng(4)
    for _ in range(5):
        q, v = random_state(ch, rng), 0.01 * rng.standard_normal(ch.n2)
        F = ch.friction_forces(q, v)
        power = ch.outputs(q, v)["chain.friction_power"]
        assert np.all(power <= 0) and power.sum() < 0
        assert v @ F == pytest.approx(power.sum(), rel=1e-12)
    assert not np.any(chain().friction_forces(q, v))


def test_mass_matrix_equals_quadrature_of_kinetic_energy():
    ch = chain(n=5)
    rng = np.random.default_rng(5)
    v = rng.standard_normal(ch.n2)
    vu, vw, vq = ch.split(v)
    xg, wg = np.polynomial.legendre.leggauss(8)
    H = shape_functions(xg, PIN_L)
    T = 0.5 * float(ch.m_pack @ vq ** 2)
    for hf in range(2):
        Uperp = np.einsum("ig,inc->gnc", H, vu[hf])
        Upar = vw[hf, 0][None] + xg[:, None] * vw[hf, 1][None]
        T += 0.5 * float(np.einsum("g,n,gnc->", wg, ch.m_half[hf] / 2, Uperp ** 2))
        T += 0.5 * float(np.einsum("g,n,gn->", wg, ch.m_axial / 2, Upar ** 2))
    assert ch.kinetic_energy(v) == pytest.approx(T, rel=1e-13)
    assert ch.n2 == 21 * 5 and ch.mass_matrix.shape == (105, 105)
    q = ring_state(ch)
    a = ch.accel(q, 0 * v, q_ext=v)
    assert np.abs(ch.mass_matrix @ a - ch.forces(q, 0 * v) - v).max() < 1e-12 * np.abs(ch.mass_matrix @ a).max()


def test_translations_and_rotation_about_k_leave_energy_unchanged():
    ch = chain()
    rng = np.random.default_rng(6)
    q = random_state(ch, rng)
    u, w, qp = ch.split(q.copy())
    E0, Q0 = ch.potential_energy(q), ch.elastic_forces(q)
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s], [s, c]])
    ur = u @ R.T
    ur[:, 0] += [0.3, -0.2]
    qr = ch.join(ur, w + np.array([0.01, 0.0])[None, :, None], qp + 0.01)
    assert ch.potential_energy(qr) == pytest.approx(E0, rel=1e-9)
    Qu, Qw, Qq = ch.split(Q0)
    Qru, Qrw, Qrq = ch.split(ch.elastic_forces(qr))
    scale = np.abs(Q0).max()
    assert np.abs(Qru - Qu @ R.T).max() < 1e-7 * scale and np.abs(Qrw - Qw).max() < 1e-7 * scale
    assert np.abs(Qu[:, 0].sum((0, 1))).max() < 1e-9 * scale                     # internal forces sum to zero
    assert abs(Qw[:, 0].sum() + Qq.sum()) < 1e-9 * scale


def test_coloured_jacobian_equals_differences_and_stays_in_its_pattern():
    """The colouring bookkeeping: each coloured column is exactly the single-column difference (the compiled
    element Jacobian is checked against differences in test_halves_kernel.py)."""
    ch = chain(n=10, **DAMP)
    rng = np.random.default_rng(7)
    q, v = random_state(ch, rng), 0.01 * rng.standard_normal(ch.n2)
    K, C = ch.coloured_jacobian(q, v)
    cols = rng.choice(ch.n2, 25, replace=False)
    pat = ch.jac_sparsity.toarray()
    for j in cols:
        for wrt, Jm in ((0, K), (1, C)):
            h = 1e-7 * max(abs((q, v)[wrt][j]), 1e-2 * PIN_L)
            e = np.zeros(ch.n2)
            e[j] = h
            fp = ch.forces(q + e, v) if wrt == 0 else ch.forces(q, v + e)
            fm = ch.forces(q - e, v) if wrt == 0 else ch.forces(q, v - e)
            col = (fp - fm) / (2 * h)
            assert np.all(col[~pat[:, j]] == 0)
            assert np.abs(Jm[:, [j]].toarray().ravel() - col).max() <= 1e-12 * np.abs(col).max() + 1e-300


def test_open_segment_under_end_tension_carries_it_in_every_link():
    """Newton on all 21 n coordinates, end pins pulled by -+T (a quarter at each end of each half)."""
    T, n = 2000.0, 4
    ch = chain(n=n, closed=False, stopper_play=0.0)
    q = straight(ch)
    pins = np.repeat([0, n - 1], 4)
    half = np.tile([0, 0, 1, 1], 2)
    xi = np.tile([-1.0, 1.0], 4)
    F = np.zeros((8, 3))
    F[:4, 0], F[4:, 0] = -T / 4, T / 4
    Qext = ch.point_loads(pins, half, xi, F)
    v = np.zeros(ch.n2)
    for _ in range(30):
        R = ch.forces(q, v) + Qext
        if np.abs(R).max() < 1e-9 * T:
            break
        K, _ = ch.jacobian(q, v, damping=False)        # exact link blocks (forward differences diverge here)
        q = q + np.linalg.lstsq(-K.toarray(), R, rcond=1e-12)[0]
    assert np.abs(ch.forces(q, v) + Qext).max() < 1e-9 * T
    out = ch.outputs(q)
    Qu = ch.split(ch.elastic_forces(q, ("plates",)))[0]
    assert np.allclose(Qu[1, 0, 1:, 0], -T, rtol=1e-6)                         # plates pull each + half back by T
    assert np.allclose(Qu[0, 0, :n - 1, 0], T, rtol=1e-6)                      # and each - half forward
    assert np.allclose(out["chain.link_tension"][:n - 1], T, rtol=1e-4)        # sum of c Delta~ (tilt, moments)
    assert np.allclose(out["chain.roll_force"][1:n - 1], T, rtol=1e-6)       # interior pins: halves press with T
    assert np.allclose(out["chain.roll_force"][[0, n - 1]], T / 2, rtol=1e-6)  # end pins: the free half's share


def _ring_run(periods, rtol, n=6, lossy=False):
    """A free 6-pin ring (soft parameters: highest frequency ~7x the lowest link mode), DOP853.

    ``lossy``: damping and friction on, and the state carries the dissipated energy ``D' = 2 Phi - P_friction``;
    returns ``E + D`` then.  Also returns the round-off scale of the momentum, ``eps sqrt(m) max|Q(0)| t_end``
    (the internal forces sum to zero only up to the rounding of their element contributions)."""
    soft = dict(plate_stiffness=1e8, plate_bending_stiffness=0.03, plate_torsion_stiffness=5.0,
                pin_axial_stiffness=2e6, half_bending_tau=0.05, half_bending_n=0.1, roll_stiffness=1e9,
                hole_stiffness=1e9, hole_clearance=1.2e-3, hole_radius=0.0038, stopper_play=0.0, plate_model="A3-keep")
    if lossy:
        soft.update(friction_coefficient=0.1, friction_speed=0.05, friction_law="smooth", **DAMP)
    ch = chain(n=n, K=2, **soft)
    q0 = ring_state(ch, stretch=2e-6, overlap=2e-6)
    v0 = 0.02 * np.random.default_rng(8).standard_normal(ch.n2)
    m = ch.n2

    def rhs(t, y):
        q, v = y[:m], y[m:2 * m]
        if not lossy:
            return np.r_[v, ch.accel(q, v)]
        r = ch._evaluate(q, v)                                   # one pass: forces, Phi and friction together
        Q = r["friction"] - r["grad"] - r["gradv"]
        return np.r_[v, ch.inverse_mass @ Q, 2 * sum(r["Phi"].values()) - v @ r["friction"]]

    omega = 2 * np.sqrt(2 * soft["plate_stiffness"] / (0.012 + 0.01)) * np.sin(np.pi / n)   # lowest link mode
    y0 = np.r_[q0, v0, [0.0] if lossy else []]
    sol = solve_ivp(rhs, (0, periods * 2 * np.pi / omega), y0, method="DOP853", rtol=rtol, atol=1e-4 * rtol)
    assert sol.success
    ys = sol.y.T[:: max(1, sol.y.shape[1] // 50)]
    E = np.array([ch.kinetic_energy(y[m:2 * m]) + ch.potential_energy(y[:m]) + (y[-1] if lossy else 0.0) for y in ys])
    P = np.array([ch.momentum(y[m:2 * m]) for y in ys])
    roundoff = np.finfo(float).eps * np.sqrt(m) * np.abs(ch.forces(q0, v0)).max() * sol.t[-1]
    return E, P, ch.momentum(v0), sol.y[-1, -1] if lossy else 0.0, roundoff


def test_free_ring_conserves_momentum_and_energy():
    E, P, P0, _, _ = _ring_run(periods=0.5, rtol=1e-8)
    assert np.abs(E - E[0]).max() < 1e-6 * E[0]
    assert np.abs(P - P0).max() < 1e-12 * max(np.abs(P0).max(), 1e-3)


def test_damped_ring_with_friction_loses_exactly_its_dissipated_energy():
    """E + int (2 Phi - Q_friction . v) dt stays constant while a good part of E is dissipated."""
    E, P, P0, lost, _ = _ring_run(periods=0.2, rtol=1e-8, lossy=True)
    assert lost > 0.05 * E[0]
    assert np.abs(E - E[0]).max() < 1e-6 * lost
    assert np.abs(P - P0).max() < 1e-12 * np.abs(P0).max()               # internal forces, friction included


@pytest.mark.slow
def test_free_ring_conserves_energy_over_many_periods():
    E, P, P0, _, roundoff = _ring_run(periods=20, rtol=1e-9)
    assert np.abs(E - E[0]).max() < 1e-6 * E[0]
    assert np.abs(P - P0).max() < roundoff            # 1.1e-15 kg m/s found (compiled pass), 5e-16 (numpy); 1.5e-14



def test_point_loads_are_the_virtual_work_at_half_axis_points():
    ch = chain()
    rng = np.random.default_rng(9)
    q = random_state(ch, rng)
    pins, half, xi = np.array([0, 3, 3, 7]), np.array([0, 1, 0, 1]), np.array([-1.0, 1.0, 0.3, -1.0])
    F = rng.standard_normal((4, 3))
    Q = ch.point_loads(pins, half, xi, F)
    J = np.array([[(ch.axis_points(q + 1e-6 * e, pins, half, xi) - ch.axis_points(q - 1e-6 * e, pins, half, xi))[k]
                   / 2e-6 for e in np.eye(ch.n2)] for k in range(4)])          # (4, n2, 3)
    assert np.allclose(Q, np.einsum("knx,kx->n", J, F), rtol=0, atol=1e-9 * np.abs(F).max())


def a1_chain(n=8, closed=True):
    rng = np.random.default_rng(10)
    e = n if closed else n - 1
    return ChainA1(pitch=np.full(e, PITCH), plate_xi=np.tile(np.linspace(-0.8, 0.8, 4), (e, 1)),
                   n_plates=np.full(e, 4), plate_stiffness=1e8, plate_bending_stiffness=0.3,
                   plate_torsion_stiffness=50.0, pin_length=PIN_L, pin_mass=0.02 * (1 + 0.1 * rng.random(n)),
                   pin_axial_stiffness=2e8, pin_bending_tau=2.8, pin_bending_n=17.2, closed=closed, use_numba=False)


@pytest.mark.parametrize("closed", [True, False])
def test_a2_half_points_and_exact_virtual_work(closed):
    ch = a1_chain(closed=closed)
    a2 = CoupledHalvesA2(ch, H_PIN)
    rng = np.random.default_rng(11)
    n = ch.n_pins
    ang = 2 * np.pi * np.arange(n) / (n if closed else 3 * n)
    q = ch.rest_state(0.02 * np.column_stack([np.cos(ang), np.sin(ang)])) + 1e-4 * rng.standard_normal(ch.n2)
    pins = np.array([0, 2, 2, n - 1, 4])
    half, xi = np.array([-1, 1, -1, 1, 1]), np.array([-1.0, 1.0, 1.0, -1.0, -1.0])
    P = a2.contact_points(q, pins, half, xi)
    P0 = ch.axis_points(q, pins, xi)
    assert np.allclose(np.linalg.norm(P[:, :2] - P0[:, :2], axis=1), H_PIN, rtol=1e-12)
    F = rng.standard_normal((5, 3))
    J = np.array([(a2.contact_points(q + 1e-7 * e, pins, half, xi) - a2.contact_points(q - 1e-7 * e, pins, half, xi))
                  / 2e-7 for e in np.eye(ch.n2)])                           # (n2, 5, 3)
    Q = a2.point_loads(q, pins, half, xi, F)
    assert np.abs(Q - np.einsum("nkx,kx->n", J, F)).max() < 1e-7 * np.abs(Q).max()
    end = CoupledHalvesA2(ch, H_PIN, transfer="end").point_loads(q, pins, half, xi, F)
    assert np.array_equal(end, ch.point_loads(pins, xi, F))
    assert np.abs(Q - end).max() > 1e-3 * np.abs(Q).max()                    # the spin term is not negligible


def test_bad_input_is_reported():
    with pytest.raises(InputError, match="plate_model"):
        chain(plate_model="A9")
    with pytest.raises(InputError, match="back_radius"):
        chain(back_radius=0.01)
    with pytest.raises(InputError, match="pitch"):
        chain(pitch=np.full(3, PITCH))
    with pytest.raises(InputError, match="h_pin"):
        CoupledHalvesA2(a1_chain(), 0.0)


@pytest.mark.slow
def test_locked_halves_approach_a1_lowest_frequencies():
    """Stiff rolling contact with a no-slip tie, stiff stoppers without play: the lowest six nonzero frequencies
    of an 8-pin ring (twist family; plate out-of-plane bending off, which A1 homogenises differently) agree with
    A1's.  The A1 ring's joint mechanisms have zero frequency; in A5 the contact prestress of the linearisation
    state (1e-10 m overlap) lifts them to a few hundred rad/s, below the compared band (> 3000 rad/s)."""
    n, K, P = 8, 3, PITCH - 2 * H_PIN
    xi = np.tile(np.linspace(-0.6, 0.6, K), (n, 1))
    common = dict(n_plates=np.full(n, K), plate_stiffness=1e8, plate_bending_stiffness=0.0,
                  plate_torsion_stiffness=50.0, pin_length=PIN_L, pin_axial_stiffness=2e8)
    a1 = ChainA1(pitch=np.full(n, P), plate_xi=xi, pin_mass=np.full(n, 0.022), pin_bending_tau=2.8,
                 pin_bending_n=17.2, use_numba=False, **common)
    ang = 2 * np.pi * np.arange(n) / n
    q1 = a1.rest_state(P / (2 * np.sin(np.pi / n)) * np.column_stack([np.cos(ang), np.sin(ang)]))
    a5 = ChainA5(pitch=np.full(n, PITCH), plate_offset=PIN_L / 2 * xi, plate_thickness=1.5e-3,
                 plate_mass=np.full(n, 0.01), pin_mass=np.full(n, 0.012), half_bending_tau=1.4, half_bending_n=8.6,
                 h_pin=H_PIN, roll_radius=(0.004, 0.004), roll_stiffness=1e13, roll_tie=1e13, hole_radius=0.0045,
                 back_radius=0.0024, back_extent=0.0025, hole_clearance=1.9e-3, hole_stiffness=1e9,
                 stopper_stiffness=1e9, stopper_play=0.0, plate_model="A3-keep", **common)
    q5 = ring_state(a5, overlap=1e-10)
    K5, _ = a5.coloured_jacobian(q5, np.zeros(a5.n2), step=1e-9)

    def omegas(K, M):
        w2 = sl.eigh(-0.5 * (K + K.T), M, eigvals_only=True)
        w = np.sqrt(np.abs(w2))
        return np.sort(w[(w2 > 0) & (w > 3000.0)])[:6]

    w1 = omegas(a1.stiffness_matrix(q1).toarray(), a1.mass_matrix.toarray())
    w5 = omegas(K5.toarray(), a5.mass_matrix.toarray())
    assert w1[0] > 6000
    assert np.allclose(w5, w1, rtol=1e-2)
