"""Variant (a) with another crown radius ``R_f`` of the pin end faces in the H2 kernel (session 11, "where the
efficiency goes"): the contact point lies ``|x_*| ~ R_f tan(gamma) / (1 - R_f f'')`` inside the pin-axis end, 3.4 mm
(driving) and 3.8 mm (driven) at the preset's 20 mm, beyond the pin's end face (``width_n`` = 6 mm: +-3 mm about the
axis).  Only the kernel's ``R_f`` changes (the Hertz constant stays the preset's, and the fixed sheaves are placed
again for the new extra approach), so the run isolates the offset.

Run:  .venv/bin/python studies/chain/loss_face_radius.py studies/chain/loss-variant-a.toml --face-radius 0.008
      --until 0.03 --results out/studies/chain/loss_variant_a_rf8.h5
      .venv/bin/python studies/chain/loss_face_radius.py --face-radius 0.008 --decompose out/studies/chain/loss_variant_a_rf8.h5
The second form runs ``loss_decomposition.py`` on that file with the same ``R_f`` (the stored scene does not hold it).
"""
from __future__ import annotations

import argparse
from dataclasses import replace

import cvtfem.machines.cvt as cvt_module
from cvtfem.elements.chain.end_contact import EndContact


def patch_face_radius(face_radius: float) -> None:
    """Make :func:`cvtfem.machines.cvt.chain_loop` build its H2 contact with crown radius ``face_radius`` (m)."""
    original = cvt_module.chain_loop

    def chain_loop(scene, *a, **kw):
        model = original(scene, *a, **kw)
        pair = replace(model.contact.pair, face_radius=face_radius)
        return replace(model, contact=EndContact(pair))._settled()

    cvt_module.chain_loop = chain_loop


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?")
    ap.add_argument("--face-radius", type=float, required=True)
    ap.add_argument("--until", type=float, default=0.03)
    ap.add_argument("--results")
    ap.add_argument("--decompose", nargs="+")
    ap.add_argument("--from", dest="t_from", default="0.02")
    ap.add_argument("--to", dest="t_to", default="0.03")
    ap.add_argument("--txt")
    a = ap.parse_args(argv)
    patch_face_radius(a.face_radius)
    if a.decompose:
        import loss_decomposition
        loss_decomposition.main(a.decompose + ["--from", a.t_from, "--to", a.t_to] + (["--txt", a.txt] if a.txt else []))
        return
    from cvtfem.analysis.run import run_scene
    from cvtfem.scene.loader import load_scene

    summary = run_scene(load_scene(a.scene), until=a.until, results=a.results, show_progress=False, overwrite=True)
    print(summary)


if __name__ == "__main__":
    main()
