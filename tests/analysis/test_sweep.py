"""Parameter sweeps: grid expansion, engines (local pool, dask), worker death, resume and extension."""
import json
import os
import signal
import tomllib
from pathlib import Path

import numpy as np
import pytest

from cvtfem.analysis.run import run_scene
from cvtfem.analysis.sweep import (Variant, expand, nested, parse_vary, read_index, read_list, run_sweep, run_variant,
                                   variant_id)
from cvtfem.errors import InputError
from cvtfem.scene.loader import load_scene

UNTIL = 0.1   # s: band-4dof starts in its stationary regime; the efficiency window is the last 0.05 s
GRID = [("cvt.regime.torque", [100, 200]), ("cvt.regime.ratio", [1.0, 2.0])]


@pytest.fixture(scope="module")
def base():
    return load_scene("band-4dof")


def summaries(index):
    return {e["id"]: e["summary"] for e in index["variants"]}


def dying_work(analysis, scene_toml, source, results, options):
    """run_variant, but the variant at 100 N m, ratio 1 kills its own worker process once (marker file)."""
    regime = tomllib.loads(scene_toml)["cvt"]["regime"]
    marker = Path(results).with_suffix(".killed")
    if (regime["torque"], regime["ratio"]) == (100, 1.0) and not marker.exists():
        marker.write_text(str(os.getpid()))
        os.kill(os.getpid(), signal.SIGKILL)
    return run_variant(analysis, scene_toml, source, results, options)


# -- grid and list expansion ---------------------------------------------------------------------------------

def test_parse_vary_grid_and_list():
    assert parse_vary("cvt.regime.torque=50:250:5") == ("cvt.regime.torque", [50, 100, 150, 200, 250])
    key, values = parse_vary("cvt.regime.ratio=0.5:2:4")
    assert key == "cvt.regime.ratio" and values == pytest.approx([0.5, 1.0, 1.5, 2.0])
    assert all(isinstance(v, float) for v in values)
    assert parse_vary("a.b=1:2:3")[1] == [1.0, 1.5, 2.0]   # integer ends, non-integer steps: floats
    assert parse_vary("cvt.geometry.sheave_profile=conical,toroidal")[1] == ["conical", "toroidal"]
    assert parse_vary("x.y=1,2.5,true")[1] == [1, 2.5, True]


@pytest.mark.parametrize("text", ["cvt.regime.torque", "=1:2:3", "cvt..torque=1:2:3", "a=1:2", "a=1:x:3",
                                  "a=1:2:0", "a=1:2:2.5", "a=nan:1:3", "a="])
def test_parse_vary_rejects_bad_syntax(text):
    with pytest.raises(InputError, match="--vary"):
        parse_vary(text)


def test_expand_grid_ids_and_overrides(base):
    variants = expand(GRID)
    assert len(variants) == 4 and len({v.id for v in variants}) == 4
    assert variants[0].params == {"cvt.regime.torque": 100, "cvt.regime.ratio": 1.0}
    assert variant_id({"b": 1, "a": 2}) == variant_id({"a": 2, "b": 1})     # order-free id
    assert expand(GRID)[3].id == variants[3].id                               # stable across calls
    assert nested({"cvt.regime.torque": 5, "cvt.regime.ratio": 2}) == {"cvt": {"regime": {"torque": 5, "ratio": 2}}}
    rows = [{"cvt.regime.torque": 100}, {"cvt.regime.torque": 100}]
    assert len(expand([("cvt.regime.ratio", [1.0, 2.0])], rows)) == 2          # repeated points run once
    with pytest.raises(InputError, match="each key once"):
        expand([("a.b", [1]), ("a.b", [2])])


def test_read_list_csv_and_toml(tmp_path):
    (tmp_path / "v.csv").write_text("cvt.regime.torque,cvt.geometry.sheave_profile\n100,conical\n200,toroidal\n")
    (tmp_path / "v.toml").write_text("[[variant]]\ncvt.regime.torque = 100\n[[variant]]\ncvt.regime.ratio = 2.0\n")
    assert read_list(tmp_path / "v.csv") == [{"cvt.regime.torque": 100, "cvt.geometry.sheave_profile": "conical"},
                                             {"cvt.regime.torque": 200, "cvt.geometry.sheave_profile": "toroidal"}]
    assert read_list(tmp_path / "v.toml") == [{"cvt.regime.torque": 100}, {"cvt.regime.ratio": 2.0}]
    (tmp_path / "bad.csv").write_text("cvt.regime.torque,cvt.regime.ratio\n100\n")
    with pytest.raises(InputError, match="--list"):
        read_list(tmp_path / "bad.csv")


