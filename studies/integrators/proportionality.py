"""Tolerance proportionality (issue 19): achieved error / rtol of every adaptive method over rtol 1e-3 ... 1e-8.

Part 1, every native adaptive method on the limit cycle (closed form, t = 2, atol = rtol; error = max absolute
error at t = 2). Part 2, the stiff methods on HIRES (published reference, atol 1e-3 rtol), Van der Pol
eps = 1e-6 (t = 2, atol = rtol) and Robertson to 1e5 (atol 1e-8 rtol), against scipy Radau at rtol 1e-12
(error = max relative component error at the end). Runs longer than ``--budget`` seconds stop that method's row
(printed as ``>``). The tested bound is ``error < 10 rtol`` (``tests/integrate/test_proportionality.py``).

Run: ``.venv/bin/python studies/integrators/proportionality.py [--budget 20]``
"""
from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from cvtfem.analysis.timing import machine
from cvtfem.integrate import solve
from cvtfem.integrate.methods import METHODS
from cvtfem.integrate.system import as_system
from cvtfem.problems import hires, limit_cycle, robertson, van_der_pol_stiff

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
STIFF = ("radau5", "rodas4", "rodas5p", "w1-extrapolation", "sw24", "trapezoidal", "implicit-euler", "rock4", "rkc")


def adaptive() -> list[str]:
    """Registered native methods with an error estimate (theta: its default is the trapezoidal rule)."""
    return [m for m, cls in METHODS.items()
            if m != "theta" and cls(as_system(lambda t, y: -y, np.ones(2))).error_order is not None]


def row(problem, method, atol_factor, relative, budget):
    """``error / rtol`` per rtol (None once a run took longer than ``budget`` s)."""
    out, ref = [], problem.y_ref
    for rtol in RTOLS:
        t0 = time.perf_counter()
        res = solve(**problem.solve_kwargs(), method=method, rtol=rtol, atol=atol_factor * rtol)
        wall = time.perf_counter() - t0
        if not res.success:
            out.append(np.inf)
        else:
            d = np.abs(res.y[:, -1] - ref)
            out.append(float(np.max(d / np.abs(ref) if relative else d)) / rtol)
        if wall > budget:
            break
    return out + [None] * (len(RTOLS) - len(out))


def show(name, method, ratios) -> None:
    cells = [(">" if q is None else f"{q:.3g}").rjust(9) for q in ratios]
    print(f"{name:12s} {method:20s} " + " ".join(cells), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=float, default=20.0, help="seconds per run before a row stops")
    args = ap.parse_args()
    print(f"error / rtol; {machine()}")
    print(f"{'problem':12s} {'method':20s} " + " ".join(f"{r:.0e}".rjust(9) for r in RTOLS))
    lc = limit_cycle(0.3, 2.0)
    lc = dataclasses.replace(lc, y_ref=lc.exact(2.0))
    for m in adaptive():
        show("limit_cycle", m, row(lc, m, 1.0, False, args.budget))

    def with_ref(p, atol):
        return dataclasses.replace(p, y_ref=solve(**p.solve_kwargs(), method="Radau", rtol=1e-12, atol=atol).y[:, -1])

    stiff = {"hires": (hires(), 1e-3), "vdp": (with_ref(van_der_pol_stiff(1e-6), 1e-12), 1.0),
             "robertson": (with_ref(robertson(1e5), 1e-20), 1e-8)}
    for name, (p, atol_factor) in stiff.items():   # HIRES: its published y_ref
        for m in STIFF:
            show(name, m, row(p, m, atol_factor, True, args.budget))
    print(f"end: {machine()}")


if __name__ == "__main__":
    main()
