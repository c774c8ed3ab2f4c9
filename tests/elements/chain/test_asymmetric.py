"""Chain model A1 (spec chain-models-2 section 2): forces against energies, mass against quadrature,
rigid-body invariance, a tensioned straight segment, conservation in free vibration."""
import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from cvtfem.elements.chain.asymmetric import ChainA1, shape_functions, shape_slopes
from cvtfem.errors import InputError

PITCH, PIN_L = 0.009, 0.03
STIFF = dict(plate_stiffness=1e7, plate_bending_stiffness=0.5, plate_torsion_stiffness=2.0,
             pin_axial_stiffness=5e7, pin_bending_tau=30.0, pin_bending_n=20.0)
DAMP = dict(beta_link_ext=1e-5, beta_link_tors=2e-5, beta_link_shear=3e-5, beta_bend=1e-5,
            pin_axial_damping=3.0, joint_damping=1e-3)


def chain(n=8, closed=True, seed=0, **over):
    """A chain with a randomised lacing (4-6 plates per link) and pitches."""
    rng = np.random.default_rng(seed)
    e = n if closed else n - 1
    xi = np.sort(rng.uniform(-0.95, 0.95, (e, 6)), 1)
    args = dict(pitch=PITCH * (1 + 0.03 * rng.standard_normal(e)), plate_xi=xi, n_plates=rng.integers(4, 7, e),
                pin_length=PIN_L, pin_mass=0.01 * (1 + 0.1 * rng.random(n)), closed=closed, use_numba=False,
                **STIFF, **DAMP)
    args.update(over)
    return ChainA1(**args)


def ring(ch):
    """Pin centres of the unstretched regular polygon of a closed chain with equal pitches."""
    n = ch.n_pins
    ang = 2 * np.pi * np.arange(n) / n
    return PITCH / (2 * np.sin(np.pi / n)) * np.column_stack([np.cos(ang), np.sin(ang)])


def random_state(ch, rng, amp=1e-4):
    """Straight chain along x1 with random perturbations of every coordinate (m, and rad for slopes)."""
    q = ch.rest_state(np.column_stack([np.cumsum(np.r_[0.0, ch.L[:-1]]), np.zeros(ch.n_pins)]))
    return q + amp * rng.standard_normal(ch.n2)


def grad(fun, x, h):
    return np.array([(fun(x + h * e) - fun(x - h * e)) / (2 * h) for e in np.eye(x.size)])


ONLY = {  # one energy or dissipation term at a time, so that a small term is not hidden by a large one
    "pin_axial": dict(plate_stiffness=0.0, plate_bending_stiffness=0.0, plate_torsion_stiffness=0.0,
                      pin_bending_tau=1e-30, pin_bending_n=1e-30),
    "pin_bending": dict(plate_stiffness=0.0, plate_bending_stiffness=0.0, plate_torsion_stiffness=0.0,
                        pin_axial_stiffness=0.0),
    "link_extension": dict(plate_bending_stiffness=0.0, plate_torsion_stiffness=0.0, pin_axial_stiffness=0.0,
                           pin_bending_tau=1e-30, pin_bending_n=1e-30),
    "link_twist": dict(plate_stiffness=0.0, plate_bending_stiffness=0.0, pin_axial_stiffness=0.0,
                       pin_bending_tau=1e-30, pin_bending_n=1e-30),
    "link_shear": dict(plate_stiffness=0.0, plate_torsion_stiffness=0.0, pin_axial_stiffness=0.0,
                       pin_bending_tau=1e-30, pin_bending_n=1e-30),
    "all": {},
}


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("part", list(ONLY))
def test_elastic_forces_are_minus_energy_gradient(part, closed):
    ch = chain(closed=closed, **ONLY[part])
    rng = np.random.default_rng(3)
    for _ in range(2):
        q = random_state(ch, rng)
        Q = ch.elastic_forces(q)
        g = grad(ch.potential_energy, q, 1e-7)
        assert np.abs(Q).max() > 0
        assert np.abs(Q + g).max() <= 1e-6 * np.abs(Q).max()


