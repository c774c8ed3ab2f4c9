"""The model of a run and its full states at the stored times, read back from a results file: the model is rebuilt
from the stored scene, the states are the ``state`` series (written when the scene sets ``output.state = true``)."""
from __future__ import annotations

import tomllib

import numpy as np

from cvtfem.errors import InputError
from cvtfem.scene.loader import scene_from_dict


def stored_model(results):
    """The closed loop of the CVT scene stored in ``results`` (as the run built it)."""
    from cvtfem.machines.cvt import closed_loop

    scene = scene_from_dict(tomllib.loads(results.scene_toml), source=str(results.path))
    if scene.kind != "cvt":
        raise InputError("RESULTS", str(results.path), f"must be the results file of a CVT run (its scene is a "
                         f"{scene.kind} scene)")
    return closed_loop(scene)


def stored_states(results, model) -> tuple[np.ndarray, np.ndarray]:
    """``(t (s,) s, x (s, n))``: the stored times and full states of ``results``, checked against ``model``."""
    if "state" not in results.series:
        raise InputError("RESULTS", str(results.path), "must store the full state (series `state`) to linearise "
                         "the model at stored times", "set `output.state = true` in the scene and run again")
    x = results.series["state"]
    if x.shape[1] != model.size:
        raise InputError("RESULTS", str(results.path), f"must store states of {model.size} values, the size of "
                         f"the model rebuilt from its scene (it stores {x.shape[1]}: another cvtfem version?)")
    if x.shape[0] == 0:
        raise InputError("RESULTS", str(results.path), "must hold at least one output row (it has none)")
    return results.time, x


def rows_at(t: np.ndarray, times, where: str = "--at") -> np.ndarray:
    """Indices of the stored rows nearest to each of ``times`` (s); InputError for a time outside the run."""
    times = np.atleast_1d(np.asarray(times, float))
    slack = 0.5 * (float(np.median(np.diff(t))) if t.size > 1 else 0.0) + 1e-12
    bad = (times < t[0] - slack) | (times > t[-1] + slack) | ~np.isfinite(times)
    if bad.any():
        raise InputError(where, float(times[bad][0]), f"must lie in the stored run, {t[0]:.6g} .. {t[-1]:.6g} s")
    return np.abs(t[None, :] - times[:, None]).argmin(axis=1)
