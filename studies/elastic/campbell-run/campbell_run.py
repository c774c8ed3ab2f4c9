"""Campbell diagram along a run of chain S2 on elastic shafts in regime A (shortened), the tracked modes over the
support-force spectrogram, and the full Jacobian's spectrum at two stored states (docs/transmission.md).

Run:  .venv/bin/python studies/elastic/campbell-run/campbell_run.py [--until 0.01] [--out out/studies/campbell-run]
      [--results RESULTS.h5]

1. ``chain-S2-A-elastic.toml`` (next to this script; ``output.state = true``, a row every 0.1 ms) runs ``--until``
   seconds unless its results file is given.
2. ``cvtfem runcampbell`` against time and against the driving speed (51 stored times, 14 modes, up to 6 kHz),
   ``cvtfem spectrogram --campbell`` of the driving x1 reaction with those modes, ``cvtfem jacobian`` at 1 ms and
   at the end (PNG + CSV each); the commands print the tracked frequencies, the tracking jumps and the spectra.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from cvtfem.analysis.run import run_scene
from cvtfem.analysis.timing import machine
from cvtfem.cli import main as cli
from cvtfem.scene.loader import load_scene

HERE = Path(__file__).resolve().parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--until", type=float, default=0.01)
    ap.add_argument("--out", default="out/studies/campbell-run")
    ap.add_argument("--results", default=None)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(machine())
    results = args.results
    if results is None:
        results = str(out / "elastic-A.h5")
        print(run_scene(load_scene(HERE / "chain-S2-A-elastic.toml"), until=args.until, results=results,
                        overwrite=True, show_progress=False))
    table = str(out / "campbell.csv")
    common = ["runcampbell", results, "--points", "51", "--modes", "14", "--fmax", "6000"]
    assert cli(common + ["--png", str(out / "campbell-time.png"), "--csv", table]) == 0
    assert cli(common + ["--against", "speed", "--png", str(out / "campbell-speed.png")]) == 0
    assert cli(["spectrogram", results, "--series", "driving.support_force", "--start", "0.001", "--window", "0.002",
                "--overlap", "0.9", "--fmax", "5000", "--campbell", table,
                "--png", str(out / "spectrogram-modes.png")]) == 0
    assert cli(["jacobian", results, "--at", f"0.001,{args.until}", "--png", str(out / "jacobian.png"),
                "--csv", str(out / "jacobian.csv")]) == 0


if __name__ == "__main__":
    main()
