"""Work-precision diagram on HIRES (t = 321.8122, published reference): native stiff methods
against scipy's Radau and BDF. Error vs median wall time and vs RHS calls; PNG + CSV into
``out/studies/integrators/``.

Run: ``.venv/bin/python studies/integrators/work_precision_hires.py [--repeats 3]``
"""
from __future__ import annotations

import argparse
import platform
from pathlib import Path

from cvtfem.integrate.study import work_precision
from cvtfem.post.integrators import plot_work_precision, write_csv
from cvtfem.problems import hires

OUT = Path("out/studies/integrators")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    wide = tuple(10.0 ** -k for k in range(2, 11))   # errors from ~1e-1 to ~1e-10
    plan = {"trapezoidal": wide[:5], "sw24": wide[:5],   # order 2, proportional: rtol 1e-6 is ~1e4 steps
            "rock4": wide[1:7], "rodas4": wide, "rodas5p": wide, "Radau": wide, "BDF": wide}
    runs = [(m, m, {"rtol": r, "atol": r * 1e-3, "t_eval": [321.8122]}) for m, rs in plan.items() for r in rs]
    rows = work_precision(hires(), runs, repeats=args.repeats)
    print(f"HIRES work-precision, median of {args.repeats} runs, {platform.machine()} Python {platform.python_version()}")
    for r in rows:
        print(f"{r['label']:12s} rtol={r['rtol']:.0e}  rel.err={r['error']:.2e}  RHS={r['nfev']:7d}  "
              f"LU={r['nlu']:6d}  time={r['time']:.3f} s")
    plot_work_precision(rows, OUT / "work_precision_hires.png", "HIRES, relative error at t = 321.8122",
                        "error: max over the 8 components of |y - y_ref| / |y_ref| at t = 321.8122 (published "
                        f"reference); simulated span 0 ... 321.8122; labels: rtol (atol = 1e-3 rtol); median of "
                        f"{args.repeats} runs")
    write_csv(rows, OUT / "work_precision_hires.csv")
    print(f"wrote {OUT / 'work_precision_hires.png'}, {OUT / 'work_precision_hires.csv'}")


if __name__ == "__main__":
    main()