@pytest.mark.parametrize("shear", ["derived", "printed"])
def test_forces_of_printed_shear_convention_are_its_gradient(shear):
    ch = chain(shear_convention=shear, **ONLY["link_shear"])
    q = random_state(ch, np.random.default_rng(4))
    assert np.abs(ch.elastic_forces(q) + grad(ch.potential_energy, q, 1e-7)).max() \
        <= 1e-6 * np.abs(ch.elastic_forces(q)).max()


DONLY = {name: {k: (v if k == name else 0.0) for k, v in DAMP.items()} for name in DAMP}


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("part", list(DONLY) + ["all"])
def test_dissipative_forces_are_minus_rayleigh_gradient(part, closed):
    ch = chain(closed=closed, **DONLY.get(part, {}))
    rng = np.random.default_rng(5)
    q = random_state(ch, rng)
    v = rng.standard_normal(ch.n2)
    Qd = ch.dissipative_forces(q, v)
    assert np.abs(Qd).max() > 0
    assert np.abs(Qd + grad(lambda x: ch.rayleigh(q, x), v, 1e-4)).max() <= 1e-6 * np.abs(Qd).max()
    # Phi is quadratic in v: Euler's identity v . Q_d = -2 Phi, and Phi >= 0
    assert v @ Qd == pytest.approx(-2 * ch.rayleigh(q, v), rel=1e-10)
    assert ch.rayleigh(q, v) > 0
    Q = ch.elastic_forces(q)                              # one pass sums the link "stresses" first: round-off of Q
    assert np.allclose(ch.forces(q, v), Q + Qd, rtol=0, atol=1e-12 * np.abs(Q).max())


def test_printed_joint_damping_is_not_the_rayleigh_gradient():
    ch_e = chain(**DONLY["joint_damping"])
    ch_p = chain(joint_damping_form="printed", **DONLY["joint_damping"])
    rng = np.random.default_rng(6)
    q, v = random_state(ch_e, rng), rng.standard_normal(ch_e.n2)
    Qe, Qp = ch_e.dissipative_forces(q, v), ch_p.dissipative_forces(q, v)
    assert np.abs(Qe - Qp).max() > 0.1 * np.abs(Qe).max()
    assert Qe.sum() == pytest.approx(0.0, abs=1e-12 * np.abs(Qe).max())   # internal: no net force


def test_mass_matrix_equals_quadrature_of_kinetic_energy():
    ch = chain(n=5)
    rng = np.random.default_rng(7)
    v = rng.standard_normal(ch.n2)
    x, wq = np.polynomial.legendre.leggauss(8)
    h = shape_functions(x, PIN_L)
    vu, vw = ch.split(v)
    Uperp = np.einsum("ix,inc->nxc", h, vu)                 # (n, nodes, 2)
    Upar = vw[0][:, None] + vw[1][:, None] * x[None]
    T = 0.5 * ch.m / 2 @ (((Uperp ** 2).sum(2) + Upar ** 2) @ wq)   # (1.134)
    assert ch.kinetic_energy(v) == pytest.approx(T, rel=1e-13)
    M = ch.mass_matrix.toarray()
    assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)
    # the per-pin block is the consistent Hermite beam mass in raw end coordinates (chain-models-1 4.4)
    B = np.array([[0.5, 0.5, 0, 0], [-0.5, 0.5, 0, 0], [1 / PIN_L, -1 / PIN_L, 1, 0], [1 / PIN_L, -1 / PIN_L, 0, 1]])
    i = ch.dof_index[0, 0:8:2]
    raw = B.T @ M[np.ix_(i, i)] @ B
    l, m = PIN_L, ch.m[0]
    ref = m / 420 * np.array([[156, 54, 22 * l, -13 * l], [54, 156, 13 * l, -22 * l],
                              [22 * l, 13 * l, 4 * l ** 2, -3 * l ** 2], [-13 * l, -22 * l, -3 * l ** 2, 4 * l ** 2]])
    assert np.allclose(raw, ref, rtol=1e-13, atol=0)


