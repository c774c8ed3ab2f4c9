"""``cvtfem spectrum SCENE --speeds A:B:N --node N [--orders ...] [--chain ...] [--ripple ...] [--lines F]``:
order map, excitation-line responses and ERP of the sheave faces over speed."""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("spectrum", help="order map, pin-entry / ripple / user line responses and sheave-face ERP "
                                        "of a rotor scene over a speed sweep")
    p.add_argument("scene", metavar="SCENE", help="rotor scene file (.toml) or preset name")
    p.add_argument("--speeds", required=True, help="START:STOP<unit>:COUNT, unit rpm, rad/s or Hz (0:6000rpm:121)")
    p.add_argument("--node", type=int, required=True, help="shaft node whose |(u1, u2, u3)| is reported")
    p.add_argument("--orders", help="order lines k (w = k x speed) drawn and followed, comma separated")
    p.add_argument("--chain", metavar="R:N:LSHORT:LLONG:FLONG[:SEED]",
                   help="pin entry on the sheaves: pitch radius R (m), N links of lengths LSHORT/LLONG (m), share "
                        "FLONG of long links placed at random (seed SEED, default 0; FLONG 0: a uniform chain)")
    p.add_argument("--impulse", type=float, default=1e-3, help="impulse of one pin entry per sheave, N s "
                                                               "(default 1e-3)")
    p.add_argument("--entry-angle", type=float, default=0.0, help="angle of the chain's entry point, deg")
    p.add_argument("--link-harmonics", type=int, default=3, help="pin-entry lines up to this multiple of f_link")
    p.add_argument("--ripple", action="append", default=[], metavar="NODE:ORDER:TORQUE",
                   help="torque ripple of amplitude TORQUE (N m) at shaft order ORDER on node NODE; repeatable")
    p.add_argument("--lines", metavar="FILE.csv",
                   help="user force lines: CSV with header node,dof,order,freq_hz,amplitude,phase_deg")
    p.add_argument("--force-node", type=int, help="without --chain: node of the unit x force driving the map "
                                                  "(default --node)")
    p.add_argument("--n-freqs", type=int, default=200, help="frequency lines of the map (default 200)")
    p.add_argument("--fmax", type=float, metavar="HZ", help="top of the map, Hz (default: highest order line)")
    p.add_argument("--n-modes", type=int, default=12, help="modes of the superposition (default 12)")
    p.add_argument("--results", metavar="OUT.h5", help="write the spectra as an HDF5 results file")
    p.add_argument("--json", metavar="OUT", help="write map, order responses, lines and ERP as JSON")
    p.add_argument("--png", metavar="OUT.png", help="order map; with excitation sources also OUT_erp.png "
                                                    "(ERP over speed)")
    p.set_defaults(func=run)


def _chain(args: argparse.Namespace):
    import numpy as np

    from cvtfem.analysis.spectrum import PinEntry
    from cvtfem.errors import InputError
    from cvtfem.modal.excitation import chain_pattern

    rule = "must be R:N:LSHORT:LLONG:FLONG[:SEED] (m, links, m, m, 0..1, integer), e.g. 0.06:84:0.008:0.01:0.5"
    parts = args.chain.split(":")
    try:
        if len(parts) not in (5, 6):
            raise ValueError
        r, n, ls, ll, fl = float(parts[0]), int(parts[1]), float(parts[2]), float(parts[3]), float(parts[4])
        seed = int(parts[5]) if len(parts) == 6 else 0
    except ValueError:
        raise InputError("--chain", args.chain, rule) from None
    if not (np.isfinite([r, ls, ll]).all() and r > 0 and 0 < ls <= ll < 1 and 3 <= n <= 10_000 and 0 <= fl <= 1
            and seed >= 0):
        raise InputError("--chain", args.chain, "needs R > 0, 3 <= N <= 10000, 0 < LSHORT <= LLONG < 1 m, "
                                                "0 <= FLONG <= 1, SEED >= 0")
    if not (np.isfinite(args.impulse) and args.impulse > 0):
        raise InputError("--impulse", args.impulse, "must be a finite impulse > 0 N s")
    if not np.isfinite(args.entry_angle):
        raise InputError("--entry-angle", args.entry_angle, "must be a finite angle in deg")
    if not 1 <= args.link_harmonics <= 20:
        raise InputError("--link-harmonics", args.link_harmonics, "must be 1..20")
    lengths = chain_pattern(n, ls, ll, fl, seed)
    return PinEntry(lengths, r, args.impulse, np.radians(args.entry_angle), args.link_harmonics)


