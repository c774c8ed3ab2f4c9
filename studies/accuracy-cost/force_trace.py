"""Test 2's output over the window for a few fixed-step runs against the study's cached reference: the force trace
behind each E (does RK4 at a step beyond its linear stability limit chatter, and does E hold over the window?).
Run from the repository root after the study has filled its cache (`cvtfem study accuracy-cost ... --cache DIR`):

    .venv/bin/python studies/accuracy-cost/force_trace.py STUDY.json CACHE_DIR METHOD[:OPTION=VALUE...]:H[,...] OUT.png

STUDY.json is the study's `--json` (scene, window, start, reference method and the output component); the runs start
as the study's did (from the start state the cache keeps, else `--placed` when its report says so) and sample the
same times.  Method options as the study's, e.g. `sw24:jac_every=20:5e-7`.
"""
from __future__ import annotations

import json
from dataclasses import replace
import sys

import numpy as np

from cvtfem.analysis import accuracy_cost as ac
from cvtfem.blas import single_thread_blas
from cvtfem.commands.study import parse_method
from cvtfem.integrate import solve
from cvtfem.post.accuracy_cost import plot_force_traces
from cvtfem.scene.loader import load_scene


def main(study_json: str, cache_dir: str, runs: str, png: str) -> None:
    report = json.load(open(study_json, encoding="utf-8"))
    ref = report["reference"]
    t1, t2 = ref["window"]
    method, rtol = ref["reference"].split(" rtol ")
    p_all = np.load(f"{cache_dir}/reference-{method}-{float(rtol):g}.npy")
    t_eval = np.linspace(t1, t2, p_all.shape[0])
    placed = ref["start"].startswith("placed")
    problem, _ = ac.cvt_problem(load_scene(report["scene"]), t2, placed=placed)
    problem = replace(problem, t_eval=t_eval)
    k = ref["pin"]
    series = {}
    for spec in runs.split(","):
        method_spec, _, h = spec.rpartition(":")
        label, name, opts = parse_method(method_spec)
        res = solve(**problem.solve_kwargs(), method=name, h=float(h), t_eval=t_eval, **opts)
        p = problem.pin_forces(res.y, res.t)[:, k] if res.success else np.full(len(t_eval), np.nan)
        series[f"{label} h = {float(h):g} s"] = p
        print(f"{label} h = {float(h):g} s: E = {ac.window_error(p, p_all[:, k]):.3g} ({res.message})", flush=True)
    plot_force_traces(t_eval, p_all[:, k], series, png, ac.ACCEPT_E,
                      f"{report['scene']}: {ac.output_component(ref)} axial force, reference {ref['reference']}, "
                      f"start {'placed' if placed else 'quasi-static'}")
    print(f"wrote {png}")


if __name__ == "__main__":
    with single_thread_blas():
        main(*sys.argv[1:5])
