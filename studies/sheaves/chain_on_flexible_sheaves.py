"""The chain-S2 transmission's quasi-static start on rigid and on flexible sheave faces (issue 20, deliverable 4).

Reference chain at ratio 2.4, 3500 rpm, driven clamping force F2 = 35.546 kN (the band study's), sheaves of the
``band-6+2n-flexible`` preset (24 harmonics, 24 x 2 cells, fitted over r_min - 3 mm .. r_max + 3 mm: the driven arc
runs at 88.1-88.5 mm, beyond r_max).  ``static_state`` holds the driving sheave where the wedge estimate puts it,
so on flexible faces the chain finds other radii; the study also moves the driving sheave (secant) until the ratio
of the contact-force-weighted mean radii ``r2 / r1`` equals the rigid start's, which is the comparison with the
band models' "F1 holding the span angle" (torque-free here: the chain's start loads no friction).  Prints F1, F2,
F1/F2, the faces' opening per arc, the mean contact radii; ``--bench`` times the right-hand side (7 interleaved
rounds, each the median of 200 calls) and a 50 us Radau run; ``--ratios`` repeats the comparison at ratios 0.5, 1.0
and 1.6 (F2 of the band study's table at each).

    .venv/bin/python studies/sheaves/chain_on_flexible_sheaves.py [--bench] [--ratios]
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, fields

import numpy as np
from scipy.optimize import newton

from cvtfem.analysis.timing import machine, median_us
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.elements.sheave_face import face_compliance
from cvtfem.integrate import solve
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines.chain_cvt_flexible import FlexibleChainCVT
from cvtfem.machines.sheave import cvt_sheave_section
from cvtfem.scene.loader import load_scene

RATIO, F2 = 2.4, 35546.0


@dataclass(frozen=True, eq=False)
class ShiftedDriving(FlexibleChainCVT):
    """The flexible chain whose quasi-static start holds the driving sheave ``shift`` (m) further in."""

    shift: float = 0.0

    def wedge_guess(self, ratio, F2):  # noqa: ANN001, ANN201
        pl, u3, z = super().wedge_guess(ratio, F2)
        return pl, u3, z - np.array([self.shift, 0.0])


def summary(model, x):  # noqa: ANN001, ANN201
    """Contact-force-weighted mean radius per arc (m), the faces' opening range per arc (m, in contact)."""
    q, v, _, _ = model.split(x)
    ends, shafts = model._candidates(q)
    cols, coef = model._contact_map(ends, shafts)
    X = (coef * np.concatenate([q, v, model._constants])[cols]).sum(axis=2)
    r = np.hypot(*(X[:, :2] - model.contact.centres[shafts]).T)
    if isinstance(model, FlexibleChainCVT):
        sol = model.face_solution(X, shafts)
        N, opening = sol["N"], sol["opening"]
    else:
        N, opening = model.contact.local(X, shafts, details=True)[1]["N"], np.zeros(len(X))
    mean_r = np.array([np.sum((N * r)[shafts == k]) / np.sum(N[shafts == k]) for k in (0, 1)])
    span = [(opening[(shafts == k) & (N > 0)].min(), opening[(shafts == k) & (N > 0)].max()) for k in (0, 1)]
    return mean_r, span


def compare(faces, ratio: float, F2: float, w1: float):  # noqa: ANN001, ANN201
    """Rigid and flexible starts at ``ratio`` and driven clamping force ``F2`` (N): the rows of the table
    ``(name, model, x, report)`` and the driving sheave's shift (m) that restores the rigid start's ``r2 / r1``."""
    rigid = from_scene(load_scene("band-6+2n"), reference_geometry(), np.array([30000.0, F2]))
    flex = FlexibleChainCVT.on_faces(rigid, (faces, faces))
    xr, rr = rigid.static_state(ratio, w1)
    xf, rf = flex.static_state(ratio, w1)
    r_rigid, _ = summary(rigid, xr)
    target = r_rigid[1] / r_rigid[0]

    def ratio_gap(shift):  # noqa: ANN001, ANN202
        m = ShiftedDriving(**{f.name: getattr(flex, f.name) for f in fields(flex) if f.init}, shift=shift)
        x, rep = m.static_state(ratio, w1)
        r, _ = summary(m, x)
        ratio_gap.last = (m, x, rep)
        return r[1] / r[0] - target
    shift = newton(ratio_gap, 0.0, x1=2e-6, tol=1e-10)           # secant from the rigid position
    ratio_gap(shift)
    return [("rigid", rigid, xr, rr), ("flexible, driving sheave as rigid", flex, xf, rf),
            (f"flexible, same r2/r1 (shift {1e6 * shift:+.1f} um)", *ratio_gap.last)], shift