def test_raw_end_coordinates_round_trip():
    ch = chain(n=5)
    q = random_state(ch, np.random.default_rng(18), amp=1e-2)
    far, near, sf, sn = ch.to_raw(q)
    assert np.allclose(ch.from_raw(far, near, sf, sn), q, rtol=0, atol=1e-15)
    pins = np.arange(5)
    assert np.allclose(ch.axis_points(q, pins, -np.ones(5)), far) and np.allclose(ch.axis_points(q, pins, np.ones(5)), near)
    u, _ = ch.split(q)
    for x, slope in ((-1.0, sf), (1.0, sn)):                 # dU_perp/ds = (2/l) sum u_i h_i'(xi) (1.142)
        assert np.allclose(2 / PIN_L * np.einsum("i,inc->nc", shape_slopes(np.array(x), PIN_L), u), slope)


def test_free_pin_frequencies():
    """Pins without plates (chain-models-1 8.5): axial 12 c_p/m, bending 720 A/(m l^3) (exact beam: 500.6)
    and 8400 A/(m l^3) in each of the two section directions, at the rest state."""
    free = dict(plate_stiffness=0.0, plate_bending_stiffness=0.0, plate_torsion_stiffness=0.0)
    ch = chain(n=5, **free)
    q = ch.rest_state(ring(ch) * 3.0)
    lam = sl.eigh(-ch.stiffness_matrix(q).toarray(), ch.mass_matrix.toarray(), eigvals_only=True)
    m, l = ch.m, PIN_L
    ref = np.concatenate([12 * ch.c_pin / m] + [k * A / (m * l ** 3) for k in (720, 8400) for A in (ch.A_tau, ch.A_n)])
    nonzero = np.sort(lam[np.abs(lam) > 1e-9 * lam.max()])
    assert nonzero == pytest.approx(np.sort(ref), rel=1e-10)
    assert lam.size - nonzero.size == 5 * ch.n_pins      # u_0 (2), u_1 (2), w_0 of each pin are free


def test_accel_solves_the_mass_matrix():
    ch = chain()
    rng = np.random.default_rng(8)
    q, v = random_state(ch, rng), rng.standard_normal(ch.n2)
    ext = rng.standard_normal(ch.n2)
    a = ch.accel(q, v, ext)
    assert np.allclose(ch.mass_matrix @ a, ch.forces(q, v) + ext, rtol=1e-11, atol=1e-9)


def rotate_k(ch, q, angle):
    """Rotate every in-plane vector of the state about k by ``angle``."""
    c, s = np.cos(angle), np.sin(angle)
    u, w = ch.split(q)
    return ch.join(np.stack([c * u[..., 0] - s * u[..., 1], s * u[..., 0] + c * u[..., 1]], -1), w)


def test_translations_and_rotation_about_k_are_exact_invariants():
    ch = chain()
    rng = np.random.default_rng(9)
    eq = chain(pitch=np.full(8, PITCH))
    rest = eq.rest_state(ring(eq), axial=np.full(8, 0.002))
    assert eq.potential_energy(rest) == pytest.approx(0.0, abs=1e-20)
    scale = np.abs(eq.elastic_forces(random_state(eq, rng))).max()
    for q in (rest, rotate_k(eq, rest, 0.7)):
        assert np.abs(eq.elastic_forces(q)).max() <= 1e-9 * scale
    q = random_state(ch, rng)
    Pi, Q = ch.potential_energy(q), ch.elastic_forces(q)
    shift = np.zeros(ch.n2)
    idx = ch.dof_index
    shift[idx[:, 0]], shift[idx[:, 1]], shift[idx[:, 8]] = 0.3, -0.2, 0.05   # translate by (0.3, -0.2, 0.05) m
    for moved in (q + shift, rotate_k(ch, q, 0.7)):
        assert ch.potential_energy(moved) == pytest.approx(Pi, rel=1e-9)
    assert np.allclose(ch.elastic_forces(q + shift), Q, rtol=0, atol=1e-7 * np.abs(Q).max())
    assert np.allclose(ch.elastic_forces(rotate_k(ch, q, 0.7)), rotate_k(ch, Q, 0.7), rtol=0,
                       atol=1e-7 * np.abs(Q).max())
    # rigid velocities (translation, spin about k) dissipate nothing at a deformed state
    u, _ = ch.split(q)
    spin = ch.join(np.stack([-u[..., 1], u[..., 0]], -1), np.zeros((2, ch.n_pins)))
    trans = np.zeros(ch.n2)
    trans[idx[:, 0]], trans[idx[:, 1]], trans[idx[:, 8]] = 1.0, 2.0, -1.0
    for vel in (spin, trans):
        assert ch.rayleigh(q, vel) == pytest.approx(0.0, abs=1e-12 * ch.rayleigh(q, rng.standard_normal(ch.n2)))


