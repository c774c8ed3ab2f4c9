"""Demo part: the reference CVT scene, its model layout and link pattern."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def run(outdir: Path) -> list[str]:
    """Describe the reference scene and plot its randomised link pattern."""
    from cvtfem.elements.link_pattern import link_lengths
    from cvtfem.machines import describe
    from cvtfem.post.figures import pyplot, save
    from cvtfem.scene.loader import load_scene

    scene = load_scene("reference_cvt")
    (outdir / "reference_cvt_describe.txt").write_text(describe(scene) + "\n")
    chain = scene.cvt.chain
    lengths = link_lengths(chain.n_pins, chain.pitch_short, chain.pitch_long, chain.long_fraction,
                           np.random.default_rng(scene.seed))
    fig, ax = pyplot().subplots(figsize=(9, 3))
    ax.bar(np.arange(lengths.size), lengths * 1e3, width=0.8,
           color=np.where(lengths > lengths.min(), "tab:red", "tab:blue"))
    ax.set_ylim(chain.pitch_short * 1e3 - 0.5, chain.pitch_long * 1e3 + 0.3)
    ax.set_xlabel("link number")
    ax.set_ylabel("link length, mm")
    ax.set_title(f"reference_cvt: randomised chain, {lengths.size} links (seed {scene.seed}), "
                 f"length {lengths.sum():.4f} m")
    fig.tight_layout()
    png = save(fig, outdir / "reference_cvt_links.png")
    return [f"reference_cvt_describe.txt: components, coordinates ({scene.cvt.model}) and outputs",
            f"{png.name}: long/short link pattern of the reference chain"]