def main() -> None:
    scene = load_scene("band-6+2n-flexible")
    g, w1 = scene.cvt.geometry, scene.cvt.regime.input_speed
    t0 = time.perf_counter()
    faces = face_compliance(cvt_sheave_section(scene), g.r_min - 0.003, g.r_max + 0.003, 24, (24, 2))
    print(f"face compliance: {time.perf_counter() - t0:.1f} s")
    cases = ((0.5, 12900.0), (1.0, 16700.0), (1.6, 24400.0), (RATIO, F2)) if "--ratios" in sys.argv[1:] \
        else ((RATIO, F2),)
    for ratio, force in cases:
        rows, _ = compare(faces, ratio, force, w1)
        print(f"ratio {ratio}, F2 {force / 1e3:.3f} kN")
        print(f"{'start':38s} {'F1 kN':>8s} {'F2 kN':>8s} {'F1/F2':>8s} {'r1 mm':>8s} {'r2 mm':>8s} "
              f"{'opening arc 1 um':>17s} {'arc 2 um':>12s}")
        for name, m, x, rep in rows:
            r, span = summary(m, x)
            print(f"{name:38s} {rep['F1'] / 1e3:8.3f} {rep['F2'] / 1e3:8.3f} {rep['F1'] / rep['F2']:8.4f} "
                  f"{1e3 * r[0]:8.3f} {1e3 * r[1]:8.3f} {1e6 * span[0][0]:7.1f}..{1e6 * span[0][1]:<7.1f} "
                  f"{1e6 * span[1][0]:5.1f}..{1e6 * span[1][1]:<5.1f}  residual {rep['residual']:.1e}")
        base = rows[0][3]["F1"] / rows[0][3]["F2"]
        for name, _, _, rep in rows[1:]:
            print(f"F1/F2 change, {name}: {100 * (rep['F1'] / rep['F2'] / base - 1):+.2f} %")
    if "--bench" in sys.argv[1:]:
        (_, rigid, _, rr), (_, flex, xf, rf) = rows[:2]
        bench(rigid, flex.with_clamping([rf["F1"], F2]), xf, rr, rf)


def bench(rigid, flex, x, rr, rf) -> None:  # noqa: ANN001
    """Right-hand side (interleaved rounds) and a 50 us Radau run from each model's start, rigid and flexible."""
    print(machine())
    times = {"rigid": [], "flexible": []}
    for _ in range(7):
        for name, m in (("rigid", rigid), ("flexible", flex)):
            times[name].append(median_us(lambda m=m: m.rhs(0.0, x), 200, warm_up=True))
    med = {k: float(np.median(v)) for k, v in times.items()}
    print(f"rhs: rigid {med['rigid']:.0f} us ({min(times['rigid']):.0f}-{max(times['rigid']):.0f}), flexible "
          f"{med['flexible']:.0f} us ({min(times['flexible']):.0f}-{max(times['flexible']):.0f}): "
          f"+{100 * (med['flexible'] / med['rigid'] - 1):.0f} %")
    for name, m, rep in (("rigid", rigid, rr), ("flexible", flex, rf)):
        x0 = m.static_state(RATIO, m.regime.targets(0.0)[0])[0]
        m = m.with_clamping([rep["F1"], F2])
        t0 = time.perf_counter()
        res = solve(m, (0.0, 5e-5), x0, method="Radau", rtol=1e-6, atol=1e-9, n2=m.n2, jac=m.jac,
                    jac_sparsity=m.jac_sparsity)
        st = res.stats
        print(f"50 us Radau run, {name}: {time.perf_counter() - t0:.2f} s, {st['nsteps']} steps, {st['nfev']} rhs, "
              f"{st['njev']} Jacobians, {st['nlu']} LU")


if __name__ == "__main__":
    main()
