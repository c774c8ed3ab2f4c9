"""Pin positions of a discrete-chain run read back from its results file: the model rebuilt from the stored scene
maps the stored chain coordinates (every chain family lays its coordinates out its own way)."""
from __future__ import annotations

import tomllib

import numpy as np

from cvtfem.errors import InputError
from cvtfem.machines.cvt import chain_loop
from cvtfem.scene.loader import scene_from_dict


def pin_positions(results) -> tuple[np.ndarray, float]:
    """Pin positions (rows, n, 2) m at every output row of a chain-CVT results file, and the centre distance (m):
    the model rebuilt from the stored scene maps the stored ``chain.coordinates`` (A5: the mean of a pin's
    halves)."""
    scene = scene_from_dict(tomllib.loads(results.scene_toml), source=str(results.path))
    if scene.kind != "cvt" or not scene.cvt.model.startswith("chain") or "chain.coordinates" not in results.series:
        what = scene.cvt.model if scene.kind == "cvt" else f"a {scene.kind} scene"
        raise InputError("RESULTS", str(results.path), f"must be a run of a discrete chain with the output "
                         f"chain.coordinates (this one is {what})")
    model = chain_loop(scene)
    q = results.series["chain.coordinates"]
    u = np.stack([model.pin_positions(row)[...] for row in q])              # A5: the mean of the halves
    return u, float(scene.cvt.geometry.centre_distance)
