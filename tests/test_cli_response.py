"""``cvtfem response`` through a real subprocess."""
import json


def test_response_writes_json_csv_and_pngs(cli, tmp_path):
    r = cli("response", "friswell_5_9_1", "--unbalance", "2:1e-4:0", "--speeds", "0:4000rpm:41", "--node", "2",
            "--orders", "1,2", "--n-modes", "6", "--json", str(tmp_path / "r.json"), "--csv",
            str(tmp_path / "r.csv"), "--png", str(tmp_path / "bode.png"), "--results", str(tmp_path / "r.h5"))
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "r.json").read_text())
    assert len(d["speeds_rad_s"]) == 41 and len(d["order_amplitude_m_per_N"][0]) == 2
    assert len((tmp_path / "r.csv").read_text().splitlines()) == 42
    import h5py
    import numpy as np

    with h5py.File(tmp_path / "r.h5", "r") as f:
        assert f.attrs["kind"] == "response" and f.attrs["status"] == "finished"
        assert np.allclose(np.abs(f["response/x"][:]), d["amplitude_x_m"], rtol=1e-12)
        assert f["response/map"].shape == (41, len(d["map_freqs_rad_s"]))
    assert (tmp_path / "bode.png").stat().st_size > 10_000 and (tmp_path / "bode_orders.png").stat().st_size > 10_000


def test_response_bad_input_one_line_exit_2(cli):
    cases = [("friswell_5_9_1", "--unbalance", "9:1e-4:0", "--speeds", "0:4000rpm:11", "--node", "2"),
             ("friswell_5_9_1", "--unbalance", "2:1e-4:0", "--speeds=-100:4000rpm:11", "--node", "2"),
             ("engine_gear_train", "--unbalance", "1:1e-4:0", "--speeds", "0:4000rpm:11", "--node", "1")]
    for args in cases:
        r = cli("response", *args)
        assert r.returncode == 2, (args, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr, r.stderr
    assert "supported: rotor" in r.stderr
