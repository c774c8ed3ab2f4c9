"""Which modes limit an explicit step on variant (e) once all friction is implicit (docs/accuracy-cost.md, session 16).

The frictionless Jacobian ``J_E`` (the halves' ``f_0 = 0``, the pin-sheave ``f0 = 0``: the Jacobian of
``rhs_explicit_all``, the explicit part of ``strang-friction``) at a running state (DUMKA3 at 2e-6 s from the study's
cached start to ``T`` s), its largest-magnitude eigenvalues by ARPACK and the state blocks their eigenvectors live in;
then the same with the acceleration rows of more and more coordinate groups removed, as if those groups were
integrated implicitly: the ladder of step limits an explicit part meets (RK4: ``h <= 2.83 /
|lambda|`` on the imaginary axis).  Run from the repository root on a cache of the elastic inclined (e) study:

    .venv/bin/python studies/accuracy-cost/a5_explicit_ladder.py SCENE.toml CACHE_DIR [T]
"""
from __future__ import annotations

import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.analysis import accuracy_cost as ac
from cvtfem.blas import single_thread_blas
from cvtfem.integrate import solve
from cvtfem.scene.loader import load_scene

sys.path.insert(0, "studies/accuracy-cost")
from a5_all_friction_radius import frictionless  # noqa: E402  (the split's f_E: all friction off)

#: Coordinate groups taken out of the explicit part one after another (suffixes of the chain's state blocks).
LADDER = (("pin-half bending u_2, u_3", ("u_perp2", "u_perp3")), ("pin-half axial stretch w_1", ("u_par1",)),
          ("pin-half axial position w_0", ("u_par0",)), ("pin-half tilt u_1", ("u_perp1",)),
          ("pin-half position u_0 (links, contacts)", ("u_perp0",)), ("plate packs", ("chain.pack",)),
          ("shafts and sheaves", ("structure",)))


def top(J, k: int = 6):
    """The ``k`` largest-magnitude eigenvalues (1/s) and eigenvectors, sorted by magnitude."""
    lam, vec = spla.eigs(J.tocsc(), k=k, which="LM", tol=1e-8, maxiter=20000)
    order = np.argsort(-np.abs(lam))
    return lam[order], vec[:, order]


def owners(vec, names, n2: int, count: int = 3) -> str:
    """The state blocks holding most of an eigenvector's position part, with their shares."""
    w = np.abs(vec[:n2]) ** 2
    share: dict[str, float] = {}
    for name, part in zip(names, w / w.sum()):
        share[name] = share.get(name, 0.0) + part
    best = sorted(share.items(), key=lambda kv: -kv[1])[:count]
    return ", ".join(f"{name} {part:.2f}" for name, part in best)


def main(scene_path: str, cache_dir: str, T: float = 2e-4) -> None:
    problem, _ = ac.cvt_problem(load_scene(scene_path), T, cache=ac.StudyCache.existing(cache_dir))
    loop, n2 = problem.loop, problem.loop.n2
    x = solve(**problem.solve_kwargs(), method="dumka3", h=2e-6, adaptive=False, t_eval=[T]).y[:, -1]
    free = frictionless(loop)
    fE = free.rhs(T, x)
    print(f"state at {T:g} s (DUMKA3 2e-6 s); frictionless rhs = rhs_explicit_all to "
          f"{np.abs(fE - loop.rhs_explicit_all(T, x)).max() / np.abs(fE).max():.1e} (relative)", flush=True)
    names = np.concatenate([[b.name] * b.size for b in loop.layout.blocks])[:n2]
    J = sp.coo_matrix(free.jac(T, x))
    removed = np.zeros(0, int)
    for label, suffixes in (("nothing", ()),) + LADDER:
        removed = np.r_[removed, np.flatnonzero([nm.endswith(suffixes) for nm in names])] if suffixes else removed
        keep = ~np.isin(J.row, n2 + removed)
        lam, vec = top(sp.csr_matrix((J.data[keep], (J.row[keep], J.col[keep])), shape=J.shape))
        r = np.abs(lam).max()
        print(f"implicit also {label:40s} radius {r:9.3e}  leading {lam[0].real:.3g}{lam[0].imag:+.3g}j  "
              f"RK4 h <= {2.83 / r:.2e} s  [{owners(vec[:, 0], names, n2)}]", flush=True)


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        raise SystemExit(__doc__)
    with single_thread_blas():
        main(sys.argv[1], sys.argv[2], *(float(a) for a in sys.argv[3:]))
