"""Cost of one RHS and one Jacobian of the chain on two sheaves with H1 and with H2 contact (S2 and S3).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/bench_refined.py [--calls 200] [--jac-calls 10]
    # -> out/studies/chain/bench_refined.txt

The reference chain (84 pins) in its quasi-static running state at ratio 2.4, 3500 rpm (band-6+2n scene
values, 30/35 kN per sheave), slightly perturbed; medians of ``calls`` RHS and ``jac-calls`` Jacobians,
and of the contact pass alone (local forces of all candidate contacts), machine and load named.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.scene.loader import load_scene

OUT = Path("out/studies/chain")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--jac-calls", type=int, default=10)
    a = ap.parse_args()
    scene = load_scene("band-6+2n")
    lines = [f"machine: {machine()}", f"medians of {a.calls} RHS / {a.jac_calls} Jacobians", "",
             f"{'':28s}{'contacts':>9s}{'contact pass us':>17s}{'RHS us':>10s}{'Jacobian ms':>13s}{'Jac / RHS':>11s}"]
    rng = np.random.default_rng(0)
    for model in ("chain-S2", "chain-S3"):
        for contact in ("hertz", "hertz-refined"):
            m = from_scene(scene, reference_geometry(), np.array([30000.0, 35000.0]), model=model, contact=contact)
            x, _ = m.static_state(2.4, scene.cvt.regime.input_speed)
            nc = m.family.size
            x[:nc] += rng.normal(0, 1e-6, nc)
            q, v = x[:m.n2], x[m.n2:2 * m.n2]
            pins, shafts, X, _ = m._contacts(q, v)
            t_pass = median_us(lambda: m.contact.local(X, shafts), a.calls, warm_up=True)
            t_rhs = median_us(lambda: m.rhs(0.0, x), a.calls, warm_up=True)
            t_jac = median_us(lambda: m.jac(0.0, x), a.jac_calls, warm_up=True)
            lines.append(f"{model + ' ' + contact:28s}{len(pins):>9d}{t_pass:>17.0f}{t_rhs:>10.0f}"
                         f"{t_jac / 1e3:>13.1f}{t_jac / t_rhs:>11.0f}")
    lines.append(f"load after: {machine().split('load ')[1].split(',')[0]}")
    text = "\n".join(lines)
    print(text)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "bench_refined.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
