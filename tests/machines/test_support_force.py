"""Support forces of the running chain (`driving.support_force`, `driven.support_force` of ChainCVT): the bearing
reactions of the rigid shafts balance the chain, statically to the solver's residual and on average in running,
where they also carry the pin-entry line f_link."""
import numpy as np
import pytest

from cvtfem.io.results import read_results
from cvtfem.machines.cvt import chain_loop
from cvtfem.post import spectrogram as sg
from cvtfem.scene.loader import load_scene


def test_static_support_forces_balance_the_chain_and_its_span_tensions():
    """Quasi-static state at ratio 2.4 without speed (no friction, no centrifugal force): each bearing reaction
    equals minus the chain's elastic forces on the pins touching that shaft (per-pin balance; an independent sum,
    to the solver's residual), the two reactions cancel (the chain is free), and the reaction is the resultant
    2 T cos(phi) of the two span tensions along the line of centres (T the span tension, phi the span angle)."""
    model = chain_loop(load_scene("chain-S2"))
    x0, rep = model.static_state(2.4, 0.0)
    out = model.outputs(0.0, x0)
    R = np.array([out["driving.support_force"], out["driven.support_force"]])
    nc, _, _, dof3 = model._idx
    q, v, _, _ = model.split(x0)
    Q_chain = model.family.forces(q[:nc], v[:nc])[dof3[:, :2]]              # (n, 2) on the pin ends' x1, x2
    touching = out["contact.penetration"].reshape(-1, 2) > 0
    slack = rep["residual"] * rep["F2"]                                       # largest unbalanced force, N
    for k in (0, 1):
        np.testing.assert_allclose(R[k], -Q_chain[touching[:, k]].sum(axis=0), rtol=0,
                                   atol=touching[:, k].sum() * slack + 1e-9 * abs(R[k]).max())
    np.testing.assert_allclose(R[0] + R[1], 0.0, atol=model.family.n * slack)
    T = out["chain.span_tension"]
    assert T[0] == pytest.approx(T[1], rel=1e-3)
    phi = rep["placement"].phi
    assert R[0, 0] == pytest.approx(T.sum() * np.cos(phi), rel=5e-3)
    assert abs(R[0, 1]) < 1e-3 * R[0, 0]


SCENE = """preset = "chain-S2"
[output]
step = 2e-5
[cvt.chain]
long_fraction = 0.0
pitch_short = 0.009
"""


@pytest.mark.slow
def test_running_support_force_balances_the_spans_and_shows_f_link(cli, tmp_path):
    """12 ms of chain-S2 with a uniform chain, 20 us sampling.  Over 4-12 ms the mean bearing reaction of the driving
    shaft balances the span tensions: ``(T_tight + T_slack - 2 m' v^2) cos(phi)`` along the line of centres (the
    arc sees the tension less the centrifugal part ``m' v^2``, m' = chain mass / length, v = omega_1 r_1) and
    ``(T_tight - T_slack) sin(phi)`` across it, each to 1 % of the resultant; the driven shaft's is opposite to 0.5 %;
    the pins travel slower than the driving sheaves at their contact radius and faster than the driven ones
    (creep, under 1 %); the spectrogram of its x1 component peaks at f_link, the pins' passing rate, to one bin
    (250 Hz)."""
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE)
    h5 = tmp_path / "r.h5"
    r = cli("run", str(scene), "--until", "0.012", "--results", str(h5), timeout=900)
    assert r.returncode == 0, r.stderr
    res = read_results(h5)
    late = res.time >= 4e-3 - 1e-12
    s = {name: res.series[name][late] for name in res.series}
    R1, R2 = s["driving.support_force"].mean(axis=0), s["driven.support_force"].mean(axis=0)
    T = s["chain.span_tension"].mean(axis=0)
    radius = s["contact.radius"].reshape(late.sum(), -1, 2)
    r1, r2 = (radius[:, :, k][radius[:, :, k] > 0].mean() for k in (0, 1))
    sc = load_scene(str(scene))
    length, L = 84 * 0.009, sc.cvt.geometry.centre_distance
    v = s["driving.speed"].mean() * r1
    phi = np.arcsin((r2 - r1) / L)
    expected = np.array([(T.sum() - 2 * sc.cvt.chain.mass / length * v ** 2) * np.cos(phi),
                         (T[0] - T[1]) * np.sin(phi)])
    np.testing.assert_allclose(R1, expected, rtol=0, atol=0.01 * np.hypot(*expected))
    np.testing.assert_allclose(R2, -R1, rtol=0, atol=0.005 * np.hypot(*R1))
    t, y, _ = sg.select_signal(res, "driving.support_force", "0", 4e-3)
    spec = sg.compute_spectrogram(t, y, 4e-3, fmax=5000.0)
    f_link = sg.chain_frequencies(res, 84, length, L).f_link[late].mean()           # the pins' own travel
    v2 = np.abs(s["driven.speed"]).mean() * r2
    assert v2 / 0.009 < f_link < v / 0.009          # creep: the chain lags the driving sheaves, leads the driven ones
    assert f_link == pytest.approx(v / 0.009, rel=1e-2)           # (H1: the contact radius is the pins' radius)
    assert spec.f[1 + np.argmax(spec.psd[1:].mean(axis=1))] == pytest.approx(f_link, abs=spec.df)
