"""The spectral radius of ``f_E`` with all friction of variant (e) removed (docs/accuracy-cost.md, session 12).

The state of a5_friction_owners.py (DUMKA3 at 2e-6 s from the w-short cache's start to ``T``, s).  ``J`` is the model
Jacobian, ``J_E`` the Jacobian of the same model without any friction (the halves' ``f_0 = 0`` and the pin-sheave
``f0 = 0``): exactly the Jacobian of ``rhs_explicit_all``, the explicit part of the split variant ``"all"``.  The
largest-magnitude eigenvalues by ARPACK; the RK4 step limits from them (imaginary-axis limit 2.83, real 2.79).
    .venv/bin/python studies/accuracy-cost/a5_all_friction_radius.py out/studies/w-short-cache 2e-4
"""
import sys
import time
from dataclasses import replace

import numpy as np

from cvtfem.analysis.accuracy_cost import StudyCache
from cvtfem.elements.chain.end_contact import EndContact
from cvtfem.elements.chain.half_end_contact import HalfEndContact
from cvtfem.integrate import solve
from cvtfem.machines.chain_halves_cvt import HalvesFamily
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

sys.path.insert(0, "studies/accuracy-cost")
from a5_friction_owners import SCENE, show, top  # noqa: E402


def frictionless(loop):
    """``loop`` with the halves' and the pin-sheave friction off (``f_E`` of the split variant "all")."""
    fam, h2 = loop.family, loop.contact.pair.pair
    return replace(loop, family=HalvesFamily(fam.chain.without_friction(), fam.geom),
                   contact=EndContact(HalfEndContact(replace(h2, f0=0.0))))


def main(cache_dir, T, k=12):
    loop = closed_loop(load_scene(SCENE))
    x0 = StudyCache.existing(cache_dir).start()[0]
    t0 = time.process_time()
    x = solve(loop, (0.0, T), x0, method="dumka3", h=2e-6, adaptive=False, t_eval=[T]).y[:, -1]
    print(f"state at {T:g} s by dumka3 2e-6 ({time.process_time() - t0:.1f} s CPU)", flush=True)
    free = frictionless(loop)
    fE, fE2 = free.rhs(T, x), loop.rhs_explicit_all(T, x)
    print(f"frictionless model's rhs = rhs_explicit_all to {np.abs(fE - fE2).max() / np.abs(fE).max():.1e} (relative)")
    show("J (all)", top(loop.jac(T, x), k))
    lam = top(free.jac(T, x), k)
    show("J_E: no friction at all", lam)
    r = np.abs(lam).max()
    print(f"RK4 limit on J_E: h <= 2.83 / {r:.3g} = {2.83 / r:.3g} s (imaginary axis); the leading pair's real part "
          f"{lam[0].real:.3g} 1/s")


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]))
