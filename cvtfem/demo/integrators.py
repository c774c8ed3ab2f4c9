"""Demo part (issue 4): stability regions, effective orders, bouncing ball, a heat benchmark."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def run(outdir: Path) -> list[str]:
    """Compute representative integrator studies in well under 20 s; one line per file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cvtfem.integrate import solve
    from cvtfem.integrate.study import effective_order, heat_benchmark, local_errors
    from cvtfem.post.integrators import plot_effective_order, plot_stability
    from cvtfem.problems import bouncing_ball, limit_cycle

    outdir = Path(outdir)
    lines = []
    methods = [("rk4", "rk4", {}), ("dopri78", "dopri78", {}), ("GBS2s", "gbs-smooth", {"stages": 2}),
               ("SW24-0.5", "sw24", {"d": 0.5}), ("W1-0.5-X4", "w1-extrapolation", {"d": 0.5, "stages": 4}),
               ("RKC s=5", "rkc", {"stages": 5}), ("DUMKA3 P0", "dumka3", {"polynomial": 0})]
    f = plot_stability(methods, outdir / "integrators_stability.png", extent=6.0, n=161)
    lines.append(f"{f.name}: stability regions |R(z)| <= 1 of seven methods, linear plane (brute force)")
    f = plot_stability(methods, outdir / "integrators_stability_log.png", log=True, n=161)
    lines.append(f"{f.name}: the same on the source's signed-log plane (x* = 1e-3)")

    problem = limit_cycle()
    hs = np.geomspace(0.4, 0.025, 5)
    curves, orders = [], {}
    for label, method, opts, p in [("rk4", "rk4", {}, 4), ("dopri45", "dopri45", {}, 5),
                                   ("dopri56", "dopri56", {}, 6), ("GBS3", "gbs", {"stages": 3}, 6),
                                   ("trapezoid", "trapezoidal", {}, 2), ("SW24", "sw24", {}, 2),
                                   ("DUMKA3 P6", "dumka3", {"polynomial": 6}, 3)]:
        errs = local_errors(problem, method, hs, **opts)
        curves.append((label, hs, errs, p))
        orders[label] = {"nominal": p, "measured": float(effective_order(hs, errs)[-1])}
    f = plot_effective_order(curves, outdir / "integrators_order.png", "effective order (local error), limit cycle")
    lines.append(f"{f.name}: local error e(h) and effective order p~(h) of seven methods")

    ball = bouncing_ball(x0=1.0, v0=0.5, e=0.8, t_end=3.5)
    res = solve(**ball.solve_kwargs(), method="dopri45", rtol=1e-8, t_eval=np.linspace(0, 3.5, 701))
    impacts = ball.info["impacts"](len(res.t_events[0]))
    fig, ax = plt.subplots(figsize=(8, 3))
    ax.plot(res.t, res.y[0], lw=1, label="height x(t), DOPRI45 + dense output")
    ax.plot(res.t_events[0], 0 * res.t_events[0], "rv", label="located impacts")
    ax.set_xlabel("t, s")
    ax.set_ylabel("x, m")
    ax.set_title(f"bouncing ball: max |t_event - closed form| = "
                 f"{np.max(np.abs(res.t_events[0] - impacts)):.1e} s", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(outdir / "integrators_bouncing_ball.png", dpi=110)
    plt.close(fig)
    lines.append("integrators_bouncing_ball.png: bouncing ball with events, impact times vs closed form")

    rows = heat_benchmark(N=200, repeats=1, methods=["rk4", "rkc", "dumka3", "trapezoidal", "BDF"])
    summary = {"effective_orders": orders, "heat_N200_target_1e-4": [
        {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in r.items()}
        for r in rows]}
    (outdir / "integrators_summary.json").write_text(json.dumps(summary, indent=1, default=str))
    lines.append("integrators_summary.json: measured orders; heat equation N=200 RHS calls and time "
                 "(RK4, RKC, DUMKA3, sparse trapezoid, scipy BDF)")
    return lines
