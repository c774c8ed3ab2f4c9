"""``cvtfem study accuracy-cost SCENE``: what accuracy costs on a chain transmission (issue 16; spec
numerics-and-periodic section 9): Jacobian spectra with ``v0`` and ``v0/10``, the global error ``E`` of a
pin's axial force over a window for every method and step or tolerance, its cost, and the speed-up table."""
from __future__ import annotations

import argparse
import json
import math

#: Upper bounds checked before any work (each run of the study costs RHS calls of the whole chain).
MAX_SETTINGS = 20
MAX_FIXED_STEPS = 2_000_000     # steps of one fixed-step run
MAX_SAMPLES = 100_000           # output samples in the window
#: The source's Table 2.4 baseline: RK4 at this step, s.
BASELINE_H = 5e-8


def add_subparser(s) -> None:
    """The ``accuracy-cost`` study under ``cvtfem study``."""
    e = s.add_parser("accuracy-cost", help="accuracy against cost on a chain transmission (spectra, global error "
                                           "of a pin force, speed-up table; spec section 9)")
    e.add_argument("scene", metavar="SCENE", help="chain-CVT scene or preset, e.g. chain-S2,regime-chapter2")
    e.add_argument("--window", default="1e-3:5e-3", help="T1:T2, s: the error window (the run spans 0..T2)")
    e.add_argument("--sample", type=float, default=1e-5, help="output step in the window, s")
    e.add_argument("--fixed", default="rk4,dopri45,dumka3", help="fixed-step methods (comma-separated specs)")
    e.add_argument("--steps", default="5e-8,1e-7,2e-7,5e-7,1e-6", help="fixed steps h, s")
    e.add_argument("--adaptive", default="Radau,BDF,rodas5p", help="adaptive methods (comma-separated specs)")
    e.add_argument("--rtols", default="1e-2,1e-3,1e-4,1e-5", help="tolerances of the adaptive runs (atol = 1e-3 rtol)")
    e.add_argument("--reference", default="Radau:1e-8", help="METHOD:RTOL of the reference run")
    e.add_argument("--check", default="rodas5p:1e-8", help="METHOD:RTOL of the second, independent reference")
    e.add_argument("--repeats", type=int, default=3, help="wall time = median of this many runs")
    e.add_argument("--png", default="out/studies/accuracy_cost.png", help="E against wall time and RHS calls")
    e.add_argument("--spectrum-png", default="out/studies/accuracy_cost_spectrum.png",
                   help="Jacobian eigenvalues at the window's start, with v0 and v0/10")
    e.add_argument("--csv", default="out/studies/accuracy_cost.csv", help="one row per run")
    e.add_argument("--json", default="out/studies/accuracy_cost.json", help="reference report and speed-up table")


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


def run(args: argparse.Namespace) -> int:
    from cvtfem.analysis import accuracy_cost as ac
    from cvtfem.analysis.timing import machine
    from cvtfem.commands.study import _floats, _out, parse_method
    from cvtfem.errors import InputError
    from cvtfem.post import accuracy_cost as plots
    from cvtfem.post.integrators import write_csv
    from cvtfem.scene.loader import load_scene

    try:
        window = tuple(float(v) for v in args.window.split(":"))
    except ValueError:
        window = ()
    if len(window) != 2 or not (0 <= window[0] < window[1] <= 1.0):
        raise InputError("--window", args.window, "must be T1:T2 in s with 0 <= T1 < T2 <= 1")
    fixed = [parse_method(m) for m in args.fixed.split(",") if m.strip()]
    adaptive = [parse_method(m) for m in args.adaptive.split(",") if m.strip()]
    steps, rtols = _floats(args.steps, "--steps"), _floats(args.rtols, "--rtols")
    _check(args, fixed, steps, adaptive, rtols, window)
    reference, check = _pair(args.reference, "--reference"), _pair(args.check, "--check")
    scene = load_scene(args.scene)
    problem, report = ac.pin_force_problem(scene, window, args.sample, reference, check)
    print(f"{args.scene}: {report['start']}; pin {report['pin']} axial force {report['force_range_N'][0]:.0f}.."
          f"{report['force_range_N'][1]:.0f} N over {window[0]:g}..{window[1]:g} s; references {report['reference']}"
          f" and {report['check']} differ by E = {report['reference_E']:.2e}")
    lam, lam_v0 = ac.spectrum_with_v0(scene, problem.y0)
    v0 = scene.cvt.friction.v0
    plots.plot_spectra({f"v0 = {v0:g} m/s": lam, f"v0 = {v0 / 10:g} m/s": lam_v0}, _out(args.spectrum_png),
                       f"{args.scene}: Jacobian eigenvalues at the start state ({len(lam)} states)")
    rows = ac.measure(problem, fixed, steps, adaptive, rtols, args.repeats)
    base = [r for r in rows if r["method"] == "rk4" and r.get("h") == BASELINE_H]
    table = ac.speedups(rows, base[0] if base else None)
    print(f"{'method':<22}{'setting':>12}{'E':>11}{'wall s':>9}{'RHS':>9}{'speed-up':>10}   "
          f"(cheapest run with E <= {ac.ACCEPT_E}; baseline rk4 h={BASELINE_H:g})")
    for t in table:
        if t["setting"] is None:
            print(f"{t['label']:<22}{'none':>12}")
            continue
        up = f"{t['speedup']:.1f}x" if t["speedup"] else "-"
        print(f"{t['label']:<22}{t['setting']:>12}{t['error']:>11.2e}{t['time']:>9.2f}{t['nfev']:>9}{up:>10}")
    plots.plot_accuracy_cost(rows, _out(args.png), ac.ACCEPT_E,
                             f"{args.scene}: E of pin {report['pin']}'s axial force over {window[0]:g}..{window[1]:g} s"
                             f" vs reference {report['reference']}")
    write_csv(rows, _out(args.csv))
    with open(_out(args.json), "w", encoding="utf-8") as fh:
        json.dump({"scene": args.scene, "machine": machine(), "reference": report, "speedups": table}, fh, indent=1)
    print(f"wrote {args.png}, {args.spectrum_png}, {args.csv}, {args.json}")
    return 0
