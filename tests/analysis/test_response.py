"""Order response of the CVT sheave shaft against its Campbell diagram; Friswell unbalance response by scene."""
import numpy as np
import pytest
from scipy.signal import find_peaks

from cvtfem.analysis.response import Unbalance, scene_response
from cvtfem.errors import InputError
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def sheave():
    speeds = np.linspace(0.0, 6000.0, 61) * np.pi / 30
    return scene_response(load_scene("cvt_sheave_shaft"), [Unbalance(4, 1e-5, 0.0)], speeds, 4,
                          orders=(14.0, 42.0), n_freqs=50, n_modes=10)


def test_order_peaks_sit_on_campbell_crossings(sheave):
    """Every peak of the order response (x force and x, y response at the fixed sheave) lies within one speed step
    of a lateral-mode crossing of that order line in the Campbell diagram, and every lateral crossing has a peak
    within two steps (a backward/forward pair closer than two steps can merge into one peak; at 121 and 241 speeds
    the pairs at 398/410 rad/s on the 42x line separate)."""
    step = sheave.speeds[1] - sheave.speeds[0]
    for j, k in enumerate(sheave.orders):
        peaks = sheave.speeds[find_peaks(sheave.order_amplitude[:, j])[0]]
        cross = np.array([c["speed_rad_s"] for c in sheave.campbell.crossings
                          if c["order"] == f"{k:g}x" and c["whirl"] in ("forward", "backward")])
        assert len(peaks) >= 2 and len(cross) >= 2
        assert all(np.min(np.abs(cross - p)) <= step for p in peaks), (k, peaks, cross)
        assert all(np.min(np.abs(peaks - c)) <= 2 * step for c in cross), (k, peaks, cross)


def test_order_map_ridges_follow_natural_frequencies(sheave):
    """Along each speed, the map's largest value lies within one frequency line of a lateral natural frequency."""
    df = sheave.freqs[1] - sheave.freqs[0]
    lateral = np.isin(sheave.campbell.whirl, ("forward", "backward"))
    for i in range(len(sheave.speeds)):
        top = sheave.freqs[np.argmax(sheave.map[i])]
        assert np.min(np.abs(sheave.campbell.wd[i][lateral[i]] - top)) <= df


def test_unbalance_response_scene_and_bad_input():
    scene = load_scene("friswell_5_9_1")
    speeds = np.linspace(0.0, 4000.0, 81) * np.pi / 30
    r = scene_response(scene, [Unbalance(2, 1e-4, 0.0), Unbalance(4, 1e-4, np.pi)], speeds, 3)
    assert r.major.shape == speeds.shape and np.all(r.minor >= -1e-12 * r.major.max())  # isotropic: forward
    d = r.to_dict()
    assert len(d["amplitude_x_m"]) == len(speeds) and "orders" not in d
    for kwargs in ({"node": 9}, {"unbalances": [Unbalance(12, 1e-4, 0.0)]}, {"speeds": -speeds[::-1]},
                   {"orders": (0.0,)}):
        args = {"unbalances": [Unbalance(2, 1e-4, 0.0)], "speeds": speeds, "node": 3, **kwargs}
        with pytest.raises(InputError):
            scene_response(scene, **args)
    with pytest.raises(InputError, match="supported: rotor"):
        scene_response(load_scene("engine_gear_train"), [Unbalance(1, 1e-4, 0.0)], speeds, 1)


def test_jeffcott_scene_against_closed_form():
    """A 10 kg disk at mid-span of a light (rho = 1) Euler-Bernoulli shaft on stiff bearings with a damper at the
    disk: x = me W^2 / (k - m W^2 + i c W) with k = 48 EI / L^3 and m = disk + 17/35 of the shaft's 1.9e-4 kg
    (Rayleigh; without it the error at W = wn is 2.3e-4), phase -90 deg at W = wn."""
    from cvtfem.scene.loader import scene_from_dict

    E, D, L, mass, zeta, me = 2.1e11, 0.02, 0.6, 10.0, 0.02, 1e-4
    k = 48 * E * np.pi * D**4 / 64 / L**3
    m = mass + 17 / 35 * 1.0 * np.pi * D**2 / 4 * L
    wn = np.sqrt(k / m)
    c = 2 * zeta * wn * m
    scene = scene_from_dict({
        "rotor": {"theory": "euler-bernoulli", "rotary_inertia": False, "gyroscopic": False},
        "material": [{"name": "light", "E": E, "G": E / 2.6, "rho": 1.0}],
        "shaft": [{"length": L / 2, "outer_diameter": D, "material": "light", "repeat": 2}],
        "disk": [{"node": 1, "mass": mass, "Id": 0.01, "Ip": 0.02}],
        "bearing": [{"node": 0, "kxx": 1e13, "kyy": 1e13}, {"node": 2, "kxx": 1e13, "kyy": 1e13},
                    {"node": 1, "cxx": c, "cyy": c}]})
    s = np.sort(np.append(np.linspace(0.2, 2.0, 9) * wn, wn))
    r = scene_response(scene, [Unbalance(1, me, 0.0)], s, 1)
    exact = me * s**2 / (k - m * s**2 + 1j * c * s)
    assert np.allclose(r.x, exact, rtol=1e-5, atol=0)
    assert np.allclose(r.y, -1j * exact, rtol=1e-5, atol=0)  # forward circular: y lags x by 90 deg
    assert np.degrees(np.angle(r.x[s == wn][0])) == pytest.approx(-90.0, abs=0.01)
