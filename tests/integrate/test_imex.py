"""strang-friction on a mass-spring with a stiff tanh friction (the split A5 uses: f_I the friction, solved by the
system's own backward Euler, or integrated explicitly with the positions frozen by multirate-rk4): convergence to the
unsplit solution, energy bookkeeping, bad input."""
import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.integrate import solve
from cvtfem.integrate.system import OdeSystem, StiffSplit

M, K, C, V0 = 1.0, 400.0, 20.0, 1e-4          # kg, N/m, N (friction force bound), m/s: |lambda| = C/(M V0) = 2e5 1/s
X0 = np.array([0.1, 0.0, 0.0])                # position, velocity, dissipated work


def drive(t):
    return 30.0 * np.sin(25.0 * t)            # N


def explicit(t, x):
    return np.array([x[1], (-K * x[0] + drive(t)) / M, 0.0])


def friction(v):
    return -C * np.tanh(v / V0)


def full(t, x):
    f = explicit(t, x)
    f[1] += friction(x[1]) / M
    f[2] = -friction(x[1]) * x[1]
    return f


def backward_euler(t, x, h):
    """``v = v* + h F(v) / M`` by Newton (monotone: unique), the work ``-h F(v) (v + v*) / 2`` booked."""
    vs, v = x[1], x[1]
    for it in range(1, 100):
        r = M * (v - vs) - h * friction(v)
        dv = -r / (M + h * C / V0 / np.cosh(v / V0) ** 2)
        v += dv
        if abs(dv) < 1e-14:
            break
    out = x.copy()
    out[1] = v
    out[2] -= h * friction(v) * 0.5 * (v + vs)
    return out, it


def hold(x, d):
    return np.array([0.0, d[1], -M * d[1] * x[1]])


class FrictionRate:
    """The friction's rate with the position frozen (it has none to freeze here) and its stiffness bound."""

    def advance(self, v, a, eta, coefficients):
        """The Chebyshev stages on ``u' = a + F(u) / M`` (as the A5 chain's compiled twin)."""
        mu, nu, mu_t = coefficients
        u_prev, u = v, v + mu_t[1] * eta * (a + friction(v) / M)
        for j in range(2, len(mu)):
            u, u_prev = mu[j] * u + nu[j] * u_prev + mu_t[j] * eta * (a + friction(u) / M), u
        return u

    def bound(self, z, iterations):
        return C / (M * V0), z


def rate(x):
    return FrictionRate()


SYSTEM = OdeSystem(fun=full, n=3, n2=1, split=StiffSplit(explicit, backward_euler, hold, None, rate))


def energy(x):
    return 0.5 * M * x[1] ** 2 + 0.5 * K * x[0] ** 2


@pytest.fixture(scope="module")
def reference():
    return solve(SYSTEM, (0.0, 0.5), X0, method="Radau", rtol=1e-11, atol=1e-13).y[:, -1]


@pytest.mark.parametrize("explicit", ["rk4", "dumka3"])
def test_strang_converges_with_order_one_to_the_unsplit_solution(reference, explicit):
    """Steps 1e-3..3.1e-5 s are 200..6 times the friction's stability limit of an explicit method, 1/|lambda|; the
    backward-Euler half steps make the splitting order 1 (the stick-slip kinks scatter the single ratios: fitted)."""
    hs = [1e-3 / 2 ** k for k in range(6)]
    errs = [np.abs(solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", h=h, explicit=explicit).y[:2, -1]
                   - reference[:2]).max() for h in hs]
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 0.9 < order < 1.1 and errs[-1] < 4e-4, (errs, order)


def test_frozen_error_and_energy(reference):
    """The held friction forces: error below 2e-4 (m, m/s) at every step from 2.5e-4 s down (it does not fall further
    there: the held force is the one of the step's end, whose slip the friction's scale 1/|lambda| sets), and the
    balance closes to the explicit method's error (the held forces' work is integrated along the step)."""
    for h in (2.5e-4, 1.25e-4, 6.25e-5):
        res = solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", h=h, explicit="rk4", scheme="frozen")
        assert np.abs(res.y[:2, -1] - reference[:2]).max() < 2.5e-4
    assert_balance("frozen")


def test_frozen_mid_converges(reference):
    """The held forces of the step's middle (a backward-Euler half step after half the explicit impulse) converge:
    the error falls by 3..6 per halving from 2.5e-4 s (order 1.5..2.5) and the balance closes."""
    errs = [np.abs(solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", h=h, explicit="rk4",
                         scheme="frozen-mid").y[:2, -1] - reference[:2]).max() for h in (2.5e-4, 1.25e-4, 6.25e-5)]
    ratios = np.array(errs[:-1]) / errs[1:]
    assert np.all(ratios > 3) and np.all(ratios < 6) and errs[-1] < 1.5e-4, errs
    assert_balance("frozen-mid")


def assert_balance(scheme):
    ts = np.linspace(0.0, 0.5, 5001)
    res = solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", h=1e-4, explicit="rk4", t_eval=ts, scheme=scheme)
    assert res.y[2, -1] > 0.1 * energy(X0)
    # input work by the drive, trapezoidal on the dense samples (1e-4 s, the drive's period 0.25 s)
    p = drive(ts) * res.y[1]
    w_in = np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(ts))
    balance = w_in - (energy(res.y[:, -1]) - energy(X0)) - res.y[2, -1]
    assert abs(balance) < 2e-3 * res.y[2, -1]