def tilted_straight_chain(ch, theta, axis):
    """The straight rest chain along x1 rotated rigidly by ``theta`` about the in-plane ``axis`` (0: e1, 1: e2)."""
    n = ch.n_pins
    X = np.column_stack([PITCH * np.arange(n), np.zeros(n), np.zeros(n)])
    c, s = np.cos(theta), np.sin(theta)
    R = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) if axis == 0 else np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    centre, k = X @ R.T, R[:, 2]
    q = ch.rest_state(centre[:, :2], centre[:, 2])
    u, w = ch.split(q)
    u[1] = PIN_L / 2 * k[:2]
    w[1] = PIN_L / 2 * k[2]
    return q


@pytest.mark.parametrize("axis", [0, 1])
def test_rotation_about_an_inplane_axis_is_invariant_to_first_order(axis):
    """Linearised strains (1.140), (1.146), (1.149): forces of a rigid tilt by theta scale as theta^2."""
    ch = chain(n=6, closed=False, pitch=np.full(5, PITCH))
    F = [np.abs(ch.elastic_forces(tilted_straight_chain(ch, th, axis))).max() for th in (1e-3, 1e-4)]
    stiff = np.abs(ch.elastic_forces(tilted_straight_chain(ch, 0, 0) + 1e-3 * np.eye(ch.n2)[3])).max()
    assert F[0] < 1e-2 * stiff
    assert F[0] / F[1] == pytest.approx(100, rel=1e-2)


def test_shear_of_a_uniformly_tilted_link():
    """Spec 2.5 (reviewed): both pins tilted by theta give 6 a theta^2 / L per plate (derived), 4x that (printed)."""
    kw = dict(n=4, closed=False, pitch=np.full(3, PITCH), **ONLY["link_shear"])
    theta = 1e-3
    for conv, factor in (("derived", 1.0), ("printed", 4.0)):
        ch = chain(shear_convention=conv, **kw)
        q = ch.rest_state(np.column_stack([PITCH * np.arange(4), np.zeros(4)]))
        u, _ = ch.split(q)
        u[1, :, 0] = theta * PIN_L / 2
        a_total = ch.c_shear[:3] * PITCH / 12
        assert ch.potential_parts(q)["link_shear"] == pytest.approx(factor * 6 * theta ** 2 / PITCH * a_total.sum(),
                                                                   rel=1e-12)
        assert np.allclose(ch.outputs(q)["chain.shear"], theta, rtol=1e-12)


