"""``cvtfem study stability|order|work|heat|accuracy-cost``: integrator studies (PNG + CSV).

Method specs are ``NAME[:key=value...]``, e.g. ``gbs-smooth:stages=2`` or ``sw24:d=0.5``.
``order`` and ``work`` also run on a band-model scene (``--scene band-6+2n --until 0.05``): its
closed loop with the second-order structure and analytic Jacobian; ``work`` then measures the
relative error of ratio, speeds and work ratio at the end against Radau at ``--ref-rtol``.
"""
from __future__ import annotations

import argparse
import math
import platform
from pathlib import Path

from cvtfem.commands import accuracy_cost

DEFAULT_STABILITY = ("euler,rk4,dopri45,dopri56,dopri78,gbs:stages=2,gbs-smooth:stages=2,"
                     "euler-extrapolation:stages=4,sw24:d=0.5,w1:d=1.0,w1-extrapolation:d=0.5:stages=4,"
                     "trapezoidal,implicit-euler,rkc:stages=5,rock2:stages=5,rock4:stages=5,dumka3:polynomial=0")
#: Upper bounds of what a study may be asked for (checked before any work; each message names the cost).
MAX_METHODS = 40        # methods per study (a panel or a row each)
MAX_PIXELS = 2001       # `stability --n`: n^2 amplification factors per method
MAX_EXTENT = 1e8        # `stability --extent`
MAX_HS = 50             # `order --hs` COUNT
MAX_SETTINGS = 20       # `work --rtols` / `--steps` entries
MIN_RTOL = 1e-14        # below double precision's reach
MAX_FIXED_STEPS = 10_000_000    # steps of one fixed-step run of `work --steps`
MAX_REPEATS = 100
MAX_HEAT_N = 1000       # `heat --N`: RK4 needs ~0.15 N^2 steps of N unknowns (1.5e5 at N = 1000, minutes)
MAX_UNTIL = 10.0        # s: `--scene ... --until` (the reference at --ref-rtol takes minutes per second)
DEFAULT_ORDER = ("euler,rk4,dopri45,dopri56,dopri78,gbs:stages=2,sw24,trapezoidal,rkc:stages=10,"
                 "dumka3:polynomial=6")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("study", help="integrator studies: stability regions, effective order, "
                                     "work-precision, heat-equation benchmark, accuracy-cost on a chain")
    s = p.add_subparsers(dest="study", metavar="STUDY", required=True)
    a = s.add_parser("stability", help="stability regions of methods on the complex h*lambda plane")
    a.add_argument("--methods", default=DEFAULT_STABILITY, help="comma-separated method specs")
    a.add_argument("--log", action="store_true", help="signed-log axes (spec §2.3) instead of linear")
    a.add_argument("--extent", type=float, default=6.0, help="half-width of the linear plane")
    a.add_argument("--n", type=int, default=401, help="pixels per axis")
    a.add_argument("--png", default="out/studies/stability.png", help="output PNG")
    b = s.add_parser("order", help="effective-order test: local error vs h (spec §9.4)")
    b.add_argument("--problem", default="limit_cycle", help="problem name (cvtfem.problems.PROBLEMS)")
    _scene_args(b)
    b.add_argument("--methods", default=DEFAULT_ORDER)
    b.add_argument("--hs", default="0.4:0.0125:6", help="H_MAX:H_MIN:COUNT (log spaced)")
    b.add_argument("--png", default="out/studies/order.png")
    b.add_argument("--csv", default="out/studies/order.csv")
    c = s.add_parser("work", help="work-precision diagram of methods on a problem")
    c.add_argument("--problem", default="hires")
    _scene_args(c)
    c.add_argument("--methods", default="trapezoidal,sw24,Radau,BDF")
    c.add_argument("--rtols", default="1e-2,1e-3,1e-4,1e-5,1e-6", help="tolerances of adaptive runs")
    c.add_argument("--steps", default="", help="fixed steps h instead of tolerances (comma separated)")
    c.add_argument("--repeats", type=int, default=3, help="wall time = median of this many runs")
    c.add_argument("--png", default="out/studies/work.png")
    c.add_argument("--csv", default="out/studies/work.csv")
    d = s.add_parser("heat", help="benchmark: heat equation, RHS calls and time at a target error")
    d.add_argument("--N", type=int, default=1000)
    d.add_argument("--target", type=float, default=1e-4)
    d.add_argument("--repeats", type=int, default=3)
    d.add_argument("--methods", default="", help="subset (default: the issue's list)")
    d.add_argument("--csv", default="out/studies/heat_benchmark.csv")
    accuracy_cost.add_subparser(s)
    p.set_defaults(func=run)


def _scene_args(p) -> None:
    p.add_argument("--scene", default="", help="band-model scene or preset instead of --problem")
    p.add_argument("--until", type=float, default=0.05, help="with --scene: simulated time, s")
    p.add_argument("--ref-rtol", type=float, default=1e-9, help="with --scene: rtol of the Radau reference")


