"""``cvtfem study accuracy-cost SCENE``: what accuracy costs on a CVT transmission (issue 16; spec
numerics-and-periodic section 9): Jacobian spectra with ``v0`` and ``v0/10``, the global error ``E`` of a
pin's axial force over a window for every method and step or tolerance, its cost, and the speed-up table;
with ``--local``, test 1 instead: the local error of one step and the effective order of every method."""
from __future__ import annotations

import argparse
import json
import math

#: Upper bounds checked before any work (each run of the study costs RHS calls of the whole chain).
MAX_SETTINGS = 20
MAX_FIXED_STEPS = 2_000_000     # steps of one fixed-step run
MAX_SAMPLES = 100_000           # output samples in the window
MAX_LOCAL_HS = 40               # steps of test 1
#: Steps of test 1 by default, s: the source's grid 1e-8 .. 1e-5 (section 9.4).
LOCAL_HS = "1e-8:1e-5:13"
#: The source's Table 2.4 baseline: RK4 at this step, s.
BASELINE_H = 5e-8


def add_subparser(s) -> None:
    """The ``accuracy-cost`` study under ``cvtfem study``."""
    e = s.add_parser("accuracy-cost", help="accuracy against cost on a chain transmission (spectra, global error "
                                           "of a pin force, speed-up table; spec section 9)")
    e.add_argument("scene", metavar="SCENE", help="chain-CVT scene or preset, e.g. chain-S2,regime-chapter2")
    e.add_argument("--window", default="1e-3:5e-3", help="T1:T2, s: the error window (the run spans 0..T2)")
    e.add_argument("--settle", type=float, default=0.0,
                   help="start every run (and the spectra, test 1) at this time, from the state the --reference "
                        "method reaches there, s (0: from the scene's start state; at most T1)")
    e.add_argument("--placed", action="store_true",
                   help="A5 chains: start from the chain placed on the sheaves without trying the quasi-static solve")
    e.add_argument("--sample", type=float, default=1e-5, help="output step in the window, s")
    e.add_argument("--fixed", default="rk4,dopri45,dumka3", help="fixed-step methods (comma-separated specs)")
    e.add_argument("--steps", default="5e-8,1e-7,2e-7,5e-7,1e-6", help="fixed steps h, s")
    e.add_argument("--adaptive", default="Radau,BDF,rodas5p", help="adaptive methods (comma-separated specs)")
    e.add_argument("--rtols", default="1e-2,1e-3,1e-4,1e-5", help="tolerances of the adaptive runs (atol = 1e-3 rtol)")
    e.add_argument("--reference", default="Radau:1e-8", help="METHOD:RTOL of the reference run")
    e.add_argument("--check", default="rodas5p:1e-8", help="METHOD:RTOL of the second, independent reference")
    e.add_argument("--repeats", type=int, default=3, help="wall time = median of this many runs")
    e.add_argument("--cache", default="",
                   help="directory keeping the reference outputs and the rows of test 2: a study run again (or split "
                        "over processes sharing it) runs only what it does not hold")
    e.add_argument("--from-cache", action="store_true",
                   help="with --cache: the tables and figures from every run the cache holds (runs nothing new)")
    e.add_argument("--png", default="out/studies/accuracy_cost.png", help="E against wall time and RHS calls")
    e.add_argument("--spectrum-png", default="out/studies/accuracy_cost_spectrum.png",
                   help="Jacobian eigenvalues at the window's start, with v0 and v0/10")
    e.add_argument("--skip-spectrum", action="store_true",
                   help="no spectra (two dense eigenvalue problems: minutes on A5's 3544 states)")
    e.add_argument("--csv", default="out/studies/accuracy_cost.csv", help="one row per run")
    e.add_argument("--json", default="out/studies/accuracy_cost.json", help="reference report and speed-up table")
    e.add_argument("--local", action="store_true",
                   help="test 1 instead of test 2: local error of one step against h and the effective order")
    e.add_argument("--methods", default="", help="with --local: methods (default every method of the playground)")
    e.add_argument("--hs", default=LOCAL_HS, help="with --local: steps LO:HI:COUNT (log grid) or a list, s")
    e.add_argument("--local-at", type=float, default=None,
                   help="with --local: time of the state the steps start from, s (default T1 of --window)")
    e.add_argument("--local-png", default="out/studies/accuracy_cost_local.png", help="with --local: e(h) and p~(h)")
    e.add_argument("--local-csv", default="out/studies/accuracy_cost_local.csv", help="with --local: one row per step")


