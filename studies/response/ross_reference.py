"""ROSS 3.1 reference numbers for the cvtfem comparison tests (issue 15), written to ``tests/data/ross/``.

Runs ONLY in an environment with Python >= 3.13 and ``ross-rotordynamics`` 3.1 (not cvtfem's): here a Debian
trixie chroot (see docs/response.md, "ROSS comparison"):

    chroot /work/trixie /opt/ross/bin/python /src/studies/response/ross_reference.py /src/tests/data/ross

Writes ``rotor_example.json`` (ROSS ``rotor_example()`` and a damped variant: unbalance response, static
deflection, undamped critical-speed map) and ``compressor.json`` (``compressor_example()``: natural frequencies
and log decrements over speed with its speed-dependent bearing and seal coefficients, static deflection,
undamped critical-speed map). ``studies/response/ross_scenes.py`` turns ROSS's data file of the compressor
(``ross/data/compressor_example.toml`` in the ROSS package, not copied here) into a cvtfem scene.
"""
import json
import sys
from pathlib import Path

import numpy as np
import ross as rs

OUT = Path(sys.argv[1])


def unbalance(rotor, node, me, phase, speeds, probes):
    """x and y response (complex, m) at the probe nodes, per speed."""
    res = rotor.run_unbalance_response(node, me, phase, speed_range=speeds)
    ndof = rotor.number_dof
    fr = np.asarray(res.forced_resp)
    return {str(p): {"x_re": fr[ndof * p].real.tolist(), "x_im": fr[ndof * p].imag.tolist(),
                     "y_re": fr[ndof * p + 1].real.tolist(), "y_im": fr[ndof * p + 1].imag.tolist()}
            for p in probes}


def critical_speeds(rotor, n):
    """1x crossings of the n lowest modes: the fixed points speed = wd(speed) (iterated to 1e-12)."""
    out = []
    for k in range(n):
        s = float(np.asarray(rotor.run_modal(speed=0.0, num_modes=2 * n + 4).wd)[k])
        for _ in range(60):
            new = float(np.asarray(rotor.run_modal(speed=s, num_modes=2 * n + 4).wd)[k])
            if abs(new - s) < 1e-12 * s:
                break
            s = new
        out.append(s)
    return out


def modal(rotor, speed, n):
    m = rotor.run_modal(speed=speed, num_modes=2 * n)
    return {"speed": float(speed), "wn": np.asarray(m.wn).tolist(), "wd": np.asarray(m.wd).tolist(),
            "log_dec": np.asarray(m.log_dec).tolist(),
            "whirl": [str(w) for w in m.whirl_direction()]}


def ucs(rotor, k_range, num, num_modes=16):
    u = rotor.run_ucs(stiffness_range=k_range, num=num, num_modes=num_modes)
    return {"stiffness": np.asarray(u.stiffness_log).tolist(), "wn": np.asarray(u.wn).tolist(),
            "intersection_k": list(u.intersection_points["x"]),
            "intersection_speed": list(u.intersection_points["y"])}


def static(rotor):
    s = rotor.run_static()
    return {"disp_y": np.asarray(s.deformation).tolist(), "nodes_pos": np.asarray(rotor.nodes_pos).tolist(),
            "bearing_forces": {k: float(v) for k, v in rotor.bearing_forces_tag.items()}}


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    rotor = rs.rotor_example()
    speeds = np.linspace(0.0, 1000.0, 101)
    data = {"ross_version": rs.__version__, "speeds": speeds.tolist(),
            "unbalance": {"node": 3, "me": 10.0, "phase": 0.0},
            "undamped": unbalance(rotor, 3, 10.0, 0.0, speeds, (2, 3, 4)),
            "modal_0": modal(rotor, 0.0, 8), "modal_500": modal(rotor, 500.0, 8),
            "static": static(rotor), "ucs": ucs(rotor, (5, 9), 9)}
    damped = rs.Rotor(rotor.shaft_elements, rotor.disk_elements,
                      [rs.BearingElement(n, kxx=1e6, kyy=0.8e6, cxx=300.0, cyy=250.0, cxy=20.0, kxy=2e4, kyx=-1e4)
                       for n in (0, 6)])
    crit = critical_speeds(damped, 4)
    # the 1x critical speeds of the four lowest modes, then between them
    d_speeds = np.unique(np.concatenate([np.linspace(0.0, 1000.0, 41), crit]))
    data["damped"] = {"bearing": {"kxx": 1e6, "kyy": 0.8e6, "cxx": 300.0, "cyy": 250.0, "cxy": 20.0,
                                  "kxy": 2e4, "kyx": -1e4},
                      "speeds": d_speeds.tolist(), "critical_speeds": crit,
                      "response": unbalance(damped, 2, 1e-3, np.pi / 3, d_speeds, (2, 3, 4)),
                      "unbalance": {"node": 2, "me": 1e-3, "phase": float(np.pi / 3)},
                      "modal_300": modal(damped, 300.0, 8)}
    (OUT / "rotor_example.json").write_text(json.dumps(data, indent=1))

    comp = rs.compressor_example()
    cdata = {"ross_version": rs.__version__, "modal": [modal(comp, w, 12) for w in (418.879, 600.0, 837.758,
                                                                                    1047.198, 1151.917, 1300.0)],
             "static": static(comp), "ucs": ucs(comp, (6, 10), 9)}
    c_speeds = np.linspace(400.0, 1300.0, 19)
    cdata["unbalance"] = {"node": 26, "me": 1e-4, "phase": 0.5, "speeds": c_speeds.tolist(),
                          "response": unbalance(comp, 26, 1e-4, 0.5, c_speeds, (20, 26, 35))}
    (OUT / "compressor.json").write_text(json.dumps(cdata, indent=1))


if __name__ == "__main__":
    main()