def parse_method(spec: str) -> tuple[str, str, dict]:
    """``"gbs:stages=2"`` -> ``("gbs:stages=2", "gbs", {"stages": 2})``; ``true``/``false`` become booleans."""
    from cvtfem.errors import InputError

    import inspect

    from cvtfem.integrate.driver import solve
    from cvtfem.integrate.methods import parse_options

    name, *pairs = spec.strip().split(":")
    opts = parse_options(pairs, "--methods", "gbs:stages=2")
    for key in opts:
        if key in inspect.signature(solve).parameters:   # h, rtol, ...: the study sets them
            raise InputError("--methods", spec, f"options must be the method's own, not `{key}` (the study sets it)")
    return spec.strip(), name, opts


def _floats(text: str, where: str) -> list[float]:
    from cvtfem.errors import InputError

    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(where, text, "must be comma-separated numbers") from None


def _problem(name: str, args=None):
    from cvtfem.errors import InputError
    from cvtfem.problems import PROBLEMS

    if args is not None and getattr(args, "scene", ""):
        from cvtfem.analysis.study_problem import scene_problem

        return scene_problem(args.scene, args.until, ref_rtol=args.ref_rtol)

    if name not in PROBLEMS:
        raise InputError("--problem", name, f"must be one of {sorted(PROBLEMS)}")
    return PROBLEMS[name]()


def _check_args(args: argparse.Namespace, methods: list) -> None:
    """Counts, sizes and values of a study's arguments within their bounds, before any work."""
    from cvtfem.errors import InputError

    def bounded(where: str, value: float, lo: float, hi: float, rule: str = "") -> None:
        if not (math.isfinite(value) and lo <= value <= hi):
            raise InputError(where, value, f"must lie in {lo:g}..{hi:g}{rule}")

    if args.study != "heat" and not 1 <= len(methods) <= MAX_METHODS:
        raise InputError("--methods", args.methods, f"must name 1..{MAX_METHODS} methods, comma separated")
    if args.study == "stability":
        bounded("--n", args.n, 2, MAX_PIXELS, f" pixels per axis ({args.n}^2 evaluations per method)")
        if not (math.isfinite(args.extent) and 0 < args.extent <= MAX_EXTENT):
            raise InputError("--extent", args.extent, f"must be a half-width in (0, {MAX_EXTENT:g}]")
    if hasattr(args, "repeats"):
        bounded("--repeats", args.repeats, 1, MAX_REPEATS, " (runs per setting)")
    if getattr(args, "scene", ""):
        bounded("--until", args.until, 0.0, MAX_UNTIL, " s (the reference run costs minutes per simulated second)")
        bounded("--ref-rtol", args.ref_rtol, MIN_RTOL, 1e-2)
    if args.study == "heat":
        bounded("--N", args.N, 3, MAX_HEAT_N, f" (RK4 needs ~{0.15 * args.N ** 2:.3g} steps of {args.N} unknowns)")
        if not (math.isfinite(args.target) and 0 < args.target < 1):
            raise InputError("--target", args.target, "must be a relative error in (0, 1)")


def _hs(text: str):
    """``H_MAX:H_MIN:COUNT`` -> COUNT log-spaced steps from H_MAX down to H_MIN."""
    import numpy as np

    from cvtfem.errors import InputError

    try:
        hmax, hmin, n = text.split(":")
        hmax, hmin, n = float(hmax), float(hmin), int(n)
    except ValueError:
        raise InputError("--hs", text, "must be H_MAX:H_MIN:COUNT") from None
    if not (math.isfinite(hmax) and 0 < hmin < hmax and 2 <= n <= MAX_HS):
        raise InputError("--hs", text, "must be H_MAX:H_MIN:COUNT with finite H_MAX > H_MIN > 0 and COUNT in "
                         f"2..{MAX_HS}")
    return np.geomspace(hmax, hmin, n)


def _settings(args: argparse.Namespace, t_span) -> list[dict]:
    """The runs of `work`: fixed steps ``--steps`` (at most MAX_FIXED_STEPS over the span) or tolerances ``--rtols``."""
    from cvtfem.errors import InputError

    steps = _floats(args.steps, "--steps")
    values = steps or _floats(args.rtols, "--rtols")
    where = "--steps" if steps else "--rtols"
    if not 1 <= len(values) <= MAX_SETTINGS:
        raise InputError(where, args.steps or args.rtols, f"must hold 1..{MAX_SETTINGS} values")
    span = t_span[1] - t_span[0]
    for v in values:
        if steps and not (math.isfinite(v) and v > 0 and span / v <= MAX_FIXED_STEPS):
            raise InputError("--steps", v, f"must be step sizes > {span / MAX_FIXED_STEPS:.3g} s (at most "
                             f"{MAX_FIXED_STEPS:.0e} steps over the problem's {span:g} s)")
        if not steps and not (math.isfinite(v) and MIN_RTOL <= v < 1):
            raise InputError("--rtols", v, f"must be relative tolerances in {MIN_RTOL:g}..1")
    return [{"h": h} for h in steps] if steps else [{"rtol": r, "atol": r * 1e-3} for r in values]