def test_straight_segment_carries_end_tension_in_every_link():
    """Static solve of an open segment pulled by +-T at its end pins (forces split over both pin ends)."""
    n, T = 7, 2000.0
    ch = chain(n=n, closed=False, seed=11)
    q = ch.rest_state(np.column_stack([np.cumsum(np.r_[0.0, ch.L[:n - 1]]), np.zeros(n)]))
    Qe = ch.point_loads([0, 0, n - 1, n - 1], [-1, 1, -1, 1], [[-T / 2, 0, 0]] * 2 + [[T / 2, 0, 0]] * 2)
    idx = ch.dof_index
    # the six rigid-body modes: translations, rotations about k, e1 (uniform u_1y) and e2 (w_0 linear in x1)
    fixed = [idx[0, 0], idx[0, 1], idx[0, 8], idx[0, 3], idx[n - 1, 1], idx[n - 1, 8]]
    free = np.setdiff1d(np.arange(ch.n2), fixed)
    for _ in range(10):
        r = ch.elastic_forces(q) + Qe
        if np.abs(r[free]).max() < 1e-9 * T:
            break
        J = np.column_stack([(ch.elastic_forces(q + 1e-8 * e) - ch.elastic_forces(q - 1e-8 * e))[free] / 2e-8
                             for e in np.eye(ch.n2)[free]])
        q[free] -= np.linalg.solve(J, r[free])
    r = ch.elastic_forces(q) + Qe
    assert np.abs(r).max() < 1e-9 * T          # reactions at the fixed coordinates vanish too
    out = ch.outputs(q)
    plate_T = out["chain.plate_tension"].reshape(n - 1, ch.kmax)
    eps_max = 0.0
    for p in range(n - 1):
        k = np.flatnonzero(ch.plate_mask[p])
        chord = ch.axis_points(q, np.full(k.size, p + 1), ch.plate_xi[p, k]) \
            - ch.axis_points(q, np.full(k.size, p), ch.plate_xi[p, k])
        # in-plane resultant of the plate forces along their chords (1.66); at the order of (1.140) plates
        # pull in the plane, the axial balance is the shear term's
        resultant = plate_T[p, k] @ chord[:, :2] / ch.L[p]
        assert resultant == pytest.approx([T, 0], rel=1e-9, abs=1e-9 * T)
        eps_max = max(eps_max, np.abs(np.linalg.norm(chord, axis=1) / ch.L[p] - 1).max())
    # the link tension output sum_k c^k Delta^k is the same force to the order of the linearisation (1.140)
    assert np.abs(out["chain.link_tension"] / T - 1).max() < 2 * eps_max


def test_point_loads_are_the_virtual_work_of_forces_and_moments():
    ch = chain(n=5)
    rng = np.random.default_rng(12)
    q = random_state(ch, rng)
    pins, xi = np.array([0, 3, 3, 4]), np.array([-1.0, 0.3, 1.0, -0.6])
    F, M = rng.standard_normal((4, 3)), rng.standard_normal((4, 2))
    Q = ch.point_loads(pins, xi, F, M)
    dq = rng.standard_normal(ch.n2)
    h = 1e-6

    def tangent(x):                                           # t_perp = (2/l) dU_perp/dxi (1.142)
        return 2 / PIN_L * (ch.axis_points(x, pins, xi + h) - ch.axis_points(x, pins, xi - h))[:, :2] / (2 * h)

    dU = (ch.axis_points(q + h * dq, pins, xi) - ch.axis_points(q - h * dq, pins, xi)) / (2 * h)
    dt = (tangent(q + 1e-3 * dq) - tangent(q - 1e-3 * dq)) / 2e-3
    dtheta = np.column_stack([-dt[:, 1], dt[:, 0]])           # k x dt
    assert Q @ dq == pytest.approx(np.sum(F * dU) + np.sum(M * dtheta), rel=1e-7)
    # spec 2.7 at the ends: a far-end moment acts on u_1 with (2/l) M x k and on u_2 with M x k
    Qm = ch.point_loads([2], [-1.0], np.zeros((1, 3)), [[0.0, 1.0]])
    u, _ = ch.split(Qm)
    assert np.allclose(u[1, 2], [2 / PIN_L, 0]) and np.allclose(u[2, 2], [1, 0]) and np.allclose(u[3, 2], 0)
    assert np.allclose(shape_slopes(np.array([-1.0, 1.0]), PIN_L)[2:], [[PIN_L / 2, 0], [0, PIN_L / 2]])


