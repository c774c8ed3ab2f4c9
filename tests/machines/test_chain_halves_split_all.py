"""All friction of variant (e) split off (the variant ``"all"`` of ``ChainHalvesCVT.stiff_split``): the compiled
pin-sheave slip map reproduces the H2 kernel's friction forces and power, ``f_E + f_I = f`` to round-off on running
states, the friction solve is backward Euler on all velocities (chain, shafts, sheaves) and books the kinetic energy it
removes, and ``strang-friction`` runs it (``friction="all"``)."""
import numpy as np
import pytest

from cvtfem.elements.chain import half_end_contact_kernel as HEK
from cvtfem.errors import InputError
from cvtfem.integrate import solve
from tests.machines.chain_checks import assert_friction_solve_all_is_backward_euler, friction_rate
from tests.machines.test_chain_halves_one_pass import _states
from tests.machines.test_chain_halves_split import model  # noqa: F401 - the fixture (variant (e), placed)


def test_slip_map_gives_the_kernels_friction(model):  # noqa: F811
    """``-G^T (N psi(|Gv|) Gv)`` = the H2 contact forces less those at ``f0 = 0``, and ``N psi |s|^2`` sums to the
    kernel's friction power; ``G`` reads the fixed sheaves' rates as zero (no column past the velocities)."""
    m, x0 = model
    n2, table, ck = m.n2, m._pair_table, m._compiled_contact
    free = m._sheave_friction[0]
    for x in _states(m, x0):
        y = np.concatenate([x[:2 * n2], m._constants])
        Q, Q0 = np.zeros(n2), np.zeros(n2)
        Pf = HEK.forces(y, *table, *ck, Q)[0]
        HEK.forces(y, *table, *free, Q0)
        G, N = m.sheave_slips(x)
        fs = m.friction_sets(x)[1]
        s = G @ x[n2:2 * n2]
        r = fs.forces(s)
        assert len(N) > 100 and np.all(N > 0) and G.shape == (2 * len(N), n2)
        assert np.abs(-(G.T @ r) - (Q - Q0)).max() <= 1e-12 * np.abs(Q).max()
        assert -r @ s == pytest.approx(Pf, rel=1e-12)


def test_explicit_plus_all_friction_equals_the_rhs(model):  # noqa: F811
    m, x0 = model
    assert m.stiff_split[3] == {"all": (m.rhs_explicit_all, m.friction_solve_all, m.friction_hold, None,
                                        m.friction_rate)}
    for x in _states(m, x0):
        f, fE, fI = m.rhs(0.0, x), m.rhs_explicit_all(0.0, x), friction_rate(m, x)
        iphi = m.n2 + m._idx[1]
        assert np.abs(fI[iphi]).max() > 0.0                   # the shafts feel the friction torques
        assert np.abs(f - fE - fI).max() <= 1e-12 * np.abs(f).max()


def test_friction_solve_all_is_backward_euler_and_books_the_kinetic_energy(model, monkeypatch):  # noqa: F811
    """To the solve's tolerance (1e-6 v0 on the slips here; the default is 0.1 v0), and the booked work is the kinetic
    energy removed to round-off (at any tolerance)."""
    m, x0 = model
    monkeypatch.setattr(type(m), "FRICTION_TOL", 1e-6)
    assert_friction_solve_all_is_backward_euler(m, _states(m, x0, 2))


def test_strang_friction_runs_all_friction(model):  # noqa: F811
    m, x0 = model
    with pytest.raises(InputError, match="friction"):
        solve(m, (0.0, 1e-7), x0, method="strang-friction", h=1e-7, friction="pins")
    res = solve(m, (0.0, 4e-7), x0, method="strang-friction", h=2e-7, scheme="frozen-mid", explicit="rk4",
                friction="all")
    assert res.success and np.all(np.isfinite(res.y)) and res.stats["nlu"] > 0
