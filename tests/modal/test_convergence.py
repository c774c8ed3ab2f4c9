"""Simply supported uniform shafts: convergence to analytic Euler-Bernoulli / Rayleigh / Timoshenko roots."""
import numpy as np
import pytest

from cvtfem.modal import ModalProblem

from .helpers import STEEL, simply_supported_lateral


def lowest(n, length, Do, Di=0.0, speed=0.0, n_modes=6, **opts):
    M, K, G, kind, b = simply_supported_lateral(n, length, Do, Di, **opts)
    return ModalProblem(M, K, 0 * K, G, kind, method="dense").solve(speed, n_modes), b


def test_euler_bernoulli_rate_is_four():
    """Error of modes 1-3 vs (n pi/L)^2 sqrt(EI/rho A) falls as h^4 (cubic Hermite element)."""
    L, D = 2.0, 0.05
    A, I = np.pi * D**2 / 4, np.pi * D**4 / 64
    k = np.arange(1, 4) * np.pi / L
    exact = np.repeat(k**2 * np.sqrt(STEEL["E"] * I / (STEEL["rho"] * A)), 2)
    errs = []
    for n in (4, 8, 16):
        r, _ = lowest(n, L, D, shear=False, rotary_inertia=False, gyroscopic=False)
        errs.append(np.max(np.abs(r.wd - exact) / exact))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert errs[-1] < 1e-4
    assert np.all(rates > 3.8) and np.all(rates < 4.3), rates


def timoshenko_roots(k, Do, Di, kappa, speed):
    """Lower (flexural) roots of the analytic Timoshenko equation of spec §12.2a, backward then forward."""
    A, I = np.pi / 4 * (Do**2 - Di**2), np.pi / 64 * (Do**4 - Di**4)
    E, G, rho = STEEL["E"], STEEL["G"], STEEL["rho"]
    kGA, rIp = kappa * G * A, rho * 2 * I
    out = []
    for sign in (-1.0, 1.0):
        # (kGA k^2 - rho A w^2)(EI k^2 + kGA - rho I w^2 + s rho Ip Omega w) - (kGA k)^2 = 0, a quartic in w
        p1 = np.array([-rho * A, 0.0, kGA * k**2])
        p2 = np.array([-rho * I, sign * rIp * speed, E * I * k**2 + kGA])
        poly = np.polysub(np.polymul(p1, p2), [(kGA * k) ** 2])
        r = np.roots(poly)
        out.append(np.min(r[(abs(r.imag) < 1e-6 * abs(r)) & (r.real > 0)].real))
    return out


@pytest.mark.parametrize("Di,speed", [(0.0, 0.0), (0.0, 3000.0), (0.06, 3000.0)])
def test_timoshenko_short_shaft(Di, speed):
    """L/D = 5 (spec §12.2a): 32 elements within 2e-3 of the analytic roots; error shrinks with n."""
    from cvtfem.elements.beam import cowper_kappa

    L, Do = 0.5, 0.1
    kappa = float(cowper_kappa(STEEL["E"] / (2 * STEEL["G"]) - 1, Di / Do))
    exact = np.concatenate([timoshenko_roots(n * np.pi / L, Do, Di, kappa, speed) for n in (1, 2, 3)])
    errs = []
    for n in (8, 32):
        r, _ = lowest(n, L, Do, Di, speed=speed)
        errs.append(np.max(np.abs(r.wd - exact) / exact))
    assert errs[1] < 2e-3 and errs[1] < errs[0] / 4, errs
    r, _ = lowest(32, L, Do, Di, speed=speed)
    if speed:
        assert list(r.whirl) == ["backward", "forward"] * 3
    # Euler-Bernoulli over-estimates a thick shaft: shear and rotary inertia matter at L/D = 5
    eb, _ = lowest(32, L, Do, Di, speed=speed, shear=False, rotary_inertia=False)
    assert np.all(eb.wd > r.wd * 1.02)


@pytest.mark.parametrize("P", [5e4, -2e3])
def test_axial_force_geometric_stiffness(P):
    """Euler-Bernoulli string-beam: w^2 = (EI k^4 + P k^2) / (rho A) for a simply supported shaft."""
    from cvtfem.assembly import assemble

    from .helpers import restrict, uniform_shaft

    n, L, D = 16, 2.0, 0.05
    b, M, K, G, kind = uniform_shaft(n, L, D, shear=False, rotary_inertia=False, gyroscopic=False)
    K = assemble(M.shape[0], [(b.stiffness(P), b.dofs)])
    node = np.repeat(np.arange(n + 1), 6)
    keep = np.flatnonzero(np.isin(kind, [0, 1, 3, 4]) & ~(np.isin(kind, [0, 1]) & ((node == 0) | (node == n))))
    M, K, G = restrict(keep, M, K, G)
    r = ModalProblem(M, K, 0 * K, G, kind[keep], method="dense").solve(0.0, 6)
    A, I = np.pi * D**2 / 4, np.pi * D**4 / 64
    k = np.repeat(np.arange(1, 4) * np.pi / L, 2)
    exact = np.sqrt((STEEL["E"] * I * k**4 + P * k**2) / (STEEL["rho"] * A))
    np.testing.assert_allclose(r.wd, exact, rtol=2e-4)
