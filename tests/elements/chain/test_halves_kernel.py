"""Compiled A5 force pass (halves_kernel) against its numpy twin, and the element-by-element Jacobian against
central differences of the numpy forces, column by column."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from tests.elements.chain.test_halves import DAMP, chain, random_state

pytest.importorskip("numba")

CLOSED_HOLES = dict(hole_clearance=0.0, stopper_play=0.0, roll_tie=1e9)     # 8 pins at 45 degrees: holes closed
CASES = {
    "A4 closed, linear-saturated": (dict(plate_model="A4", friction_coefficient=0.1, **DAMP), 0.05),
    "A4 open, smooth": (dict(plate_model="A4", closed=False, friction_coefficient=0.1, friction_law="smooth",
                             **DAMP), 0.05),
    "A3 closed": (dict(plate_model="A3", friction_coefficient=0.1, **DAMP), 0.05),
    "A3-keep open, arctan near zero slip": (dict(plate_model="A3-keep", closed=False, friction_coefficient=0.1,
                                                 friction_law="arctan", **DAMP), 1e-9),
    "holes closed, stoppers, tie, tanh near zero slip": (dict(friction_coefficient=0.1, friction_law="tanh",
                                                              **CLOSED_HOLES, **DAMP), 1e-9),
}


def state(ch, v_scale, seed=12):
    rng = np.random.default_rng(seed)
    return random_state(ch, rng, amp=2e-5), v_scale * rng.standard_normal(ch.n2)


def slot_error(ch, ref, test):
    """Largest error of each of the 21 coordinate slots relative to that slot's largest reference force."""
    errs = [np.abs(ref[i] - test[i]).max() / np.abs(ref[i]).max() for i in ch.dof_index.T if np.abs(ref[i]).max() > 0]
    return max(errs)


@pytest.mark.parametrize("case", CASES)
def test_compiled_forces_equal_numpy_twin(case):
    kw, v_scale = CASES[case]
    fast, ref = chain(**kw), chain(use_numba=False, **kw)
    assert fast.backend == "numba" and ref.backend == "numpy"
    q, v = state(ref, v_scale)
    Qf, Qr = fast.forces(q, v), ref.forces(q, v)
    assert slot_error(ref, Qr, Qf) < 1e-12
    out = ref.outputs(q, v)
    roll = out["chain.roll_force"]
    assert roll.max() > 0 and roll.min() == 0                                 # contacts on and off
    if kw.get("plate_model", "A4") == "A4":
        assert len(set(out["chain.plate_state"])) > 2                         # several plate states
    if v_scale < 1e-6:                                                        # friction below its series threshold
        assert np.abs(out["chain.half_slip"]).max() < 1e-4 * fast.v0
    if "hole_clearance" in kw:
        contacts = ref.potential_parts(q, ("contacts",))["contacts"]
        no_holes = chain(use_numba=False, **{**kw, "hole_stiffness": 0.0}).potential_parts(q, ("contacts",))["contacts"]
        assert contacts > no_holes > 0 and ref.potential_parts(q)["stoppers"] > 0


@pytest.mark.parametrize("case", CASES)
def test_compiled_dissipated_power_equals_numpy_twin(case):
    """The compiled pass's dissipated power (accumulated element by element) equals ``2 Phi - P_fr`` of the numpy
    twin and the power ``-(Q(q, v) - Q(q, 0)) . v`` of the damping and friction forces, to 1e-10."""
    kw, v_scale = CASES[case]
    fast, ref = chain(**kw), chain(use_numba=False, **kw)
    q, v = state(ref, v_scale)
    Q, D = fast.forces_and_dissipation(q, v)
    Qr, Dr = ref.forces_and_dissipation(q, v)
    assert slot_error(ref, Qr, Q) < 1e-12
    D_work = -float((fast.forces(q, v) - fast.forces(q, 0 * v)) @ v)
    assert D > 0 and Dr == pytest.approx(2 * ref.rayleigh(q, v) - ref.outputs(q, v)["chain.friction_power"].sum())
    assert D == pytest.approx(Dr, rel=1e-10) and D == pytest.approx(D_work, rel=1e-9)


def column_differences(ref, f, x0, steps):
    """Central differences of ``f(x)`` over every coordinate of ``x0`` with the steps ``steps`` (n,)."""
    out = np.empty((ref.n2, ref.n2))
    for j in range(ref.n2):
        e = np.zeros(ref.n2)
        e[j] = steps[j]
        out[:, j] = (f(x0 + e) - f(x0 - e)) / (2 * steps[j])
    return out


def reference_jacobian(ref, q, v):
    """``dQ/dq``: differences of ``forces`` (step ``1e-7 max(|q|, l)``); ``dQ/dv``: of the dissipative forces
    (linear in ``v``: unit steps, exact but for round-off) plus of the friction forces (step ``1e-2 v_0``: the
    friction laws bend on the scale ``v_0`` of the slip, whatever the speed of the chain)."""
    K = column_differences(ref, lambda x: ref.forces(x, v), q, 1e-7 * np.maximum(np.abs(q), ref.l))
    C = column_differences(ref, lambda y: ref.dissipative_forces(q, y), v, np.ones(ref.n2))
    C += column_differences(ref, lambda y: ref.friction_forces(q, y), v, np.full(ref.n2, 1e-2 * ref.v0))
    return K, C