def run(args: argparse.Namespace) -> int:
    from cvtfem.errors import InputError
    from cvtfem.integrate import study
    from cvtfem.integrate.methods import METHODS
    from cvtfem.post import integrators as plots

    if args.study == "accuracy-cost":
        return accuracy_cost.run(args)
    methods = [parse_method(m) for m in getattr(args, "methods", "").split(",") if m.strip()]
    _check_args(args, methods)
    problem = _problem(args.problem, args) if args.study in ("order", "work") else None
    hs = _hs(args.hs) if args.study == "order" else None
    settings = _settings(args, problem.t_span) if args.study == "work" else None
    if args.study == "stability":
        for _, method, _ in methods:   # scipy's solvers take real states only: no complex test equation
            if method not in METHODS:
                raise InputError("--methods", method, f"must be native methods {sorted(METHODS)}")
        out = plots.plot_stability(methods, _out(args.png), extent=args.extent, log=args.log, n=args.n)
        print(f"wrote {out}")
    elif args.study == "order":
        curves, rows = [], []
        for label, method, opts in methods:
            if method not in METHODS:
                raise InputError("--methods", method, f"must be native methods {sorted(METHODS)}")
            nominal = METHODS[method](problem_system(problem), None, **opts).order
            errs = study.local_errors(problem, method, hs, **opts)
            curves.append((label, hs, errs, nominal))
            p = study.effective_order(hs, errs)
            rows += [{"label": label, "h": h, "error": e, "p_eff": q}
                     for h, e, q in zip(hs, errs, [math.nan, *p])]
            print(f"{label:28s} nominal {nominal}  p~ = " + " ".join(f"{q:5.2f}" for q in p))
        plots.plot_effective_order(curves, _out(args.png), f"effective order on {problem.name}")
        plots.write_csv(rows, _out(args.csv))
        print(f"wrote {args.png}, {args.csv}")
    elif args.study == "work":
        runs = [(label, method, {**opts, **s}) for label, method, opts in methods for s in settings]
        rows = study.work_precision(problem, runs, repeats=args.repeats, error=getattr(problem, "error", None))
        _print_rows(rows)
        t0, t1 = problem.t_span
        measure = ("largest relative error of the scene's outputs (ratio, speeds, work) at t_end"
                   if getattr(problem, "error", None) else "max over components of |y - y_ref| / |y_ref| at t_end")
        note = (f"error: {measure}; simulated span {t0:g} ... {t1:g} s; labels: each run's rtol "
                f"(atol = 1e-3 rtol) or fixed step h; wall time: median of {args.repeats}")
        plots.plot_work_precision(rows, _out(args.png), f"work-precision on {problem.name}", note)
        plots.write_csv(rows, _out(args.csv))
        print(f"wrote {args.png}, {args.csv}")
    elif args.study == "heat":
        names = [m.strip() for m in args.methods.split(",") if m.strip()] or None
        try:
            rows = study.heat_benchmark(N=args.N, target=args.target, repeats=args.repeats, methods=names)
        except KeyError as err:   # a name the benchmark's plan does not hold
            if names is None or err.args[0] not in names:
                raise
            raise InputError("--methods", err.args[0], "must be methods of the heat benchmark (rk4, dopri45, dumka3, "
                             "rock2, rock4, rkc, trapezoidal, Radau, BDF)") from None
        print(f"heat equation N={args.N}, t=0.1, target relative error {args.target:g}; "
              f"median of {args.repeats} runs on {platform.machine()} {platform.processor() or ''} "
              f"Python {platform.python_version()}")
        _print_rows(rows)
        plots.write_csv(rows, _out(args.csv))
        print(f"wrote {args.csv}")
    return 0


def _out(path: str) -> str:
    """An output file's path, its folder created (once the study has its results)."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    return path


def problem_system(problem):
    """The :class:`OdeSystem` of a problem (to instantiate a stepper for its nominal order)."""
    from cvtfem.integrate.system import as_system

    kw = problem.solve_kwargs()
    return as_system(kw.pop("fun"), kw.pop("y0"), n2=kw.pop("n2"), jac=kw.get("jac"),
                     jac_sparsity=kw.get("jac_sparsity"))


def _print_rows(rows) -> None:
    print(f"{'method':28s} {'setting':22s} {'rel.error':>10s} {'RHS calls':>10s} {'time, s':>9s}  status")
    for r in rows:
        setting = ", ".join(f"{k}={r[k]:.3g}" for k in ("h", "rtol") if k in r)
        status = r.get("status")
        met = "" if r.get("met") is None else ("  meets target" if r["met"] else "  MISSES target")
        print(f"{r['label']:28s} {setting:22s} {r['error']:10.2e} {r['nfev']:10d} {r['time']:9.4f}  "
              f"{status}{met}")