def _pair(text: str, where: str) -> tuple[str, float]:
    from cvtfem.errors import InputError

    name, _, rtol = text.partition(":")
    try:
        value = float(rtol)
    except ValueError:
        value = math.nan
    if not name or not (1e-14 <= value < 1):
        raise InputError(where, text, "must be METHOD:RTOL with 1e-14 <= RTOL < 1, e.g. Radau:1e-8")
    return name, value


def _check(args, fixed, steps, adaptive, rtols, window) -> None:
    from cvtfem.errors import InputError
    from cvtfem.integrate.methods import METHODS, SCIPY_METHODS

    t1, t2 = window
    for where, specs in (("--fixed", fixed), ("--adaptive", adaptive)):
        for _, method, _ in specs:
            if method not in METHODS and (where == "--fixed" or method not in SCIPY_METHODS):
                allowed = sorted(METHODS) + ([] if where == "--fixed" else sorted(SCIPY_METHODS))
                raise InputError(where, method, "must name methods of the playground: " + ", ".join(allowed))
    for where, values in (("--steps", steps), ("--rtols", rtols)):
        if len(values) > MAX_SETTINGS:
            raise InputError(where, len(values), f"must hold at most {MAX_SETTINGS} values")
    for h in steps:
        if not (math.isfinite(h) and h > 0 and t2 / h <= MAX_FIXED_STEPS):
            raise InputError("--steps", h, f"must be positive steps, at most {MAX_FIXED_STEPS} over the {t2:g} s run")
    for r in rtols:
        if not (1e-14 <= r < 1):
            raise InputError("--rtols", r, "must be tolerances in 1e-14..1")
    if not (math.isfinite(args.sample) and args.sample > 0 and (t2 - t1) / args.sample <= MAX_SAMPLES):
        raise InputError("--sample", args.sample, f"must be positive and give at most {MAX_SAMPLES} samples")
    if not 1 <= args.repeats <= 100:
        raise InputError("--repeats", args.repeats, "must be 1..100")


def _local_steps(text: str) -> list[float]:
    """``LO:HI:COUNT`` (log grid) or a comma-separated list of steps, s."""
    from cvtfem.commands.study import _floats
    from cvtfem.errors import InputError

    import numpy as np

    if ":" in text:
        try:
            lo, hi, count = (float(v) for v in text.split(":"))
        except ValueError:
            lo = hi = count = math.nan
        if not (0 < lo < hi < 1 and 2 <= count <= MAX_LOCAL_HS and count == int(count)):
            raise InputError("--hs", text, f"must be LO:HI:COUNT with 0 < LO < HI < 1 s and 2 <= COUNT <= "
                             f"{MAX_LOCAL_HS}, or a list of steps")
        return [float(h) for h in np.geomspace(lo, hi, int(count))]
    hs = _floats(text, "--hs")
    if not (2 <= len(hs) <= MAX_LOCAL_HS and all(math.isfinite(h) and 0 < h < 1 for h in hs)):
        raise InputError("--hs", text, f"must be 2..{MAX_LOCAL_HS} steps in (0, 1) s")
    return hs


def run_local(args: argparse.Namespace, window) -> int:
    """Test 1 (section 9.4): one step of every method from a state of the run, at every step of ``--hs``."""
    import dataclasses

    from cvtfem.analysis import accuracy_cost as ac
    from cvtfem.commands.study import _out, parse_method
    from cvtfem.errors import InputError
    from cvtfem.integrate.methods import METHODS
    from cvtfem.post import accuracy_cost as plots
    from cvtfem.post.integrators import write_csv
    from cvtfem.scene.loader import load_scene

    names = [m for m in args.methods.split(",") if m.strip()] or [m for m, cls in METHODS.items()
                                                                    if not getattr(cls, "needs_split", False)]
    methods = [parse_method(m) for m in names]
    for _, method, _ in methods:
        if method not in METHODS:
            raise InputError("--methods", method, "must name fixed-step methods of the playground: "
                             + ", ".join(sorted(METHODS)))
    hs = _local_steps(args.hs)
    t_at = window[0] if args.local_at is None else args.local_at
    if not (math.isfinite(t_at) and 0 <= t_at <= window[1]):
        raise InputError("--local-at", t_at, f"must be a time in 0..{window[1]:g} s (T2 of --window)")
    if not args.settle <= t_at:
        raise InputError("--settle", args.settle, f"must be at most the time of --local-at, {t_at:g} s")
    reference = _pair(args.reference, "--reference")
    scene = load_scene(args.scene)
    problem, start = ac.cvt_problem(scene, window[1], args.settle, reference, args.placed)
    x = ac.state_at(problem, t_at, *reference)
    rows = ac.local_error_table(dataclasses.replace(problem, y0=x, t_span=(t_at, window[1])), methods, hs)
    print(f"{args.scene}: start {start['start']}" + (f", settled to {args.settle:g} s by {start['settled_by']}"
                                                      if args.settle else ""))
    print(f"local error of one step from the state at t = {t_at:g} s ({len(x)} states; norm: max over "
          f"components of |error| / block scale)")
    for label in dict.fromkeys(r["label"] for r in rows):
        mine = [r for r in rows if r["label"] == label]
        print(f"{label:28s} nominal {mine[0]['nominal']}  p~ = " + " ".join(f"{r['p_eff']:5.2f}" for r in mine[1:]))
    plots.plot_local_errors(rows, _out(args.local_png), f"{args.scene}: test 1 from the state at t = {t_at:g} s")
    write_csv(rows, _out(args.local_csv))
    print(f"wrote {args.local_png}, {args.local_csv}")
    return 0