def test_strang_energy_balance_closes():
    """Input work of the drive = stored energy change + booked dissipation: the friction substeps book exactly what
    they remove; what is left is RK4's error and the trapezoidal input work on the samples."""
    assert_balance("strang")


def test_multirate_converges_with_order_one_and_stays_accurate_at_long_steps(reference):
    """The friction integrated over ``eta = 2/3 h`` by the strongly damped Chebyshev method inside each RK4 stage:
    below 6e-4 (m, m/s) at steps 1e-3..3.1e-5 s (200..6 times the friction's explicit limit; found 5.3e-4 at 1e-3 s,
    6.3e-5 at 2.5e-4 s and below; frozen-mid errs 6.6e-3 at 1e-3 s), and at least order one over the first 0.05 s at
    steps 5e-4..6.25e-5 s (fitted 1.25: the stick-slip kinks scatter the single ratios)."""
    def error(h, t_end, ref):
        res = solve(SYSTEM, (0.0, t_end), X0, method="strang-friction", h=h, scheme="multirate-rk4")
        return np.abs(res.y[:2, -1] - ref[:2]).max()

    assert max(error(1e-3 / 2 ** k, 0.5, reference) for k in range(6)) < 6e-4
    short = solve(SYSTEM, (0.0, 0.05), X0, method="Radau", rtol=1e-12, atol=1e-14).y[:, -1]
    hs = [5e-4 / 2 ** k for k in range(4)]
    order = np.polyfit(np.log(hs), np.log([error(h, 0.05, short) for h in hs]), 1)[0]
    assert 0.8 < order < 1.6, order


def test_adaptive_multirate_error_falls_with_the_tolerance(reference):
    """The embedded third-order estimate on the frictionless rate steers the steps: the error at the end does not grow
    with a tighter rtol from 1e-2 to 1e-6 and falls 50x or more over that range (found 2.0e-2, 7.3e-3, 7.0e-3, 9.4e-4,
    2.2e-4: the averaging's O(eta) error, which the estimate does not see, keeps it above rtol and flat between 1e-3
    and 1e-4, where the spring's steps barely change)."""
    errs = [np.abs(solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", scheme="multirate-rk4", rtol=rtol,
                         atol=1e-2 * rtol).y[:2, -1] - reference[:2]).max() for rtol in 10.0 ** -np.arange(2, 7)]
    assert np.all(np.diff(errs) <= 0.05 * np.array(errs[:-1])) and errs[-1] < min(errs[0] / 50, 3e-4), errs


def test_adaptive_multirate_at_its_cap_is_the_fixed_step_run():
    """A tolerance no step exceeds keeps every step at ``max_step``; the end stage is then the next step's first,
    computed as the fixed-step run computes it: the same states bitwise."""
    fixed = solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", scheme="multirate-rk4", h=1e-3)
    capped = solve(SYSTEM, (0.0, 0.5), X0, method="strang-friction", scheme="multirate-rk4", h=1e-3, adaptive=True,
                   rtol=0.5, atol=1.0, max_step=1e-3)
    assert len(capped.t) == len(fixed.t) == 501 and capped.stats["nreject"] == 0
    np.testing.assert_array_equal(capped.y, fixed.y)


def test_multirate_energy_balance_closes():
    """The friction's mean force over each stage's ``eta`` is booked at the power it delivers at the stage (the split's
    ``hold``): the balance stays RK4's."""
    assert_balance("multirate-rk4")


def test_bad_input():
    plain = OdeSystem(fun=full, n=3, n2=1)
    with pytest.raises(InputError, match="StiffSplit"):
        solve(plain, (0.0, 0.01), X0, method="strang-friction", h=1e-3)
    for bad in ({"explicit": "radau5"}, {"scheme": "lie"}, {"explicit": "rk4", "stages": 9}):
        with pytest.raises(InputError):
            solve(SYSTEM, (0.0, 0.01), X0, method="strang-friction", h=1e-3, **bad)
    no_hold = OdeSystem(fun=full, n=3, n2=1, split=StiffSplit(explicit, backward_euler))
    with pytest.raises(InputError, match="hold"):
        solve(no_hold, (0.0, 0.01), X0, method="strang-friction", h=1e-3, scheme="frozen")
    with pytest.raises(InputError, match="rate"):
        solve(no_hold, (0.0, 0.01), X0, method="strang-friction", h=1e-3, scheme="multirate-rk4")
    for bad in ({"scheme": "multirate-rk4", "max_step": 0.0}, {"scheme": "multirate-rk4", "max_step": "1e-3s"},
                {"scheme": "frozen", "max_step": 1e-3}):
        with pytest.raises(InputError, match="max_step"):
            solve(SYSTEM, (0.0, 0.01), X0, method="strang-friction", h=1e-3, **bad)
    with pytest.raises(InputError, match="no error estimate"):
        solve(SYSTEM, (0.0, 0.01), X0, method="strang-friction", scheme="imex-rk4")
