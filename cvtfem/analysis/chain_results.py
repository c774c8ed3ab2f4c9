"""Pin positions of a discrete-chain run read back from its results file: the model rebuilt from the stored scene
maps the stored chain coordinates (every chain family lays its coordinates out its own way); where a refined
contact's points lie on the pins' end faces."""
from __future__ import annotations

import tomllib

import numpy as np

from cvtfem.errors import InputError
from cvtfem.machines.cvt import chain_loop, pin_section
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


#: Share of the refined contacts whose point lies off the pin's end face above which `cvtfem history` warns.
OFF_FACE_WARNING = 0.05


def off_face(results) -> dict[str, np.ndarray] | None:
    """Where a refined (H2) run's contact points lie on the pin's end face (``contact.face_offset``), per shaft
    (driving, driven) over all stored rows: ``fraction`` of the contacts (pin ends with ``N > 0``) whose point lies
    farther than the face half-height ``width_n / 2`` from the pin axis, ``mean`` and ``max`` offset (m), and
    ``half_height`` (m, of the stored scene's pin section); None for a run without the series."""
    s = results.series
    if "contact.face_offset" not in s:
        return None
    x = np.asarray(s["contact.face_offset"]).reshape(len(results.time), -1, 2)
    on = np.asarray(s["contact.normal_force"]).reshape(x.shape) > 0
    h = 0.5 * pin_section(scene_from_dict(tomllib.loads(results.scene_toml), str(results.path))).width_n
    n_on = np.maximum(on.sum(axis=(0, 1)), 1)
    return {"fraction": ((x > h) & on).sum(axis=(0, 1)) / n_on, "mean": (x * on).sum(axis=(0, 1)) / n_on,
            "max": np.where(on, x, 0.0).max(axis=(0, 1)), "half_height": h}
