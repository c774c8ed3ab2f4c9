"""``cvtfem rotormaps SCENE``: static deflection, undamped critical-speed map and 2D mode shapes of a rotor."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("rotormaps", help="rotor design maps: static deflection under gravity, undamped "
                       "critical-speed map over support stiffness, 2D mode shapes")
    p.add_argument("scene", metavar="SCENE", help="rotor scene file (.toml) or preset name")
    p.add_argument("--supports", help="shaft nodes of the supports, comma separated (default: the bearings with "
                   "lateral stiffness); rigid in the static case, stiffness k in the map")
    p.add_argument("--stiffness", default="1e5:1e10:26", metavar="K0:K1:N",
                   help="support stiffness range of the map, N/m, log-spaced (default 1e5:1e10:26)")
    p.add_argument("--n-modes", type=int, default=4, help="modes in the map and shapes drawn (default 4)")
    p.add_argument("--speed", default="0rpm", help="spin speed of the mode shapes (default 0rpm)")
    p.add_argument("--gravity", type=float, default=9.80665, help="gravity along -y, m/s^2 (default 9.80665)")
    p.add_argument("--json", metavar="OUT", help="write deflections, map, crossings and modes as JSON")
    p.add_argument("--png", metavar="F.png", help="write the critical-speed map to F.png, the static deflection to "
                   "F_static.png and the mode shapes to F_shapes.png")
    p.set_defaults(func=run)


def _stiffness(text: str):  # noqa: ANN202 - array
    import numpy as np

    from cvtfem.errors import InputError

    try:
        a, b, n = text.split(":")
        a, b, n = float(a), float(b), int(n)
    except ValueError:
        raise InputError("--stiffness", text, "must be K0:K1:N with K0, K1 in N/m and N points, e.g. 1e5:1e10:26")
    if not (0 < a < b < float("inf")) or n < 2:
        raise InputError("--stiffness", text, "needs 0 < K0 < K1 and N >= 2")
    return np.logspace(np.log10(a), np.log10(b), n)


def _supports(text: str | None, model) -> list[int]:  # noqa: ANN001
    import numpy as np

    from cvtfem.errors import InputError

    if text:
        try:
            nodes = [int(v) for v in text.split(",") if v.strip()]
        except ValueError:
            raise InputError("--supports", text, "must be comma-separated shaft node numbers") from None
        model.support_dofs(nodes)  # checks the range
        return nodes
    b = model.bearings
    lateral = ((np.abs(b.kxx) + np.abs(b.kyy)) > 0) & (b.nodes < model.n_shaft_nodes)  # not pedestals' own
    nodes = sorted(set(b.nodes[lateral].tolist()) | set(model.tables.nodes.tolist() if model.tables else ()))
    if not nodes:
        raise InputError("--supports", "", "is needed: the scene has no bearing with lateral stiffness")
    return nodes


def run(args: argparse.Namespace) -> int:
    import json

    import numpy as np

    from cvtfem.commands.modes import load_rotor
    from cvtfem.errors import InputError
    from cvtfem.modal import ModalProblem
    from cvtfem.modal.maps import critical_crossings, critical_speed_map, static_deflection
    from cvtfem.units import parse_speed

    if args.n_modes < 1:
        raise InputError("--n-modes", args.n_modes, "must be >= 1")
    if not 0 < args.gravity < 1e3:
        raise InputError("--gravity", args.gravity, "must be in (0, 1000) m/s^2")
    scene, model = load_rotor(args.scene)
    k = _stiffness(args.stiffness)
    speed = parse_speed(args.speed)
    supports = _supports(args.supports, model)
    pinned = model.support_dofs(supports)
    n = model.n_shaft_nodes
    K_free = model.K - model.support_stiffness()
    u_bearings = static_deflection(model.M, model.K, model.dof_kind, [], args.gravity)
    u_rigid = static_deflection(model.M, K_free, model.dof_kind, pinned.ravel(), args.gravity)
    wn = critical_speed_map(model.M, K_free, model.dof_kind, pinned, k, args.n_modes)

    def frequencies(ki: float):  # noqa: ANN202
        return critical_speed_map(model.M, K_free, model.dof_kind, pinned, [ki], args.n_modes)[0]

    curves, crossings = [], []
    if model.tables is not None and supports[0] in model.tables.nodes.tolist():
        i = model.tables.nodes.tolist().index(supports[0])
        s = np.linspace(model.tables.speeds[i][0], model.tables.speeds[i][-1], 25)
        kxx = np.array([model.tables.coefficients(x)[i, 0] for x in s])
        curves.append((f"kxx(speed) of the support at node {supports[0]}", kxx, s))
        crossings = critical_crossings(frequencies, lambda x: model.tables.coefficients(x)[i, 0], s, args.n_modes)
    else:  # a constant support stiffness: a vertical line, crossed at the map's frequencies there
        b = model.bearings
        at = np.flatnonzero(b.nodes == supports[0])
        kk = float(b.kxx[at].max()) if len(at) else 0.0
        if kk > 0:
            w = frequencies(kk)
            curves.append((f"kxx of the support at node {supports[0]}", np.full(2, kk), (w[0] / 2, 2 * w[-1])))
            crossings = [(j, float(w[j]), kk) for j in range(args.n_modes)]
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, speed_terms=model.speed_terms)
    modes = problem.solve(speed, args.n_modes)
    title = scene.title or str(scene.source)
    print(f"{title}: supports at nodes {', '.join(map(str, supports))}")
    print(f"  static deflection (g = {args.gravity:g} m/s^2): max {1e6 * np.abs(u_bearings[1:6 * n:6]).max():.4g} um "
          f"on the bearings, {1e6 * np.abs(u_rigid[1:6 * n:6]).max():.4g} um on rigid supports")
    print(f"  undamped critical speeds (rpm) at k = {k[0]:.3g} .. {k[-1]:.3g} N/m:")
    for j in range(args.n_modes):
        print(f"    mode {j + 1}: {wn[0, j] * 30 / np.pi:10.5g} .. {wn[-1, j] * 30 / np.pi:10.5g}")
    for j, s, kk in crossings:
        print(f"  mode {j + 1} crosses the support's kxx at {s * 30 / np.pi:.5g} rpm, k = {kk:.4g} N/m")
    print(f"  modes at {speed * 30 / np.pi:.5g} rpm (Hz / log dec / whirl): " + ", ".join(
        f"{w / (2 * np.pi):.4g} / {d:.3g} / {h}" for w, d, h in zip(modes.wd, modes.log_dec, modes.whirl)))
    if args.json:
        out = {"supports": supports, "z_m": model.z[:n].tolist(), "gravity_m_s2": args.gravity,
               "static_bearings_u2_m": u_bearings[1:6 * n:6].tolist(),
               "static_rigid_u2_m": u_rigid[1:6 * n:6].tolist(), "stiffness_n_m": k.tolist(),
               "critical_wn_rad_s": wn.tolist(),
               "crossings": [{"mode": j + 1, "speed_rad_s": s, "stiffness_n_m": kk} for j, s, kk in crossings],
               "modes": modes.to_dict()}
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
        print(f"wrote {args.json}")
    if args.png:
        from cvtfem.post.rotor_maps import plot_critical_map, plot_mode_shapes, plot_static

        disks = model.seats
        stem = args.png[:-4]
        for p in (plot_static(model.z[:n], {"on the bearings": u_bearings[1:6 * n:6],
                                             "rigid supports": u_rigid[1:6 * n:6]}, supports, disks,
                              f"{stem}_static.png", title),
                  plot_critical_map(k, wn, args.png, curves, crossings, title),
                  plot_mode_shapes(model.z, modes, n, f"{stem}_shapes.png", supports, disks)):
            print(f"wrote {p}")
    return 0