def test_unknown_key_fails_before_any_work(base, tmp_path):
    with pytest.raises(InputError, match="cvt.regime.torqe"):
        run_sweep(base, expand([("cvt.regime.torqe", [1, 2])]), "run", tmp_path / "s", show_progress=False)
    assert not (tmp_path / "s" / "index.json").exists()


# -- engines -------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def local_sweep(base, tmp_path_factory):
    """The 2x2 sweep on the local pool with 2 workers, and the same variants run directly in this process."""
    direct = {}
    for v in expand(GRID):
        s = run_scene(base.replace(nested(v.params)), until=UNTIL, results=None, show_progress=False)
        direct[v.id] = (s.efficiency, s.ratio, s.clamping_force_N)
    out = tmp_path_factory.mktemp("local")
    return out, run_sweep(base, expand(GRID), "run", out, "local", 2, options={"until": UNTIL},
                          show_progress=False), direct


def test_local_sweep_equals_direct_runs(local_sweep):
    """Each variant is a pure function of its scene: the pool's summaries are bitwise those of run_scene."""
    out, index, direct = local_sweep
    assert [e["status"] for e in index["variants"]] == ["finished"] * 4
    for e in index["variants"]:
        s = e["summary"]
        assert (s["efficiency"], s["ratio"], [s["F1_N"], s["F2_N"]]) == direct[e["id"]]
        assert s["ratio"] == pytest.approx(e["params"]["cvt.regime.ratio"], rel=2e-3)   # the regime is reached
        assert 0.99 < s["efficiency"] < 1.0
        assert (out / e["results"]).is_file()
    assert read_index(out) == index   # the file on disk is the returned index


@pytest.fixture(scope="module")
def dask_scheduler():
    """A dask LocalCluster of 2 single-threaded worker processes, reached through its scheduler address."""
    import logging

    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster:
        yield cluster.scheduler_address


@pytest.mark.slow
def test_dask_sweep_bitwise_equals_local(base, local_sweep, dask_scheduler, tmp_path):
    index = run_sweep(base, expand(GRID), "run", tmp_path, "dask", scheduler=dask_scheduler,
                      options={"until": UNTIL}, show_progress=False)
    assert summaries(index) == summaries(local_sweep[1])


def test_killed_local_worker_is_retried(base, local_sweep, tmp_path):
    """A variant that kills its worker (SIGKILL) once breaks the pool; it is resubmitted and the sweep ends
    with the summaries of the undisturbed sweep."""
    index = run_sweep(base, expand(GRID), "run", tmp_path, "local", 2, options={"until": UNTIL},
                      show_progress=False, work=dying_work)
    killed = variant_id({"cvt.regime.torque": 100, "cvt.regime.ratio": 1.0})
    assert (tmp_path / "variants" / f"{killed}.killed").is_file()
    assert summaries(index) == summaries(local_sweep[1])
    attempts = {e["id"]: e["attempts"] for e in index["variants"]}
    assert attempts[killed] == 2 and all(1 <= a <= 2 for a in attempts.values())


@pytest.mark.slow
def test_killed_dask_worker_is_retried(base, local_sweep, dask_scheduler, tmp_path):
    """dask's scheduler reschedules the task of a dead worker (the nanny restarts the worker)."""
    index = run_sweep(base, expand(GRID), "run", tmp_path, "dask", scheduler=dask_scheduler,
                      options={"until": UNTIL}, show_progress=False, work=dying_work)
    killed = variant_id({"cvt.regime.torque": 100, "cvt.regime.ratio": 1.0})
    assert (tmp_path / "variants" / f"{killed}.killed").is_file()
    assert summaries(index) == summaries(local_sweep[1])


