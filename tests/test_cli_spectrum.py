"""``cvtfem spectrum`` through a real subprocess; the issue-15 acceptance: the order map's resonance crossings sit
where ``cvtfem campbell``'s excitation lines cross the natural frequencies."""
import json

import h5py
import numpy as np
import pytest
from scipy.signal import find_peaks

from cvtfem.cli import main

SPEEDS = "0:6000rpm:61"  # 100 rpm steps
ORDERS = "14,42"


def _crossings(campbell, order, whirls):
    return np.array([c["speed_rad_s"] for c in campbell["crossings"]
                     if c["order"] == f"{order:g}x" and c["whirl"] in whirls])


def run(*args):
    """``cvtfem ARGS`` in this process (the subprocess route is tested below): the exit status."""
    return main(list(args))


def test_order_map_peaks_sit_on_the_campbell_crossings(tmp_path):
    """Unit x force at the fixed sheave: every peak of the order response lies within one speed step of a lateral
    crossing from ``cvtfem campbell --json``, and every lateral crossing has a peak within two steps (a
    backward/forward pair 3 % apart merges at this resolution).  Driven by the pin-entry forces (radial and axial
    at the contact arc), every peak lies within one step of a lateral or axial crossing."""
    assert run("campbell", "cvt_sheave_shaft", "--speeds", SPEEDS, "--orders", ORDERS, "--n-modes", "12", "--json",
               str(tmp_path / "c.json")) == 0
    camp = json.loads((tmp_path / "c.json").read_text())
    assert run("spectrum", "cvt_sheave_shaft", "--speeds", SPEEDS, "--node", "4", "--orders", ORDERS, "--n-freqs",
               "20", "--json", str(tmp_path / "x.json")) == 0
    assert run("spectrum", "cvt_sheave_shaft", "--speeds", SPEEDS, "--node", "4", "--orders", ORDERS, "--n-freqs",
               "20", "--chain", "0.06:84:0.009:0.009:0", "--link-harmonics", "1", "--json",
               str(tmp_path / "p.json")) == 0
    for name, whirls, both_ways in (("x.json", ("forward", "backward"), True),
                                    ("p.json", ("forward", "backward", "axial"), False)):
        spec = json.loads((tmp_path / name).read_text())
        speeds = np.array(spec["speeds_rad_s"])
        step = speeds[1] - speeds[0]
        amp = np.array(spec["order_amplitude"])
        for order in (14.0, 42.0):
            j = spec["orders"].index(order)
            peaks = speeds[find_peaks(amp[:, j])[0]]
            cross = _crossings(camp, order, whirls)
            assert len(peaks) >= 2 and len(cross) >= 2, (name, order)
            assert all(np.min(np.abs(cross - p)) <= step for p in peaks), (name, order, peaks, cross)
            if both_ways:
                assert all(np.min(np.abs(peaks - c)) <= 2 * step for c in cross), (name, order, peaks, cross)


def test_spectrum_writes_json_hdf5_and_pngs(cli, tmp_path):
    lines = tmp_path / "lines.csv"
    lines.write_text("node,dof,order,freq_hz,amplitude,phase_deg\n7,u3,0,1500,20,0\n")
    r = cli("spectrum", "cvt_sheave_shaft", "--speeds", "0:6000rpm:13", "--node", "4", "--chain",
            "0.06:84:0.008:0.01:0.5:3", "--link-harmonics", "1", "--ripple", "4:2:5", "--lines", str(lines),
            "--n-freqs", "30", "--json",
            str(tmp_path / "s.json"), "--results", str(tmp_path / "s.h5"), "--png", str(tmp_path / "s.png"))
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "s.json").read_text())
    n_lines = 84 + 2
    assert len(d["line_labels"]) == n_lines and np.array(d["line_erp_w"]).shape == (13, n_lines)
    with h5py.File(tmp_path / "s.h5", "r") as f:
        assert f.attrs["kind"] == "spectrum" and f.attrs["status"] == "finished"
        assert np.allclose(f["spectrum/line_erp"][:], d["line_erp_w"], rtol=1e-12)
        assert f["spectrum/map"].shape == (13, 30)
    assert (tmp_path / "s.png").stat().st_size > 10_000 and (tmp_path / "s_erp.png").stat().st_size > 10_000


BAD = [("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "99", "--orders", "14"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--chain", "0.06:84:0.009"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--chain", "0.5:84:0.009:0.009:0"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--chain", "0.06:84:0.009:0.009:2"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--ripple", "4:x:5"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--ripple", "4:-2:5"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--lines", "no/such.csv"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--orders", "14", "--png", "x.svg"),
       ("cvt_sheave_shaft", "--speeds", "0:6000rpm:5", "--node", "4", "--orders", "14", "--n-freqs", "1"),
       ("friswell_5_9_1", "--speeds", "0:6000rpm:5", "--node", "2", "--chain", "0.06:84:0.009:0.009:0"),
       ("engine_gear_train", "--speeds", "0:6000rpm:5", "--node", "1", "--orders", "1")]


@pytest.mark.parametrize("args", BAD, ids=range(len(BAD)))
def test_spectrum_bad_input_one_line_exit_2(args, capsys):
    assert run("spectrum", *args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err


def test_spectrum_bad_input_subprocess(cli):
    r = cli("spectrum", "friswell_5_9_1", "--speeds", "0:6000rpm:5", "--node", "2", "--chain", "0.06:84:0.009:0.009:0")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "sheaves" in r.stderr, r.stderr