@pytest.mark.parametrize("closed", [True, False])
def test_jacobian_pattern_contains_finite_differences(closed):
    ch = chain(n=9, closed=closed)
    rng = np.random.default_rng(13)
    q, v = random_state(ch, rng), rng.standard_normal(ch.n2)
    Jq = grad(lambda x: ch.forces(x, v), q, 1e-7).T
    Jv = grad(lambda x: ch.forces(q, x), v, 1e-3).T
    outside = ~ch.jac_sparsity.toarray()
    for J in (Jq, Jv):
        assert np.abs(J[outside]).max() <= 1e-6 * np.abs(J).max()
    assert sp.issparse(ch.jac_sparsity) and ch.jac_sparsity.nnz == 50 * 10 * ch.n_pins - (0 if closed else 600)


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("part", list(ONLY))
def test_stiffness_matrix_equals_finite_differences(part, closed):
    """Per block of coordinates (u_0, u_1, u_2/u_3, w), so that the small bisector-rotation terms count."""
    ch = chain(closed=closed, **ONLY[part])
    q = random_state(ch, np.random.default_rng(16), amp=1e-3)
    K = ch.stiffness_matrix(q)
    Kfd = grad(ch.elastic_forces, q, 1e-8).T
    Kd = K.toarray()
    assert np.allclose(Kd, Kd.T, rtol=0, atol=1e-12 * np.abs(Kd).max())         # a Hessian
    assert not np.any(Kd[~ch.jac_sparsity.toarray()])
    d = ch.dof_index
    groups = [d[:, :2], d[:, 2:4], d[:, 4:8], d[:, 8:]]
    for a in groups:
        for b in groups:
            blk = np.ix_(a.ravel(), b.ravel())
            scale = np.abs(Kfd[blk]).max()
            if scale > 1e-9 * np.abs(Kfd).max():
                assert np.abs(Kd[blk] - Kfd[blk]).max() <= 1e-6 * scale


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("form", ["exact", "printed"])
def test_damping_matrix_equals_finite_differences(form, closed):
    ch = chain(closed=closed, joint_damping_form=form)
    rng = np.random.default_rng(17)
    q, v = random_state(ch, rng, amp=1e-3), rng.standard_normal(ch.n2)
    C = ch.damping_matrix(q).toarray()
    Cfd = grad(lambda x: ch.dissipative_forces(q, x), v, 1.0).T       # Q_d is linear in v
    assert np.abs(C - Cfd).max() <= 1e-9 * np.abs(Cfd).max()
    if form == "exact":
        assert np.allclose(C, C.T, rtol=0, atol=1e-12 * np.abs(C).max())
        assert np.all(np.linalg.eigvalsh(C) <= 1e-10 * np.abs(C).max())   # C = -d2 Phi/dv2
    # at rest the dissipative forces vanish with their q-derivative: K, C are the exact linearisation
    J = grad(lambda x: ch.forces(x, np.zeros(ch.n2)), q, 1e-8).T
    assert np.abs(J - ch.stiffness_matrix(q).toarray()).max() <= 1e-6 * np.abs(J).max()


def test_outputs_and_layout():
    ch = chain()
    rng = np.random.default_rng(14)
    q = random_state(ch, rng)
    out = ch.outputs(q)
    assert {s.name for s in ch.output_specs} == set(out)
    for s in ch.output_specs:
        assert out[s.name].shape == (s.size,)
    assert sum(b.size for b in ch.blocks) == ch.n2 == 10 * ch.n_pins
    assert np.allclose(out["chain.link_tension"], out["chain.plate_tension"].reshape(ch.n_links, -1).sum(1))
    # bending energy from the end moments: M and kappa are linear along the pin (2.4)
    parts = chain(**ONLY["pin_bending"]).potential_parts(q)
    Mf = out["chain.pin_moment_far"].reshape(-1, 2)
    Mn = out["chain.pin_moment_near"].reshape(-1, 2)
    A = np.array([ch.A_n, ch.A_tau])
    kf, kn = Mf / A, Mn / A
    Pi = PIN_L / 4 * np.sum(2 / 3 * (Mf * kf + Mn * kn) + 1 / 3 * (Mf * kn + Mn * kf))
    assert Pi == pytest.approx(parts["pin_bending"], rel=1e-12)


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("forms", [("derived", "exact"), ("printed", "printed")])
def test_compiled_kernel_equals_numpy_twin(closed, forms):
    kw = dict(closed=closed, shear_convention=forms[0], joint_damping_form=forms[1])
    ref, fast = chain(**kw), chain(use_numba=True, **kw)
    if fast.backend != "numba":
        pytest.skip("numba not installed")
    rng = np.random.default_rng(15)
    for _ in range(3):
        q, v = random_state(ref, rng), rng.standard_normal(ref.n2)
        Q = ref.elastic_forces(q)
        Qd = ref.dissipative_forces(q, v)
        assert np.allclose(fast.elastic_forces(q), Q, rtol=0, atol=1e-12 * np.abs(Q).max())
        assert np.allclose(fast.dissipative_forces(q, v), Qd, rtol=0, atol=1e-12 * np.abs(Qd).max())
        assert np.allclose(fast.forces(q, v), ref.forces(q, v), rtol=0, atol=1e-12 * np.abs(Q).max())