def run(args: argparse.Namespace) -> int:
    from cvtfem.analysis import accuracy_cost as ac
    from cvtfem.analysis.timing import machine
    from cvtfem.commands.study import _floats, _out, parse_method
    from cvtfem.errors import InputError
    from cvtfem.post import accuracy_cost as plots
    from cvtfem.post.integrators import write_csv
    from cvtfem.scene.loader import load_scene

    import numpy as np

    try:
        window = tuple(float(v) for v in args.window.split(":"))
    except ValueError:
        window = ()
    if len(window) != 2 or not (0 <= window[0] < window[1] <= 1.0):
        raise InputError("--window", args.window, "must be T1:T2 in s with 0 <= T1 < T2 <= 1")
    if not (math.isfinite(args.settle) and 0 <= args.settle <= window[0]):
        raise InputError("--settle", args.settle, f"must be a time in 0..{window[0]:g} s (T1 of --window)")
    if args.local:
        return run_local(args, window)
    fixed = [parse_method(m) for m in args.fixed.split(",") if m.strip()]
    adaptive = [parse_method(m) for m in args.adaptive.split(",") if m.strip()]
    steps, rtols = _floats(args.steps, "--steps"), _floats(args.rtols, "--rtols")
    _check(args, fixed, steps, adaptive, rtols, window)
    reference, check = _pair(args.reference, "--reference"), _pair(args.check, "--check")
    if args.from_cache and not args.cache:
        raise InputError("--from-cache", True, "must come with --cache DIR (the directory whose runs it tabulates)")
    scene = load_scene(args.scene)
    cache = ac.StudyCache(args.cache, f"{args.scene} window {args.window} sample {args.sample:g} settle "
                                      f"{args.settle:g} placed {args.placed} reference {args.reference}"
                          ) if args.cache else None
    problem, report = ac.pin_force_problem(scene, window, args.sample, reference, check, args.settle, args.placed,
                                           cache)
    t0, span = problem.t_span[0], window[1] - problem.t_span[0]
    unit = "N/m" if report["output"] == ac.BAND_FORCE else "N"
    what = f"{ac.output_component(report)} {'sheave normal' if unit == 'N/m' else 'axial'} force, {unit}"
    print(f"{args.scene}: start {report['start']}" + (f"; settled to {t0:g} s by {report['settled_by']}" if t0
                                                       else ""))
    print(f"{what} {report['force_range'][0]:.0f}..{report['force_range'][1]:.0f} over {window[0]:g}..{window[1]:g} s;"
          f" references {report['reference']} and {report['check']} differ by E = {report['reference_E']:.2e}")
    spectrum = None
    if not args.skip_spectrum:
        lam, lam_v0 = ac.spectrum_with_v0(scene, problem.y0, t=t0)
        v0 = scene.cvt.friction.v0
        plots.plot_spectra({f"v0 = {v0:g} m/s": lam, f"v0 = {v0 / 10:g} m/s": lam_v0}, _out(args.spectrum_png),
                           f"{args.scene}: Jacobian eigenvalues at the state at t = {t0:g} s ({len(lam)} states)")
        spectrum = spectrum_summary(lam, lam_v0)
        print(f"spectrum at t = {t0:g} s: min Re {lam.real.min():.3g} 1/s ({lam_v0.real.min():.3g} with v0/10), max "
              f"|Im| {np.abs(lam.imag).max():.3g} 1/s ({np.abs(lam_v0.imag).max():.3g}), max Re {lam.real.max():.3g}")
    stale = cache.stale_rows() if args.from_cache else []
    if stale:
        print(f"WARNING: {len(stale)} of the {len(cache.rows)} rows were measured with other code than today's (run "
              f"them again without --from-cache): {', '.join(stale)}")
    rows = ac.distinct_labels(sorted(cache.rows.values(), key=lambda r: (r["label"], -r.get("h", r.get("rtol", 0.0))))
                              if args.from_cache else
                              ac.measure(problem, fixed, steps, adaptive, rtols, args.repeats, cache))
    base = ac.baseline_time(rows, BASELINE_H, span)
    costs = ac.operation_costs(problem)
    if costs:
        print(f"one RHS call {costs['rhs'] * 1e3:.3g} ms CPU; one Jacobian {costs['jac_rhs']:.1f}, one LU "
              f"{costs['lu_rhs']:.1f}, one solve {costs['solve_rhs']:.2f} RHS-equivalents (at the start state)")
    table = ac.speedups(rows, base, costs=costs)
    how = ("none: no rk4 runs" if base is None else
           f"{base['time']:.1f} s, " + ("estimated from the rk4 runs' wall time per RHS call" if base["estimated"]
                                        else "measured") + (" (the study's run at that step failed)"
                                                            if base.get("failed") else ""))
    print(f"cheapest run (by CPU time) with E <= {ac.ACCEPT_E} and |energy residual| <= {ac.ACCEPT_ENERGY:g} per method; "
          f"speed-up over rk4 at h = {BASELINE_H:g} s ({how})")
    for line in markdown_table(table):
        print(line)
    plots.plot_accuracy_cost(rows, _out(args.png), ac.ACCEPT_E,
                             f"{args.scene}: E of {what} over {window[0]:g}..{window[1]:g} s"
                             f" vs reference {report['reference']}")
    write_csv(rows, _out(args.csv))
    with open(_out(args.json), "w", encoding="utf-8") as fh:
        json.dump({"scene": args.scene, "machine": machine(), "reference": report, "baseline": base,
                   "wall_per_simulated_s": wall_per_simulated_second(table, span),
                   "cpu_per_simulated_s": wall_per_simulated_second(table, span, "cpu"), "speedups": table,
                   "operation_costs": costs,
                   "spectrum": spectrum}, fh, indent=1)
    print(f"wrote {args.png}, " + ("" if args.skip_spectrum else f"{args.spectrum_png}, ") + f"{args.csv}, {args.json}")
    return 0


