"""Modal against direct FRFs on the presets (docs/response.md table).

    .venv/bin/python studies/response/modal_accuracy.py

Driving-point receptance (x force, x and y response) at a sheave/disk at 400 rad/s; error
``|H_modal - H_direct| / |H_direct|`` (2-norm over both outputs), max over 600 lines up to 0.9 x the highest
retained mode, for the complex-mode basis with and without the static correction, the sweep basis (right and left
modes at 0, 300 and 600 rad/s, + static correction) and the basis at rest.
Friswell 5.9.1 gets Rayleigh damping C = 2 M + 2e-5 K (the preset is undamped).
"""
import numpy as np

from cvtfem.machines.rotor import build_model
from cvtfem.modal.forced import ModalBasis, displacement, frf_direct
from cvtfem.scene.loader import load_scene


def main() -> None:
    print("| model | modes | highest retained (Hz) | complex + static | complex | sweep + static | at rest + static |")
    print("|---|---|---|---|---|---|---|")
    for name, node in (("friswell_5_9_1", 2), ("cvt_sheave_shaft", 4)):
        m = build_model(load_scene(name))
        C = m.C + 2.0 * m.M + 2e-5 * m.K if name.startswith("fris") else m.C
        f = np.zeros(m.n_dof)
        f[6 * node] = 1.0
        out = displacement([6 * node, 6 * node + 1], m.n_dof)
        for n_modes in (4, 6, 8, 12, 16):
            bases = [ModalBasis(m.M, m.K, C, m.G, f, n_modes, residual=r, modes=b, basis_speeds=(0.0, 300.0, 600.0))
                     for r, b in ((True, "complex"), (False, "complex"), (True, "sweep"), (True, "rest"))]
            wmax = bases[0].wmax(400.0)
            w = np.linspace(1.0, 0.9 * wmax, 600)
            Hd = frf_direct(m.M, m.K, C, m.G, f, out, w, 400.0)
            errs = [np.max(np.linalg.norm(b.frf(out, w, 400.0) - Hd, axis=(1, 2)) / np.linalg.norm(Hd, axis=(1, 2)))
                    for b in bases]
            print(f"| {name} | {n_modes} | {wmax / 2 / np.pi:.0f} | " + " | ".join(f"{e:.1e}" for e in errs) + " |")


if __name__ == "__main__":
    main()