def reference_round_off(ref, q, v):
    """Round-off bound of ``reference_jacobian``'s ``dQ/dv`` per row ``(n2, 1)``: its friction differences subtract
    two evaluations of the row's friction force, each rounded to about an ulp of its size ``|F_r|`` (a sum of terms
    up to 1e5 N at the link ends), over ``2 h`` (``h = 1e-2 v_0``): ``2 eps |F_r| / h`` allows two ulps each (the
    largest found was 0.65 of ``eps |F_r| / h``)."""
    return 2 * np.finfo(float).eps * np.abs(ref.friction_forces(q, v))[:, None] / (1e-2 * ref.v0)


def velocity_columns_agree(C, ref_v, noise):
    """Entry by entry ``|C - ref_v| <= 1e-4`` of the column's largest reference entry plus the reference's own
    round-off ``noise``."""
    return np.abs(C - ref_v) <= 1e-4 * np.abs(ref_v).max(0) + noise


JAC_CASES = ["A4 closed, linear-saturated", "A4 open, smooth", "holes closed, stoppers, tie, tanh near zero slip"]


@pytest.mark.parametrize("case", JAC_CASES)
def test_element_jacobian_equals_central_differences(case):
    """All columns of both matrices, relative to each column's largest entry, everywhere (so also zero outside
    ``jac_sparsity``): dQ/dq with central link differences to 1e-5, forward to 1e-3 (found 2e-6, 3e-4), with the
    exact link blocks to 1e-4: there the reference's own error shows, 3.5e-5 in the small slope columns of the open
    segment (its difference quotients with steps h and h/10 differ by 5e-4 of the entry: the round-off of the pins'
    large forces), which the central scheme shares (same steps, same function).  dQ/dv (exact dampers, the friction
    laws' own slopes) to 1e-4 of the column plus the reference's round-off (:func:`reference_round_off`): found
    3.4e-5 of the column near zero slip (the reference's truncation, ``tanh^(3)(0) h^2 / 6 = 3.3e-5`` of the slope),
    and up to 0.65 of the round-off bound where a saturated law leaves a damping entry of 0.0022 N s/m in a row of
    1e5 N of friction (1.46e-6 against a bound of 5.5e-6).  Outside the columns of pure round-off (largest entry
    under 100 noise bounds: 0 to 7 of 168), the check still fails on an error of 1e-3 of the column in the entry
    closest to its bound, and in every column's largest entry.  The exact link blocks against link-only
    differences, without that round-off: the next test."""
    kw, v_scale = CASES[case]
    ch, ref = chain(**kw), chain(use_numba=False, **kw)
    rng = np.random.default_rng(3)
    q, v = random_state(ref, rng, amp=2e-6), v_scale * rng.standard_normal(ref.n2)
    ref_q, ref_v = reference_jacobian(ref, q, v)
    noise = reference_round_off(ref, q, v)
    scale_q, scale_v = np.abs(ref_q).max(0), np.abs(ref_v).max(0)
    for scheme, tol_q in (("analytic", 1e-4), ("central", 1e-5), ("forward", 1e-3)):
        K, C = ch.jacobian(q, v, scheme=scheme)
        assert np.all(np.abs(K.toarray() - ref_q).max(0) <= tol_q * scale_q)
        assert np.all(velocity_columns_agree(C.toarray(), ref_v, noise))
    C = C.toarray()
    cols = np.flatnonzero(scale_v > 100 * noise.max())                           # not the round-off columns
    slack = (np.abs(C - ref_v)[:, cols] - 1e-4 * scale_v[cols]) / (1e-4 * scale_v[cols] + noise)
    r, c = np.unravel_index(np.argmax(slack), (ref.n2, cols.size))              # the entry closest to its bound
    c = cols[c]
    C[r, c] += 1e-3 * scale_v[c]
    assert not velocity_columns_agree(C, ref_v, noise)[r, c]
    C[r, c] -= 1e-3 * scale_v[c]
    rows = np.abs(ref_v[:, cols]).argmax(0)
    bad = C[rows, cols] + 1e-3 * scale_v[cols]
    caught = np.abs(bad - ref_v[rows, cols]) > 1e-4 * scale_v[cols] + noise[rows, 0]
    assert caught.all()
    assert ch.jacobian(q, v, damping=False)[1] is None


@pytest.mark.parametrize("case", CASES)
def test_exact_link_blocks_equal_the_link_differences(case):
    """The exact link blocks (``scheme="analytic"``) against central differences of the same compiled link passes
    (``"central"``; the pins' blocks are the same differences in both), and the tension and power gradients that
    come with them: the difference is the central differences' error, ``O(h^2)`` plus round-off (found 6e-12 to
    1.5e-10 of the largest entry)."""
    kw, v_scale = CASES[case]
    ch = chain(**kw)
    q, v = state(ch, v_scale)
    exact, diff = ch.jacobian_and_power_gradient(q, v, "analytic"), ch.jacobian_and_power_gradient(q, v, "central")
    for a, b in zip(exact, diff):
        a, b = (a.toarray(), b.toarray()) if hasattr(a, "toarray") else (a, b)
        assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max()


