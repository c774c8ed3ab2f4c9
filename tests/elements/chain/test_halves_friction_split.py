"""The halves' internal friction split off (``ChainA5.friction_slips``, ``friction_step``): the slip map reproduces the
friction forces of the force pass, and the implicit friction step solves backward Euler with its dissipated work equal
to the kinetic energy it removes."""
import numpy as np
import pytest

from cvtfem.elements.contact.friction import friction_gain
from tests.elements.chain.test_halves import DAMP, chain
from tests.elements.chain.test_halves_kernel import CASES, state


@pytest.mark.parametrize("use_numba", [True, False])
@pytest.mark.parametrize("case", CASES)
def test_split_forces_equal_the_force_pass(case, use_numba):
    """``-B^T (c psi(|Bv|) Bv)`` = forces less the forces at ``f_0 = 0``, to round-off of the forces' size."""
    kw, v_scale = CASES[case]
    ch = chain(use_numba=use_numba, **kw)
    q, v = state(ch, v_scale)
    B, c = ch.friction_slips(q)
    s = B @ v
    F_split = -(B.T @ (c * friction_gain(np.abs(s), ch.f0, ch.v0, ch.law) * s))
    full, free = ch.forces(q, v), ch.without_friction().forces(q, v)
    assert np.abs(F_split).max() > 0 and np.all(c > 0)
    assert np.abs(F_split - (full - free)).max() <= 1e-13 * np.abs(full).max()


@pytest.mark.parametrize("law", ["tanh", "linear-saturated", "smoothed", "arctan"])
def test_friction_step_is_backward_euler_and_books_the_kinetic_energy(law):
    ch = chain(friction_coefficient=0.1, friction_law=law, **DAMP)
    q, v = state(ch, 0.02)                           # slips up to 50 v0 (v0 = 1e-3 m/s): stick and slip
    B, c = ch.friction_slips(q)
    M = ch.mass_matrix
    for h in (1e-7, 1e-5, 1e-3):                     # h |lambda| from about 1 to 1e5
        v1, W, its = ch.friction_step(B, c, v, h)
        s1 = B @ v1
        F = -(B.T @ (c * friction_gain(np.abs(s1), ch.f0, ch.v0, law) * s1))
        assert np.abs(M @ (v1 - v) - h * F).max() <= 1e-7 * h * np.abs(F).max()   # slips to 1e-8 v0
        dT = 0.5 * v @ (M @ v) - 0.5 * v1 @ (M @ v1)
        assert W == pytest.approx(dT, rel=1e-9) and W > 0
        assert its <= 80                            # LUs (66 at most: linear-saturated, h = 1e-7 s)


@pytest.mark.parametrize("case", CASES)
def test_compiled_slip_values_equal_the_numpy_reference(case):
    """The compiled rolling slips (:mod:`~cvtfem.elements.chain.halves_slips_kernel`, used once the CSR pattern is
    known) equal the numpy method's rows, forces and groups to 1e-12, at two states (the pattern reused)."""
    kw, v_scale = CASES[case]
    fast, ref = chain(use_numba=True, **kw), chain(use_numba=False, **kw)
    q0, _ = state(fast, v_scale)
    rng = np.random.default_rng(3)
    fast.friction_slips(q0)                                   # the first call builds the pattern in numpy
    for q in (q0, q0 + 1e-6 * rng.standard_normal(q0.size)):
        B, c, g = fast.friction_slips(q, groups=True)
        B0, c0, g0 = ref.friction_slips(q, groups=True)
        assert B.shape == B0.shape and np.array_equal(g, g0) and np.any(g >= 2)
        assert np.abs((B - B0).toarray()).max() <= 1e-12 * np.abs(B0).max()
        assert np.abs(c - c0).max() <= 1e-12 * np.abs(c0).max()
