"""Why the quasi-static start of A5 on the sheaves needs the lifted Newton phase: the residual, the static stiffness
and the solver's steps where the damped phase 1 of :func:`~cvtfem.machines.static_balance.lifted_newton` alone (the
session-6 solver) stops.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/chain/a5_start_diagnosis.py
    # -> out/studies/chain/a5_start_diagnosis.txt (about 1-2 min at load 3)

Reference chain (band-6+2n scene values, clamping 30/35 kN), ratio 2.4, 3500 rpm, A4 plates.  At the stall it
prints: the residual's largest entries (pin, coordinate, N) and the link tensions; the eigenvalues of the symmetric
part of the scaled Jacobian ``dQ/dy / F2`` (positive = negative static stiffness, an unstable direction) by kind of
coordinate; whether the Jacobian is the derivative of the residual there (central differences along the
steepest-descent direction of ``|r|^2``); and whether the solver's step ``-(J - mu S)^-1 r`` lowers ``|r|`` for
``mu`` from 1e-6 to 1e8 (it does not: with an indefinite ``J`` the shifted step is no descent direction of
``|r|^2``, while ``-J^T r`` is).
"""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.analysis.timing import machine
from cvtfem.elements.chain.geometry import reference_geometry
from cvtfem.errors import NumericalError
from cvtfem.machines.chain_cvt import from_scene
from cvtfem.machines import static_balance
from cvtfem.machines.chain_halves_cvt import ChainHalvesCVT
from cvtfem.scene.loader import load_scene

F_APPL = np.array([30000.0, 35000.0])
RATIO = 2.4
OUT = Path("out/studies/chain")
#: Coordinate kinds of a pin's 21 (A1 layout per half, then the pack).
KINDS = {"u0 (in-plane position)": [0, 1, 10, 11], "u1 (in-plane tilt)": [2, 3, 12, 13],
         "u2, u3 (bending)": [4, 5, 6, 7, 14, 15, 16, 17], "w0 (axial position)": [8, 18],
         "w1 (half length)": [9, 19], "q_p (plate pack)": [20]}


class _Recorded(ChainHalvesCVT):
    """ChainHalvesCVT that keeps the residual and Jacobian functions and the point where its solve (without the tie
    continuation, phase 1 alone: ``static_balance.NEWTON_ITERATIONS = 0`` in :func:`main`) stopped."""

    ROLL_TIES = ()

    def _solve_balance(self, residual, jacobian, y0, tol):
        sol = static_balance.lifted_newton(residual, jacobian, y0, tol)
        _Recorded.stall = (residual, jacobian, sol)
        return sol


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    static_balance.NEWTON_ITERATIONS = 0
    lines = [machine()]
    say = lines.append
    scene = load_scene("band-6+2n")
    model = from_scene(scene, reference_geometry(), F_APPL, model="chain-A5")
    model = _Recorded(**{f.name: getattr(model, f.name) for f in fields(model) if f.init})
    try:
        model.static_state(RATIO, scene.cvt.regime.input_speed)
        say("the quasi-static solve converged")
    except NumericalError as err:
        say(f"stall: {err}")
    residual, jacobian, sol = _Recorded.stall
    y, r = sol.x, residual(sol.x)
    F2 = F_APPL[1]
    fam = model.family
    where = np.full((y.size, 2), -1)
    for p in range(fam.n):
        where[fam.dof_index[p]] = np.column_stack([np.full(21, p), np.arange(21)])
    say("largest residuals (pin, coordinate 0..20 or z2 = -1, N): " + ", ".join(
        f"({where[i, 0]}, {where[i, 1]}, {F2 * r[i]:.0f})" for i in np.argsort(-np.abs(r))[:10]))
    T = fam.outputs(y[:fam.size], None)["chain.link_tension"]
    say("link tensions every 6th link (N): " + " ".join(f"{t:.0f}" for t in T[::6]))
    J = np.asarray(jacobian(y))
    w, V = np.linalg.eigh(0.5 * (J + J.T))
    big = np.abs(w).max()
    say(f"Jacobian asymmetry {np.abs(J - J.T).max() / np.abs(J).max():.2e} of its largest entry; eigenvalues of its "
        f"symmetric part (N/m over F2): largest magnitude {big:.3g}")
    for label, sel in (("positive (unstable)", w > 1e-6 * big),
                       ("|w| < 1e-9 of the largest (zero)", np.abs(w) < 1e-9 * big)):
        weight = (V[:, sel] ** 2)
        kinds = {k: weight[fam.dof_index[:, cols].ravel()].sum() / max(sel.sum(), 1) for k, cols in KINDS.items()}
        say(f"  {sel.sum()} {label}; weight by kind: "
            + ", ".join(f"{k} {v:.2f}" for k, v in kinds.items() if v > 0.01))
    say("  largest positive: " + " ".join(f"{x * F2:.3g}" for x in w[-4:][::-1]) + " N/m")
    g = J.T @ r
    d = -g / np.linalg.norm(g)
    for h in (1e-9, 1e-8):
        fd = (residual(y + h * d) - residual(y - h * d)) / (2 * h)
        say(f"central difference of r along -J^T r, step {h:g} m: |fd - J d| / |J d| = "
            f"{np.linalg.norm(fd - J @ d) / np.linalg.norm(J @ d):.2e}; d|r|^2/2 = {r @ fd:.4g} (J: {r @ (J @ d):.4g})")
    Js = sp.csc_matrix(J)
    S = sp.diags(np.maximum(np.abs(J.diagonal()), 1e-9 * np.abs(J.diagonal()).max()))
    n0 = np.linalg.norm(r)
    for mu in 10.0 ** np.arange(-6, 9, 2):
        dy = spla.splu(Js - mu * S).solve(-r)
        say(f"shifted Newton step mu = {mu:.0e}: |dy| {np.abs(dy).max():.2e} m, |r(y + dy)| / |r| = "
            f"{np.linalg.norm(residual(y + dy)) / n0:.4f}, r.J dy / |r|^2 = {r @ (J @ dy) / n0 ** 2:+.3f}")
    say(machine())
    text = "\n".join(lines)
    print(text)
    (OUT / "a5_start_diagnosis.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