def _ripple(text: str):
    from cvtfem.analysis.spectrum import Ripple
    from cvtfem.errors import InputError

    try:
        node, order, torque = text.split(":")
        return Ripple(int(node), float(order), float(torque))
    except ValueError:
        raise InputError("--ripple", text, "must be NODE:ORDER:TORQUE (node, shaft order, N m), e.g. 4:2:5") from None


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    import numpy as np

    from cvtfem.analysis.spectrum import read_user_lines, scene_spectrum, write_results
    from cvtfem.commands.response import parse_orders, print_crossings, sweep_speeds, write_data
    from cvtfem.errors import InputError
    from cvtfem.scene.loader import load_scene

    speeds = sweep_speeds(args.speeds)
    if not 1 <= args.n_modes <= 500:
        raise InputError("--n-modes", args.n_modes, "must be 1..500")
    if not 2 <= args.n_freqs <= 20_000:
        raise InputError("--n-freqs", args.n_freqs, "must be 2..20000")
    if args.fmax is not None and not 0.0 < args.fmax < 1e9:
        raise InputError("--fmax", args.fmax, "must be a frequency in Hz with 0 < fmax < 1e9")
    pin = _chain(args) if args.chain else None
    ripples = [_ripple(r) for r in args.ripple]
    user = read_user_lines(args.lines) if args.lines else []
    scene = load_scene(args.scene)
    res = scene_spectrum(scene, speeds, args.node, parse_orders(args.orders), pin, ripples, user, args.force_node,
                         args.n_freqs, None if args.fmax is None else 2 * np.pi * args.fmax, args.n_modes)
    rpm = res.speeds * 30 / np.pi
    print(f"{scene.title or scene.source}: spectrum at node {res.node}, {len(speeds)} speeds; map input "
          f"{res.map_input}")
    top = max(res.freqs[-1], res.line_freqs.max(initial=0.0))
    print(f"  modal basis up to {res.wmax / 2 / np.pi:.5g} Hz (--n-modes {args.n_modes})"
          + ("" if top <= res.wmax else f"; lines up to {top / 2 / np.pi:.5g} Hz: above the basis only the residual "
                                        "vectors carry them, raise --n-modes"))
    for j, k in enumerate(res.orders):
        m = int(np.argmax(res.order_amplitude[:, j]))
        print(f"  order {k:.5g}: largest response {res.order_amplitude[m, j]:.4g} per unit at {rpm[m]:.5g} rpm")
    print("  Campbell crossings of the order lines:")
    print_crossings(res.campbell.crossings, 10, 10)
    if res.line_labels:
        i = int(np.nanargmax(np.where(np.isfinite(res.erp_a_db), res.erp_a_db, -np.inf)))
        print(f"  {len(res.line_labels)} excitation lines; sheave-face ERP up to {np.nanmax(res.erp_db[1:]):.1f} dB, "
              f"A-weighted {res.erp_a_db[i]:.1f} dB(A) re 1 pW at {rpm[i]:.5g} rpm")
    write_data(res, scene, args, write_results)
    if args.png:
        from cvtfem.post.response import plot_erp, plot_spectrum_map

        plot_spectrum_map(res, args.png, title=scene.title or scene.source)
        print(f"wrote {args.png}")
        if res.line_labels:
            path = Path(args.png)
            erp_png = path.with_name(f"{path.stem}_erp.png")
            plot_erp(res, erp_png, title=scene.title or scene.source)
            print(f"wrote {erp_png}")
    return 0