def wall_per_simulated_second(table, span: float, key: str = "time") -> dict:
    """Wall time (``key = "cpu"``: CPU time), s, per simulated second of each method's cheapest accepted run over
    ``span`` s."""
    return {t["label"]: t[key] / span for t in table if t.get(key) is not None}


def spectrum_summary(lam, lam_v0) -> dict:
    """The extremes of the spectra with ``v0`` and ``v0/10``, 1/s, for the JSON report."""
    import numpy as np

    return {key: {"min_re": float(x.real.min()), "max_re": float(x.real.max()), "max_abs_im": float(np.abs(x.imag).max())}
            for key, x in (("v0", lam), ("v0/10", lam_v0))}


def markdown_table(table) -> list[str]:
    """The speed-up table in the style of the source's Table 2.4, as Markdown lines: cost counters, the energy
    balance's residual over the run (relative to the input work), and the speed-ups by wall time, CPU time and
    RHS-equivalents."""
    lines = ["| method | cheapest accepted setting | E | energy residual | wall s | CPU s | RHS calls | Jacobians "
             "| LUs | solves | steps | speed-up wall | CPU | RHS-eq |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]

    def fmt(value, spec, suffix=""):
        return "-" if value is None else f"{value:{spec}}{suffix}"

    for t in table:
        if t["setting"] is None:
            lines.append(f"| {t['label']} | none |" + " |" * 12)
            continue
        solves = t.get("nsolve")
        lines.append(f"| {t['label']} | {t['setting']} | {t['error']:.2e} | {fmt(t.get('energy_residual'), '.1e')} | "
                     f"{t['time']:.2f} | {fmt(t.get('cpu'), '.2f')} | {t['nfev']} | {t['njev']} | {t['nlu']} | "
                     f"{solves if solves is not None and solves >= 0 else '-'} | {t['nsteps']} | "
                     f"{fmt(t['speedup'], '.1f', 'x')} | {fmt(t.get('speedup_cpu'), '.1f', 'x')} | "
                     f"{fmt(t.get('speedup_rhs'), '.1f', 'x')} |")
    return lines
