"""Stabilisation systems (spec section 5): guards, clamps, anti-windup, gains, settling of every model."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cvtfem.control.regimes import Regime
from cvtfem.control.stabilisation import Stabilisation, StabilisationParams, clamp, ratio_estimate
from cvtfem.errors import InputError
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene


def test_clamp_and_ratio_guards():
    assert clamp(5.0, 0.0, 1.0) == 1.0 and clamp(-5.0, 0.0, 1.0) == 0.0 and clamp(0.3, 0.0, 1.0) == 0.3
    assert ratio_estimate(100.0, 1e-7, 1e-5, 0.1, 10.0) == 1.0  # standstill guard
    assert ratio_estimate(100.0, 1.0, 1e-5, 0.1, 10.0) == 10.0
    assert ratio_estimate(1.0, 100.0, 1e-5, 0.1, 10.0) == 0.1
    assert ratio_estimate(240.0, 100.0, 1e-5, 0.1, 10.0) == pytest.approx(2.4)


def test_ratio_loop_saturates_and_stops_integrating():
    ctl = Stabilisation(StabilisationParams(k_sat=2.0))
    F_appl = np.array([30e3, 35e3])
    # ratio far too high: F1 correction saturates at (k_sat - 1) F1a, integral frozen
    z = np.array([300.0, 100.0, 1e5, 0.0])
    F, _, dz, d = ctl.outputs(np.array([300.0, 100.0]), z, 2.4, 100.0, 200.0, F_appl)
    assert F[0] == pytest.approx(2.0 * F_appl[0]) and F[1] == F_appl[1]
    assert d["sat1"] and dz[2] == 0.0
    # same error with the integral inside the band: it integrates at c_f1 e
    z[2] = 0.0
    F, _, dz, d = ctl.outputs(np.array([245.0, 100.0]), np.array([245.0, 100.0, 0.0, 0.0]), 2.4, 100.0, 200.0, F_appl)
    assert not d["sat1"] and dz[2] == pytest.approx(1e6 * 0.05)
    assert F[0] == pytest.approx(F_appl[0] + 2e5 * 0.05)
    # too low a ratio: the lower clamp F1a / k_sat
    F, *_ = ctl.outputs(np.array([100.0, 100.0]), np.array([100.0, 100.0, -1e6, 0.0]), 2.4, 100.0, 200.0, F_appl)
    assert F[0] == pytest.approx(F_appl[0] / 2.0)


def test_speed_loop_gains_give_damping_nu_and_time_tau():
    """Linearised loop J e'' + (b20 + cb0 w2d) e' + cb1 w2d e = 0 (section 5.4 [D])."""
    p = StabilisationParams(tau=0.02, nu=0.7, J_sigma=0.25)
    b20, w2d = 3.14, 152.7
    cb0, cb1 = p.speed_gains(b20, w2d)
    wn = np.sqrt(cb1 * w2d / p.J_sigma)
    zeta = (b20 + cb0 * w2d) / (2 * p.J_sigma * wn)
    assert wn == pytest.approx(1 / (p.tau * p.nu), rel=1e-12)
    assert zeta == pytest.approx(p.nu, rel=1e-12)


def test_speed_loop_drives_a_lossy_inertia_to_its_target():
    """J w' = M1 i - loss - b2 w with the loop on: integral action removes the loss offset."""
    p = StabilisationParams(tau_omega=1e-4, tau=0.02, nu=0.8, J_sigma=0.3)
    ctl = Stabilisation(p)
    M1, i, w2d, loss = 200.0, 2.4, 152.7, 15.0

    def f(t, y):
        w, z = y[0], y[1:]
        _, M2, dz, _ = ctl.outputs(np.array([i * w, w]), z, i, w2d, M1, np.array([3e4, 3e4]))
        return np.concatenate([[(M1 * i - loss + M2) / p.J_sigma], dz])

    sol = solve_ivp(f, (0, 0.5), np.concatenate([[140.0], ctl.initial_state(i * 140.0, 140.0)]), method="Radau",
                    rtol=1e-8, atol=1e-10)
    assert sol.y[0, -1] == pytest.approx(w2d, rel=1e-4)


def test_regime_ramps_and_bad_input():
    r = Regime("ratio-change", 314.0, 200.0, 0.45, end_value=2.4, ramp_time=5.0)
    assert r.targets(2.5)[2] == pytest.approx(0.45 + 0.5 * (2.4 - 0.45))
    assert r.targets(9.0)[2] == 2.4
    assert Regime("torque-ramp", 400.0, 150.0, 0.45, 380.0, 2.0).targets(1.0)[1] == pytest.approx(265.0)
    with pytest.raises(InputError, match="ramp_time"):
        Regime("speed-ramp", 100.0, 200.0, 0.45)


def _settle(name, t_end=1.0, **small):
    loop = closed_loop(load_scene(name), **small)
    x0 = loop.initial_state(ratio=2.3, speed_factor=0.96)
    sol = solve_ivp(loop.rhs, (0, t_end), x0, method="Radau", rtol=1e-6, atol=1e-8, jac=loop.jac, dense_output=True)
    n = loop.model.n2
    t = np.linspace(0.9, 1.0, 21) * t_end
    v = sol.sol(t)[n:2 * n]
    w1d, _, i_d = loop.regime.targets(t_end)
    ratio, w1 = v[2] / v[3], v[2]
    first = sol.y[n + 2, 0] / sol.y[n + 3, 0]
    return first, ratio, w1, i_d, w1d


@pytest.mark.parametrize("name,small", [
    ("band-4dof", {}),
    ("band-6+2n", {}),  # ~2 s each with the compiled right-hand side
    ("band-6+2n+8", {}),
])
def test_stationary_regime_settles_within_one_second(name, small):
    """3500 rpm, 200 N m, ratio 2.4, loops on, started 4 % slow at ratio 2.3: within 1 % after 1 s."""
    first, ratio, w1, i_d, w1d = _settle(name, **small)
    assert abs(first / i_d - 1) > 0.03  # really started away
    assert np.abs(ratio / i_d - 1).max() < 0.01
    assert np.abs(w1 / w1d - 1).max() < 0.01
