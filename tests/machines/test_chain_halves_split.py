"""The A5 chain's stiff split (``ChainHalvesCVT.stiff_split``): ``f_E + f_I = f`` to round-off on running states, the
friction solve books the kinetic energy it removes, the held forces' work rate, and ``strang-friction`` refuses a
system without a split."""
import numpy as np
import pytest

from cvtfem.analysis.steppers import make_stepper
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.contact.friction import friction_gain
from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene
from tests.machines.test_chain_halves_one_pass import F_APPL, RATIO, _states


@pytest.fixture(scope="module")
def model():
    scene = load_scene("band-6+2n")
    m = from_scene(scene, reference_geometry(), F_APPL, model="chain-A5", contact="hertz-refined")
    return m, m.placed_state(RATIO, scene.cvt.regime.input_speed)


def friction_rate(m, x):
    """``f_I`` at ``x``: ``M^-1`` times the halves' friction forces on the chain velocities, their dissipated power
    on the work row ``D - P_fr``."""
    ch, nc, n2 = m.family.chain, m.family.size, m.n2
    B, c = ch.friction_slips(x[:nc])
    s = B @ x[n2:n2 + nc]
    r = c * friction_gain(np.abs(s), ch.f0, ch.v0, ch.law) * s
    out = np.zeros(m.size)
    out[n2:n2 + nc] = -(ch.inverse_mass @ (B.T @ r))
    out[2 * n2 + m.control.size + 2] = r @ s
    return out


def test_explicit_plus_friction_equals_the_rhs(model):
    m, x0 = model
    assert m.stiff_split[:3] == (m.rhs_explicit, m.friction_solve, m.friction_hold)
    for x in _states(m, x0):
        f, fE, fI = m.rhs(0.0, x), m.rhs_explicit(0.0, x), friction_rate(m, x)
        assert np.abs(fI).max() > 1e-3 * np.abs(f).max()
        assert np.abs(f - fE - fI).max() <= 1e-12 * np.abs(f).max()


def test_friction_solve_is_backward_euler_and_books_the_kinetic_energy(model):
    m, x0 = model
    ch, nc, n2, iw = m.family.chain, m.family.size, m.n2, 2 * m.n2 + m.control.size + 2
    for x in _states(m, x0, 2):
        for h in (1e-7, 2e-6):
            x1, lus = m.friction_solve(0.0, x, h)
            assert np.array_equal(x1[:n2], x[:n2]) and np.array_equal(x1[n2 + nc:iw], x[n2 + nc:iw])
            dv = x1[n2:n2 + nc] - x[n2:n2 + nc]
            fI = friction_rate(m, x1)
            assert np.abs(dv - h * fI[n2:n2 + nc]).max() <= 1e-6 * np.abs(dv).max()
            T = [0.5 * y[n2:n2 + nc] @ (ch.mass_matrix @ y[n2:n2 + nc]) for y in (x, x1)]
            assert x1[iw] - x[iw] == pytest.approx(T[0] - T[1], rel=1e-9) and T[0] > T[1]
            # held forces: the accelerations and their power at another state
            d = (x1 - x) / h
            rate = m.friction_hold(x0, d)
            Mdv = ch.mass_matrix @ d[n2:n2 + nc]
            assert np.array_equal(rate[n2:n2 + nc], d[n2:n2 + nc])
            assert rate[iw] == pytest.approx(-Mdv @ x0[n2:n2 + nc], rel=1e-12)


def test_strang_friction_needs_the_split_and_runs_on_the_model(model):
    m, x0 = model
    with pytest.raises(InputError, match="StiffSplit"):
        solve(m.rhs, (0.0, 1e-7), x0, n2=m.n2, method="strang-friction", h=1e-7)
    res = solve(m, (0.0, 2e-7), x0, method="strang-friction", h=1e-7, scheme="frozen")
    assert res.success and np.all(np.isfinite(res.y))
    # the stepper of `cvtfem run` (the loop's split passed along)
    run = make_stepper("strang-friction", m.rhs, 0.0, x0, 2e-7, 1e-3, 1e-6, 1e-7, m.jac, m.n2,
                       split=m.stiff_split)
    while run.status == "running" and run.step():
        pass
    ref = solve(m, (0.0, 2e-7), x0, method="strang-friction", h=1e-7).y[:, -1]        # the default scheme
    assert run.status == "finished"
    # equal to the friction solves' tolerance (1e-6 v0 on the slips; Newton's start guess is the last solve's)
    assert np.abs(run.last.x1 - ref).max() <= 1e-7 * np.abs(ref).max()