def test_bad_scheme_is_reported():
    ch = chain()
    with pytest.raises(InputError, match="scheme"):
        ch.jacobian(np.zeros(ch.n2), np.zeros(ch.n2), scheme="complex")


@pytest.mark.parametrize("case", JAC_CASES)
def test_power_gradient_of_the_jacobian_pass(case):
    """``dD/dq``, ``dD/dv`` of the dissipated power, accumulated from the element passes of the Jacobian, against
    central differences of the compiled pass's ``D`` over every coordinate (steps as the reference Jacobian's; over
    ``v`` extrapolated from the steps ``1e-2 v_0`` and ``5e-3 v_0``: near zero slip the plain differences are off
    by 5.1e-5 and 1.3e-5, their truncation, against the exact slopes of the friction laws), relative to the
    largest entry, to 1e-8 (found 5e-10 over ``q``, 9e-10 over ``v``); and against the chain rule of the matrices,
    ``-(dQ_nc/dq)^T v`` and ``-(Q_nc + (dQ/dv)^T v)`` (``Q_nc`` the damping and friction forces), to 1e-3: that
    product carries the matrices' difference errors (found 2.7e-4 near zero slip, where the power's own
    differences agree with those of ``D`` to 1e-8)."""
    kw, v_scale = CASES[case]
    ch = chain(**kw)
    rng = np.random.default_rng(3)
    q, v = random_state(ch, rng, amp=2e-6), v_scale * rng.standard_normal(ch.n2)
    Jq, Jv, dDq, dDv = ch.jacobian_and_power_gradient(q, v)
    D = lambda qq, vv: ch.forces_and_dissipation(qq, vv)[1]  # noqa: E731
    fd_q = np.array([(D(q + e, v) - D(q - e, v)) / (2 * e.max())
                     for e in np.diag(1e-7 * np.maximum(np.abs(q), ch.l))])
    fd_v = [np.array([(D(q, v + e) - D(q, v - e)) / (2 * e.max()) for e in np.diag(np.full(ch.n2, h * ch.v0))])
            for h in (1e-2, 5e-3)]
    fd_v = (4 * fd_v[1] - fd_v[0]) / 3                                             # Richardson: O(h^4)
    assert np.abs(dDq).max() > 0 and np.abs(dDv).max() > 0
    Q_nc = ch.forces(q, v) - ch.forces(q, 0 * v)
    Kd = Jq - ch.jacobian(q, 0 * v, damping=False)[0]
    chain_q, chain_v = -(Kd.T @ v), -(Q_nc + Jv.T @ v)
    err_q, err_v = np.abs(dDq - fd_q).max() / np.abs(fd_q).max(), np.abs(dDv - fd_v).max() / np.abs(fd_v).max()
    assert err_q <= 1e-8 and err_v <= 1e-8
    assert np.abs(dDq - chain_q).max() <= 1e-3 * np.abs(chain_q).max()
    assert np.abs(dDv - chain_v).max() <= 1e-3 * np.abs(chain_v).max()


@pytest.mark.parametrize("law", ["linear-saturated", "smooth", "arctan", "smoothed", "tanh"])
def test_compiled_law_slope_equals_the_numpy_slope(law):
    """``halves_kernel._slope`` (the pins' velocity blocks) against :func:`friction.friction_slope` to 1e-14 of
    ``f_0 / v_0``, on speeds across the knees, and against central differences of the law ``psi(v) v`` away from
    its kinks (step 1e-7 v_0, to 1e-6)."""
    from cvtfem.elements.chain.halves_kernel import SMOOTH_EPS, _slope
    from cvtfem.elements.contact.friction import friction_gain, friction_slope
    from cvtfem.elements.contact.kernels import LAW_CODES
    f0, v0 = 0.1, 1e-3
    v = v0 * np.concatenate([[0.0, 1e-6], np.linspace(0.013, 3.01, 300)])
    got = np.array([_slope(x, f0, v0, LAW_CODES[law], SMOOTH_EPS) for x in v])
    assert np.abs(got - friction_slope(v, f0, v0, law, SMOOTH_EPS)).max() <= 1e-14 * f0 / v0
    x = v[2:] / v0
    smooth = (np.abs(x - 1) > 1e-3) & (np.abs(x - 1 + SMOOTH_EPS) > 1e-3) & (np.abs(x - 1 - SMOOTH_EPS) > 1e-3)
    f = lambda s: friction_gain(s, f0, v0, law, SMOOTH_EPS) * s  # noqa: E731
    h = 1e-7 * v0
    fd = (f(v[2:] + h) - f(v[2:] - h)) / (2 * h)
    assert np.abs(got[2:] - fd)[smooth].max() <= 1e-6 * f0 / v0
