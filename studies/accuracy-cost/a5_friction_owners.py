"""Which friction owns which eigenvalue of variant (e) at a running state (docs/accuracy-cost.md, session 11, step 1).

From the study's start state (the w-short cache, quasi-static at ratio 0.45), DUMKA3 at 2e-6 s runs to ``T`` (s).  At
that state: the largest-magnitude eigenvalues (ARPACK) of the model Jacobian ``J``; of ``J`` with the velocity
Jacobian of one group of the halves' internal friction removed (``-M^-1 B_g^T diag(c f') B_g``: axial half-half,
axial half-pack, rolling contact, the two plate-hole contacts) and with that group's slopes divided by 10 (its
friction speed times 10 where the law is linear in the slip); with both axial groups removed; with all removed (the
explicit part ``f_E`` of ``strang-friction``).  The pin-sheave friction's share: ``J`` and ``f_E`` with the scene's
``cvt.friction.v0`` times 10.
    .venv/bin/python studies/accuracy-cost/a5_friction_owners.py out/studies/w-short-cache 2e-4
"""
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.analysis.accuracy_cost import StudyCache
from cvtfem.elements.contact.friction import friction_slope
from cvtfem.integrate import solve
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene

SCENE = "studies/accuracy-cost/scenes/variant-e-rigid-chapter2-linear-saturated.toml"
GROUPS = ("axial half-half", "axial half-pack", "rolling", "hole next", "hole prev")


def top(J, k):
    """The ``k`` largest-magnitude eigenvalues (1/s), sorted by magnitude."""
    lam = spla.eigs(J.tocsc(), k=k, which="LM", tol=1e-8, return_eigenvectors=False, maxiter=20000)
    return lam[np.argsort(-np.abs(lam))]


def show(tag, lam):
    print(f"{tag:38s} |lambda|max {np.abs(lam).max():9.3e}  " +
          " ".join(f"{z.real:.3g}{z.imag:+.2g}j" if abs(z.imag) > 1 else f"{z.real:.4g}" for z in lam[:10]), flush=True)


def friction_jacobians(loop, x):
    """Per group the velocity Jacobian of ``f_I`` in the model's state (sparse, rows and columns of the chain's
    velocities)."""
    ch, nc, n2, N = loop.family.chain, loop.family.size, loop.n2, loop.size
    q, v = x[:nc], x[n2:n2 + nc]
    B, c, g = ch.friction_slips(q, groups=True)
    s = B @ v
    D = c * friction_slope(np.abs(s), ch.f0, ch.v0, ch.law)
    out = {}
    for k, name in enumerate(GROUPS):
        sel = g == k
        Jg = -(ch.inverse_mass @ (B[sel].T @ sp.diags(D[sel]) @ B[sel]))
        P = sp.csr_matrix((np.ones(nc), (n2 + np.arange(nc), np.arange(nc))), shape=(N, nc))
        out[name] = P @ Jg @ P.T
        print(f"  {name}: {sel.sum()} slips, {np.sum(np.abs(s[sel]) < ch.v0)} within v0, "
              f"max c {c[sel].max() if sel.any() else 0:.3g} N", flush=True)
    return out


def main(cache_dir, T, k=12):
    scene = load_scene(SCENE)
    loop = closed_loop(scene)
    x0 = StudyCache.existing(cache_dir).start()[0]
    t0 = time.process_time()
    res = solve(loop, (0.0, T), x0, method="dumka3", h=2e-6, adaptive=False, t_eval=[T])
    x = res.y[:, -1]
    print(f"state at {T:g} s by dumka3 2e-6: {res.message} ({time.process_time() - t0:.1f} s CPU)", flush=True)
    J = loop.jac(T, x)
    JI = friction_jacobians(loop, x)
    show("J (all)", top(J, k))
    for name, Jg in JI.items():
        show(f"J less {name}", top(J - Jg, 6))
        show(f"J, {name} slopes / 10", top(J - 0.9 * Jg, 6))
    show("J less both axial frictions", top(J - JI["axial half-half"] - JI["axial half-pack"], k))
    JE = J - sum(JI.values())
    show("f_E: J less all halves' friction", top(JE, k))
    v0 = scene.cvt.friction.v0
    loop10 = closed_loop(scene.replace({"cvt": {"friction": {"v0": 10 * v0}}}))
    J10 = loop10.jac(T, x)
    show("J, pin-sheave v0 x 10", top(J10, k))
    show("f_E, pin-sheave v0 x 10", top(J10 - sum(JI.values()), k))


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]))
