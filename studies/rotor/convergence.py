"""Convergence of the shaft element on a simply supported uniform shaft (figure + table).

Euler-Bernoulli (shear and rotary inertia off) against (n pi/L)^2 sqrt(EI/rho A), and the Timoshenko
element (spinning, 3000 rad/s) against the analytic Timoshenko roots, slender (L/D = 40) and short (L/D = 5).

    .venv/bin/python studies/rotor/convergence.py   # -> out/studies/rotor/convergence.png
"""
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly import assemble
from cvtfem.elements.beam import BeamFamily, BeamOptions, cowper_kappa
from cvtfem.modal import ModalProblem

E, G, RHO = 2.11e11, 8.12e10, 7810.0
OUT = Path("out/studies/rotor")


def ss_modes(n, L, D, speed, **opts):
    b = BeamFamily(nodes=np.stack([np.arange(n), np.arange(1, n + 1)], 1), L=np.full(n, L / n), Do=np.full(n, D),
                   Di=np.zeros(n), E=np.full(n, E), G=np.full(n, G), rho=np.full(n, RHO),
                   options=BeamOptions(**opts))
    N = 6 * (n + 1)
    M, K, Gm = (assemble(N, [(f(), b.dofs)]) for f in (b.mass, b.stiffness, b.gyroscopic))
    kind, node = np.tile(np.arange(6), n + 1), np.repeat(np.arange(n + 1), 6)
    keep = np.flatnonzero(np.isin(kind, [0, 1, 3, 4]) & ~(np.isin(kind, [0, 1]) & ((node == 0) | (node == n))))
    sub = [sp.csr_matrix(X)[keep][:, keep] for X in (M, K, Gm)]
    return ModalProblem(sub[0], sub[1], 0 * sub[1], sub[2], kind[keep], method="dense").solve(speed, 6).wd


def timoshenko_exact(L, D, speed):
    A, I = np.pi * D**2 / 4, np.pi * D**4 / 64
    kGA = float(cowper_kappa(E / (2 * G) - 1, 0.0)) * G * A
    out = []
    for k in np.arange(1, 4) * np.pi / L:
        for s in (-1.0, 1.0):
            poly = np.polysub(np.polymul([-RHO * A, 0, kGA * k**2], [-RHO * I, s * 2 * RHO * I * speed,
                                                                    E * I * k**2 + kGA]), [(kGA * k) ** 2])
            r = np.roots(poly)
            out.append(np.min(r[(abs(r.imag) < 1e-6 * abs(r)) & (r.real > 0)].real))
    return np.array(out)


def main():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    OUT.mkdir(parents=True, exist_ok=True)
    ns = np.array([2, 4, 8, 16, 32, 64])
    L, D = 2.0, 0.05
    k = np.arange(1, 4) * np.pi / L
    eb_exact = np.repeat(k**2 * np.sqrt(E * np.pi * D**4 / 64 / (RHO * np.pi * D**2 / 4)), 2)
    curves = {"Euler-Bernoulli, L/D = 40": [np.max(abs(ss_modes(n, L, D, 0.0, shear=False, rotary_inertia=False,
                                                                  gyroscopic=False) - eb_exact) / eb_exact)
                                             for n in ns]}
    for label, (Ls, Ds) in {"Timoshenko spinning, L/D = 40": (2.0, 0.05),
                            "Timoshenko spinning, L/D = 5": (0.5, 0.1)}.items():
        ex = timoshenko_exact(Ls, Ds, 3000.0)
        curves[label] = [np.max(abs(ss_modes(n, Ls, Ds, 3000.0) - ex) / ex) for n in ns]
    fig, ax = plt.subplots(figsize=(7, 5))
    print(f"{'elements':>8} " + " ".join(f"{c:>32}" for c in curves))
    for i, n in enumerate(ns):
        print(f"{n:>8} " + " ".join(f"{v[i]:>32.3e}" for v in curves.values()))
    for label, errs in curves.items():
        errs = np.array(errs)
        rate = np.log2(errs[:-1] / errs[1:])
        ax.loglog(ns, errs, "o-", label=f"{label} (rates {', '.join(f'{r:.1f}' for r in rate)})")
    ax.loglog(ns, 0.5 * (ns / ns[0]) ** -4.0 * curves["Euler-Bernoulli, L/D = 40"][0], "k:", label="h^4")
    ax.set_xlabel("elements")
    ax.set_ylabel("max relative error, modes 1-3 (both whirls)")
    ax.set_title("simply supported shaft: FE vs analytic frequencies")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "convergence.png", dpi=120)
    print(f"wrote {OUT / 'convergence.png'}")


if __name__ == "__main__":
    main()