def test_worker_that_keeps_dying_is_recorded_crashed(base, tmp_path):
    params = {"cvt.regime.torque": 100, "cvt.regime.ratio": 1.0}
    index = run_sweep(base, [Variant(variant_id(params), params)], "run", tmp_path, "local", 1,
                      options={"until": UNTIL}, retries=0, show_progress=False, work=dying_work)
    (entry,) = index["variants"]
    assert entry["status"] == "crashed" and "BrokenProcessPool" in entry["error"] and entry["attempts"] == 1


def test_numerical_failure_is_recorded_not_retried(base, tmp_path):
    """An expected failure (here an --until the run driver refuses) is a 'failed' entry with its message."""
    index = run_sweep(base, expand(GRID[:1]), "run", tmp_path, "local", 1, options={"until": -1.0},
                      show_progress=False)
    assert {e["status"] for e in index["variants"]} == {"failed"}
    assert all("--until" in e["error"] and e["attempts"] == 1 for e in index["variants"])


# -- resume and extension ------------------------------------------------------------------------------------

def test_interrupted_sweep_resumes_without_rerunning(base, local_sweep, tmp_path):
    """An index with two finished and two pending variants (a sweep killed midway): the rerun runs only the
    pending ones (finished results files keep their mtime) and ends with the undisturbed summaries."""
    variants = expand(GRID)
    run_sweep(base, variants[:2], "run", tmp_path, "local", 2, options={"until": UNTIL}, show_progress=False)
    index = read_index(tmp_path)
    for v in variants[2:]:   # what the killed sweep had written before it started these two
        index["variants"].append({"id": v.id, "params": v.params, "results": f"variants/{v.id}.h5",
                                  "status": "pending", "attempts": 0, "wall_s": None, "error": "", "summary": {}})
    (tmp_path / "index.json").write_text(json.dumps(index))
    before = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "variants").iterdir()}
    index = run_sweep(base, variants, "run", tmp_path, "local", 2, options={"until": UNTIL}, show_progress=False)
    after = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "variants").iterdir()}
    assert all(after[name] == mtime for name, mtime in before.items())
    assert len(after) == 4
    assert summaries(index) == summaries(local_sweep[1])
    assert [e["attempts"] for e in index["variants"]] == [1, 1, 1, 1]


def test_extended_grid_runs_only_new_points(base, tmp_path):
    first = run_sweep(base, expand(GRID[:1]), "run", tmp_path, "local", 2, options={"until": UNTIL},
                      show_progress=False)
    walls = {e["id"]: e["wall_s"] for e in first["variants"]}
    grid = [("cvt.regime.torque", [100, 150, 200])]
    index = run_sweep(base, expand(grid), "run", tmp_path, "local", 2, options={"until": UNTIL}, show_progress=False)
    assert len(index["variants"]) == 3
    assert all(e["wall_s"] == walls[e["id"]] for e in index["variants"] if e["id"] in walls)
    with pytest.raises(InputError, match="options differs"):
        run_sweep(base, expand(grid), "run", tmp_path, "local", 1, options={"until": 2 * UNTIL}, show_progress=False)


# -- other analyses ------------------------------------------------------------------------------------------

def test_modes_sweep_splits_whirl_pairs_with_speed(tmp_path):
    """Friswell's example 5.9.1 (isotropic bearings): at standstill the lowest modes come in equal pairs;
    spinning splits each pair (gyroscopic backward/forward whirl)."""
    index = run_sweep(load_scene("friswell_5_9_1"), expand([("rotor.speed", [0.0, 400.0])]), "modes", tmp_path,
                      "local", 1, show_progress=False)
    s0, s1 = (e["summary"] for e in index["variants"])
    assert s0["f0_Hz"] == pytest.approx(s0["f1_Hz"], rel=1e-8)
    assert s1["f1_Hz"] - s1["f0_Hz"] > 1e-3 * s1["f0_Hz"]
    modes = json.loads((tmp_path / index["variants"][1]["results"]).read_text())
    assert np.allclose(np.array(modes["wd_rad_s"][:2]) / (2 * np.pi), [s1["f0_Hz"], s1["f1_Hz"]], rtol=0, atol=0)
