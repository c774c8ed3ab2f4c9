"""Dynamic band models: energy conservation, power balance, clamping and slip (spec 4.3-4.6)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cvtfem.control.clamping import Clamping
from cvtfem.elements.band.geometry import radii
from cvtfem.machines.cvt import band_model, closed_loop
from cvtfem.scene.loader import load_scene

MODELS = ["band-4dof", "band-6+2n", "band-6+2n+8"]
SMALL = {"n_ritz": 2, "n_gauss": 8}  # keeps the compressible models cheap; physics unchanged


def _small(name):
    return {} if name == "band-4dof" else SMALL


def _conservative_run(name, periods, rtol, atol=1e-14):
    """Friction and damping off, no torques, constant clamping: integrate and return the energy history."""
    m = band_model(load_scene(name), friction=False, damping=False, **_small(name))
    n, F, M = m.n2, np.array([28e3, 30e3]), np.zeros(2)
    if n > 4:
        q = m.static_state(-0.2, F)  # elastic coordinates in balance, span angle not: slow oscillation
    else:
        q = np.array([-0.2, 0.0, 0.0, 0.0])
    v = np.zeros(n)
    v[1:4] = 5.0, 120.0, 60.0  # spinning shafts and band decouple without friction

    def energy(y):
        return m.kinetic_energy(y[:n], y[n:]) + m.elastic_energy(y[:n]) + m.p.kappa * F @ m.clamp_positions(y[:n])

    def f(t, y):
        return np.concatenate([y[n:], m.accel(y[:n], y[n:], F, M)[0]])

    y0 = np.concatenate([q, v])
    e_spin = 0.5 * (m.p.mass * v[1] ** 2 + np.dot(m.p.J, v[2:4] ** 2))
    # 4-DOF: periods of the span-angle oscillation (146 rad/s); compressible: of the fastest elastic mode
    # (sheave on band, ~5e4 rad/s), which the spinning band excites through its sigma-h inertia coupling
    T = 2 * np.pi / 146.4 if n == 4 else 2 * np.pi / 5.1e4
    method = "DOP853" if n == 4 else "Radau"
    sol = solve_ivp(f, (0, periods * T), y0, method=method, rtol=rtol, atol=atol, dense_output=False)
    E = np.array([energy(y) for y in sol.y.T])
    phi = sol.y[0]
    return E, e_spin, phi


def test_4dof_energy_conserved_over_1000_periods_quick_check():
    E, e_spin, phi = _conservative_run("band-4dof", 25, 1e-12)
    assert np.ptp(phi) > 0.05  # it does oscillate
    # relative to the kinetic energy of the oscillation + spin (the part that moves)
    assert np.abs(E - E[0]).max() / e_spin < 1e-9


@pytest.mark.slow
def test_4dof_energy_conserved_over_1000_periods():
    E, e_spin, phi = _conservative_run("band-4dof", 1000, 1e-12)
    assert np.abs(E - E[0]).max() / e_spin < 1e-8


@pytest.mark.parametrize("name", ["band-6+2n", pytest.param("band-6+2n+8", marks=pytest.mark.slow)])
def test_compressible_energy_conserved(name):
    E, e_spin, phi = _conservative_run(name, 10, 1e-10, 1e-11)
    assert np.ptp(phi) > 1e-7  # the span angle starts to move
    assert np.abs(E - E[0]).max() / e_spin < 1e-8



def _balance(name, t_end, law="tanh", safety=1.1):
    scene = load_scene(name, {"cvt": {"effects": {"stabilisation": False}, "friction": {"law": law},
                                      "regime": {"clamping_safety": safety}}})
    loop = closed_loop(scene, **_small(name))
    x0 = loop.initial_state()
    sol = solve_ivp(loop.rhs, (0, t_end), x0, method="Radau", rtol=1e-9, atol=1e-11, jac=loop.jac)
    return loop, sol


@pytest.mark.parametrize("name", ["band-4dof", pytest.param("band-6+2n", marks=pytest.mark.slow),
                                  pytest.param("band-6+2n+8", marks=pytest.mark.slow)])
def test_power_balance_with_friction(name):
    """Input work = output work + dissipation + change of energy (+ clamping work), to 1e-6 of the input."""
    loop, sol = _balance(name, 0.01)
    x0, x = sol.y[:, 0], sol.y[:, -1]
    W = loop.split(x)[3]
    dE = loop.energy(x) - loop.energy(x0)
    assert W[2] > 0  # friction dissipates
    assert abs(W[0] - W[1] - W[2] + W[3] - dE) < 1e-6 * W[0]


def _slip_history(safety):
    loop, sol = _balance("band-4dof", 0.15, law="linear-saturated", safety=safety)
    n = loop.model.n2
    r1 = radii(sol.y[0], loop.model.p.length, loop.model.p.L)[0][0]
    return sol.t, sol.y[n + 1] - r1 * sol.y[n + 2]  # circumferential slip on the driving pulley


@pytest.mark.parametrize("name", ["band-6+2n", "band-6+2n+8"])
def test_power_balance_short_window(name):
    """Same balance over 1 ms for the compressible models (the 10 ms runs are marked slow)."""
    loop, sol = _balance(name, 0.001)
    x0, x = sol.y[:, 0], sol.y[:, -1]
    W = loop.split(x)[3]
    dE = loop.energy(x) - loop.energy(x0)
    assert W[2] > 0
    assert abs(W[0] - W[1] - W[2] + W[3] - dE) < 1e-6 * W[0]


def test_clamping_above_estimate_holds_below_slips():
    """(1.13) x 1.1: no gross slip; x 0.8: the slip speed on the driving pulley keeps growing."""
    v0 = 0.02
    t, s_ok = _slip_history(1.1)
    late = t > 0.05
    assert np.abs(s_ok[late]).max() < v0  # stays on the sticking (linear) branch
    t, s_bad = _slip_history(0.8)
    i1, i2 = np.searchsorted(t, 0.075), len(t) - 1
    assert abs(s_bad[i2]) > 10 * v0
    assert abs(s_bad[i2]) > 1.5 * abs(s_bad[i1])  # and it grows


def test_equilibrium_split_gives_each_pulley_its_safety():
    p = band_model(load_scene("band-4dof")).p
    c = Clamping(p, 1.1)
    F, est = c.forces(200.0, 2.4), c.estimates(200.0, 2.4)
    assert (F / est).min() == pytest.approx(1.1, rel=1e-12)
    per = Clamping(p, 1.1, "per-shaft").forces(200.0, 2.4)
    assert per == pytest.approx(1.1 * est, rel=1e-12)
