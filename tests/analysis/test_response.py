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
