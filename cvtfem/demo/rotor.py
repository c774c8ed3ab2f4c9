"""Demo part (issue 3): Campbell diagrams, a rendered mode shape, section properties."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

RPM = np.pi / 30


def run(outdir: Path) -> list[str]:
    """Friswell 5.9.1 Campbell + mode rendering; CVT sheave shaft Campbell with chain orders; pin section."""
    from cvtfem.machines.rotor import build_model
    from cvtfem.modal import ModalProblem, campbell, chain_orders, shaft_orders
    from cvtfem.post.campbell import plot_campbell
    from cvtfem.render.rotor import render_mode
    from cvtfem.scene.loader import load_scene
    from cvtfem.sections import load_section_mesh, section_properties
    from cvtfem.sections.meshes import MESH_DIR

    lines = []
    m = build_model(load_scene("friswell_5_9_1"))
    problem = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)
    res = campbell(problem, np.linspace(0, 4000 * RPM, 51), 12, shaft_orders((1.0, 2.0)))
    png = plot_campbell(res, outdir / "rotor_friswell_campbell.png", "Friswell et al. example 5.9.1")
    (outdir / "rotor_friswell_campbell.json").write_text(json.dumps(res.to_dict()))
    first = [c for c in res.crossings if c["order"] == "1x"][:2]
    lines.append(f"{png.name}: Campbell diagram of Friswell 5.9.1 (51 speeds x 12 modes); 1x critical speeds "
                 + ", ".join(f"{c['speed_rad_s'] / RPM:.0f} rpm ({c['whirl']})" for c in first))
    lines.append("rotor_friswell_campbell.json: per-speed modes, tracked curves, orders, critical speeds")
    at = res.modes[-1]
    png = render_mode(m, at, 1, outdir / "rotor_friswell_mode1_4000rpm.png")
    lines.append(f"{png.name}: first forward whirl mode at 4000 rpm, {at.wd[1]:.2f} rad/s "
                 "(red deformed over faint undeformed, black orbits)")

    m = build_model(load_scene("cvt_sheave_shaft"))
    problem = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)
    orders = shaft_orders((1.0,)) + chain_orders(radius=0.06, chain_length=0.7, link_length=0.009)
    res = campbell(problem, np.linspace(0, 6000 * RPM, 61), 10, orders)
    png = plot_campbell(res, outdir / "rotor_cvt_sheave_shaft_campbell.png",
                        "CVT sheave shaft: chain orders k f_chain, k/3 f_link (contact radius 60 mm)",
                        fmax=6000.0)
    link = [c for c in res.crossings if "f_link" in c["order"]]
    lines.append(f"{png.name}: Campbell diagram of the assumed CVT sheave shaft with chain excitation lines; "
                 f"{len(link)} link-order crossings below 6000 rpm")
    props = section_properties(load_section_mesh(MESH_DIR / "rocker_pin.vtu"), nu=0.3)
    (outdir / "rotor_pin_section.json").write_text(json.dumps(props.__dict__, indent=1))
    lines.append(f"rotor_pin_section.json: rocker-pin section by scikit-fem: A = {props.A * 1e6:.3f} mm^2, "
                 f"J = {props.J * 1e12:.2f} mm^4 (Ixx + Iyy = {(props.Ixx + props.Iyy) * 1e12:.2f}), "
                 f"kappa = {props.kappa_x:.3f} / {props.kappa_y:.3f}")
    return lines
