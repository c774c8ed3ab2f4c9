"""CPU per operation of strang-friction (frozen-mid, DUMKA3, h = 2e-6 s) over [0, 0.4] ms of variant (e) from the
w-short cache's start: RHS, f_E, slip map, friction solve (docs/accuracy-cost.md, session 11).
    .venv/bin/python studies/accuracy-cost/imex_costs.py
"""
import time, warnings
import numpy as np
warnings.simplefilter("ignore")
from cvtfem.analysis.accuracy_cost import StudyCache
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene
from cvtfem.integrate import solve
scene = load_scene("studies/accuracy-cost/scenes/variant-e-rigid-chapter2-linear-saturated.toml")
loop = closed_loop(scene)
x0 = StudyCache.existing("out/studies/w-short-cache").start()[0]
ch = loop.family.chain
acc = {"slips": [0.0, 0], "step": [0.0, 0], "lus": 0}
fs, fst = ch.friction_slips, ch.friction_step
def slips(q, *a, **k):
    t = time.process_time(); r = fs(q, *a, **k); acc["slips"][0] += time.process_time() - t; acc["slips"][1] += 1; return r
def step(*a, **k):
    t = time.process_time(); r = fst(*a, **k); acc["step"][0] += time.process_time() - t; acc["step"][1] += 1; acc["lus"] += r[2]; return r
ch.friction_slips, ch.friction_step = slips, step
t = time.process_time()
res = solve(loop, (0.0, 4e-4), x0, method="strang-friction", h=2e-6, adaptive=False, scheme="frozen-mid", t_eval=[4e-4])
tot = time.process_time() - t
ts = []
for _ in range(300):
    t = time.process_time(); loop.rhs(0, x0); ts.append(time.process_time() - t)
rhs = np.median(ts)
ts = []
for _ in range(300):
    t = time.process_time(); loop.rhs_explicit(0, x0); ts.append(time.process_time() - t)
print(f"total {tot:.2f} s CPU, nfev {res.stats['nfev']}; rhs {1e3*rhs:.3f} ms, rhs_explicit {1e3*np.median(ts):.3f} ms")
print(f"slips: {acc['slips'][1]} calls, {1e3*acc['slips'][0]/acc['slips'][1]:.2f} ms each = {acc['slips'][0]/acc['slips'][1]/rhs:.1f} RHS-eq")
print(f"friction solves: {acc['step'][1]}, {acc['lus']/acc['step'][1]:.1f} LUs each, {1e3*acc['step'][0]/acc['step'][1]:.2f} ms each = {acc['step'][0]/acc['step'][1]/rhs:.1f} RHS-eq; per LU {1e3*acc['step'][0]/acc['lus']:.2f} ms")