def test_bad_input_is_reported():
    with pytest.raises(InputError):
        chain(pitch=np.full(3, PITCH))
    with pytest.raises(InputError):
        chain(shear_convention="other")
    with pytest.raises(InputError):
        chain(plate_xi=np.full((8, 6), 1.5))


def free_vibration(n_periods):
    """Closed ring of 6 pins at rest plus a random perturbation, no load, no damping; DOP853 at rtol 1e-10.

    Softer pins and stiffer plate bending/torsion than :data:`STIFF` narrow the band of frequencies
    (lowest nonzero 1.7e4 rad/s, highest 6.4e5 rad/s) so that an explicit run stays short.
    """
    n = 6
    soft = dict(pin_axial_stiffness=2e6, pin_bending_tau=1.0, pin_bending_n=0.7, plate_torsion_stiffness=50.0,
                plate_bending_stiffness=10.0, plate_stiffness=3e6)
    ch = chain(n=n, pitch=np.full(n, PITCH), seed=21, use_numba=True, **{k: 0.0 for k in DAMP}, **soft)
    rng = np.random.default_rng(22)
    q0 = ch.rest_state(ring(ch)) + 2e-6 * rng.standard_normal(ch.n2)
    v0 = 0.05 * rng.standard_normal(ch.n2)
    # lowest nonzero frequency of the linearisation at rest (the in-plane mechanism modes have none)
    rest = ch.rest_state(ring(ch))
    K = -grad(ch.elastic_forces, rest, 1e-8).T
    lam = np.sort(np.real(np.linalg.eigvals(np.linalg.solve(ch.mass_matrix.toarray(), (K + K.T) / 2))))
    omega = np.sqrt(lam[lam > 1e-6 * lam.max()][0])
    t_end = n_periods * 2 * np.pi / omega
    y0 = np.r_[q0, v0]
    sol = solve_ivp(lambda t, y: np.r_[y[ch.n2:], ch.accel(y[:ch.n2], y[ch.n2:])], (0, t_end), y0,
                    method="DOP853", rtol=1e-10, atol=1e-14, dense_output=False, t_eval=np.linspace(0, t_end, 21))
    assert sol.success
    E = [ch.kinetic_energy(y[ch.n2:]) + ch.potential_energy(y[:ch.n2]) for y in sol.y.T]
    P = [ch.momentum(y[:ch.n2], y[ch.n2:]) for y in sol.y.T]
    # momentum exchanged between pins: the scale of the round-off in the sums of internal forces
    flow = max(np.abs(ch.mass_matrix @ y[ch.n2:]).sum() for y in sol.y.T)
    return ch, np.array(E), P, flow


def check_conservation(E, P, flow):
    assert np.abs(E / E[0] - 1).max() < 1e-6
    p0, L0 = P[0]
    for p, Lk in P:
        assert np.abs(p - p0).max() < 1e-12 * flow        # linear invariants: round-off
        assert Lk == pytest.approx(L0, rel=1e-6)          # quadratic invariant: to the tolerance


def test_free_ring_conserves_momentum_and_energy():
    ch, E, P, flow = free_vibration(10)
    assert E[0] > 0
    check_conservation(E, P, flow)


@pytest.mark.slow
def test_free_ring_conserves_energy_over_100_periods():
    ch, E, P, flow = free_vibration(100)
    check_conservation(E, P, flow)
