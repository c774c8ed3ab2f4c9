"""ROCK2: regenerated recurrence vs the published table, order, stability length 0.81 s^2."""
import numpy as np
import pytest

from cvtfem.integrate import solve
from cvtfem.integrate.rock import MS, rock2_recurrence, rock2_stability_length
from cvtfem.integrate.study import real_stability_length
from cvtfem.problems import heat1d

# published ROCK2 `recf` entries (Abdulle's code; OrdinaryDiffEq.jl tableau)
PUBLISHED = {
    3: [0.03957407527591189, 0.05338681630900877, 0.02247986572029358, 0.06393794866013652,
        0.0861675960246663, 0.07433164225960258, 0.1608966052260327],          # m = 4
    7: [0.01394572558988917, 0.01901965402711647, 0.02425291169233543, 0.02282720812165174,
        0.09294575674653435, 0.02575013323611407, 0.1622227426315588, 0.0280770541578923,
        0.2243919049772138, 0.03005377306193452, 0.2802435651401261, 0.03196472247412495,
        0.3348331353768858, 0.03423680369928859, 0.398901664156519],           # m = 8
}


@pytest.mark.parametrize("k", sorted(PUBLISHED))
def test_regenerated_recurrence_matches_published(k):
    assert np.max(np.abs(rock2_recurrence(k) - PUBLISHED[k])) < 1e-12


def test_highest_degree_matches_published_last_pair():
    mu, kappa = rock2_recurrence(len(MS) - 1)[-2:]      # m = 198
    assert abs(mu - 0.0001212297589117476) < 1e-15 and abs(kappa - 0.9638702662671197) < 1e-12


@pytest.mark.parametrize("k", [17, 25, 35, 45])
def test_stability_length_published(k):
    """Abdulle-Medovikov 2001 (also Hairer-Wanner II, IV.2): l_s ~ 0.81 s^2."""
    s = MS[k] + 2
    assert abs(rock2_stability_length(k) / (0.81 * s * s) - 1) < 0.01


def test_stability_length_by_stepping():
    beta = real_stability_length("rock2", x_max=100, n=20001, stages=10)
    assert abs(beta - rock2_stability_length(7)) < 1e-6 * beta


def test_rock2_heat_automatic_stages():
    p = heat1d(N=200, t_end=0.1)
    res = solve(**p.solve_kwargs(), method="rock2", rtol=1e-4, atol=1e-7)
    ref = p.reference()
    assert res.success and np.max(np.abs(res.y[:, -1] - ref)) / np.max(np.abs(ref)) < 1e-3
    assert res.stats["nfev"] * 10 < 4 * 0.1 / (2.78 / p.info["rho"])
