"""``cvtfem run SCENE [--until T] [--summary-json OUT] [--results FILE]``: a time run of a CVT scene.

``cvtfem run --resume RESULTS.h5`` continues a killed run from the newest checkpoint in its
results file (scene, end time and solver from the file), appending to the same file; with ``--until T``
it continues a killed or finished run to the end time T.
``cvtfem run SCENE --resume RESULTS.h5`` checks that SCENE is the stored scene (exit 2 naming the first
differing key otherwise); with ``--resume-changed`` it continues the run with SCENE's values.
"""
from __future__ import annotations

import argparse


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("run", help="time run of a CVT scene (band and chain models), results to HDF5")
    p.add_argument("scene", metavar="SCENE", nargs="?", default=None,
                   help="scene file (.toml) or preset name (e.g. band-4dof); omitted with --resume")
    p.add_argument("--until", type=float, default=None, metavar="T",
                   help="simulated end time, s (default solver.t_end); with --resume: continue the run, killed or "
                        "finished, to T")
    p.add_argument("--results", default=None, metavar="FILE",
                   help="HDF5 results file (default: out/runs/<scene>.h5; 'none' for no file)")
    p.add_argument("--overwrite", action="store_true", help="replace an existing results file")
    p.add_argument("--summary-json", default=None, metavar="OUT", help="write the run summary as JSON")
    p.add_argument("--resume", default=None, metavar="RESULTS.h5",
                   help="continue a killed run from the newest checkpoint of its results file (scene from the "
                        "file; a SCENE given too must equal it); with --until T also a finished run, to T")
    p.add_argument("--resume-changed", action="store_true",
                   help="with SCENE and --resume: continue the run with SCENE's values where they differ from the "
                        "stored scene's (same state layout)")
    p.add_argument("--report-checkpoints", action="store_true",
                   help="print a line on stdout when a checkpoint is on disk")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from cvtfem.analysis.run import resume_run, run_scene
    from cvtfem.errors import InputError
    from cvtfem.scene.loader import load_scene

    def report(t: float, seq: int) -> None:
        print(f"checkpoint {seq} at t = {t:.6g} s", flush=True)

    on_checkpoint = report if args.report_checkpoints else None
    if args.resume_changed and (args.resume is None or args.scene is None):
        raise InputError("--resume-changed", True, "needs SCENE and --resume RESULTS.h5 (it continues that run "
                         "with SCENE's values)")
    if args.resume is not None:
        for name, value in (("--results", args.results), ("--overwrite", args.overwrite or None)):
            if value is not None:
                raise InputError(name, value, "cannot be combined with --resume (the run appends to its own "
                                 "results file)", "run `cvtfem run --resume RESULTS.h5 [--until T]`")
        scene = None if args.scene is None else load_scene(args.scene)
        summary = resume_run(args.resume, on_checkpoint=on_checkpoint, scene=scene, changed=args.resume_changed,
                             until=args.until)
    else:
        if args.scene is None:
            raise InputError("SCENE", None, "is required (a scene file or preset name), unless --resume RESULTS.h5")
        scene = load_scene(args.scene)
        results = args.results
        if results is None:
            results = Path("out") / "runs" / f"{Path(args.scene).stem}.h5"   # a file's or a preset's name
        elif results.lower() == "none":
            results = None
        summary = run_scene(scene, until=args.until, results=results, overwrite=args.overwrite,
                            on_checkpoint=on_checkpoint)
    s = summary
    print(f"{s.model}: {s.simulated_time_s:g} s simulated in {s.wall_time_s:.3g} s wall, "
          f"{s.process_cpu_time_s:.3g} s CPU in this process "
          f"({s.solver['name']}, {s.solver['steps']} steps, {s.solver['nfev']} RHS calls, "
          f"{s.solver['kernel']} right-hand side)")
    print(f"  ratio {s.ratio:.4f} (target {s.target_ratio:g}), input {s.input_speed_rpm:.1f} rpm, "
          f"output {s.output_speed_rpm:.1f} rpm (target {s.target_output_speed_rpm:.1f})")
    eff = (f"efficiency {s.efficiency:.4f} (kinetic-energy corrected {s.efficiency_kinetic:.4f})"
           if s.efficiency is not None else f"efficiency {s.efficiency_note}")
    print(f"  {eff}, clamping {s.clamping_force_N[0] / 1e3:.2f} / {s.clamping_force_N[1] / 1e3:.2f} kN")
    if s.off_face_fraction is not None:
        from cvtfem.analysis.chain_results import OFF_FACE_WARNING

        off = s.off_face_fraction
        print(f"  contact points off the pin end face at the end: driving {off[0]:.0%}, driven {off[1]:.0%}"
              + (f" (warning: more than {OFF_FACE_WARNING:.0%}; see `cvtfem history`)" if max(off) > OFF_FACE_WARNING
                 else ""))
    if s.results:
        print(f"  results: {s.results}")
    if args.summary_json:
        Path(args.summary_json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.summary_json).write_text(json.dumps(s.to_dict(), indent=2) + "\n", encoding="utf-8")
        print(f"  summary: {args.summary_json}")
    return 0
