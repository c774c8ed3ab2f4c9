"""A band-model CVT scene as an integrator study problem (``cvtfem study work|order --scene``).

The closed loop of the scene (model, clamping, regime, stabilisation) becomes a
:class:`~cvtfem.problems.base.Problem` with its second-order structure (``n2``) and analytic
Jacobian; the error of a run is measured on engineering outputs at ``t_end``: ratio, driving
and driven speeds and the output/input work ratio (relative, the largest of the four), against
a Radau run at tight tolerance. The analysis layer knows both sides: ``cvtfem.problems`` stays
free of CVTs.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cvtfem.errors import InputError
from cvtfem.problems.base import Problem

__all__ = ["SceneProblem", "scene_problem", "OUTPUTS"]

OUTPUTS = ("ratio", "input_speed", "output_speed", "work_ratio")


@dataclass(frozen=True)
class SceneProblem(Problem):
    """A scene's closed loop; ``y_ref`` holds the reference :data:`OUTPUTS` at ``t_span[1]``."""

    loop: object = None
    ref_setting: dict = field(default_factory=dict)

    def outputs(self, x: np.ndarray) -> np.ndarray:
        """Ratio, input and output speed (rad/s), output/input work of a state (:data:`OUTPUTS`)."""
        loop = self.loop
        n = loop.model.n2
        k1, k2 = loop.model.speed_indices()
        w1, w2 = x[n + k1], x[n + k2]
        W = x[-4:]
        return np.array([w1 / w2, w1, w2, W[1] / W[0]])

    def error(self, res) -> float:
        """Largest relative output error of a run at ``t_end`` (``inf`` for a failed run)."""
        if not res.success or abs(res.t[-1] - self.t_span[1]) > 1e-12 * self.t_span[1]:
            return float("inf")
        return float(np.max(np.abs(self.outputs(res.y[:, -1]) - self.y_ref) / np.abs(self.y_ref)))


def scene_problem(scene, until: float, ref_rtol: float = 1e-9, ref_method: str = "Radau") -> SceneProblem:
    """Study problem of a band-model scene (preset name, path or :class:`Scene`) over ``[0, until]`` s.

    The reference is ``ref_method`` at ``rtol = ref_rtol``, ``atol = 1e-2 ref_rtol`` (analytic
    Jacobian). On band-6+2n over 0.05 s, Radau at 1e-8 and 1e-9 agree to 3e-11 in the outputs.
    """
    from cvtfem.integrate import solve
    from cvtfem.machines.cvt import closed_loop
    from cvtfem.scene.loader import load_scene

    if not (np.isfinite(until) and until > 0):
        raise InputError("--until", until, "must be a positive simulated time in s")
    sc = load_scene(scene) if isinstance(scene, str) else scene
    loop = closed_loop(sc)
    x0 = loop.initial_state()
    n2 = loop.n2
    name = scene if isinstance(scene, str) else getattr(sc, "name", "scene")
    base = SceneProblem(name, loop.rhs, x0, (0.0, float(until)), n2=n2, jac=loop.jac, loop=loop)
    ref = solve(loop.rhs, (0.0, float(until)), x0, method=ref_method, rtol=ref_rtol,
                atol=1e-2 * ref_rtol, jac=loop.jac, n2=n2, t_eval=np.array([float(until)]))
    if not ref.success:
        raise InputError("--scene", name, f"reference run ({ref_method}, rtol {ref_rtol:g}) failed: "
                         f"{ref.message}")
    return SceneProblem(name, loop.rhs, x0, (0.0, float(until)), n2=n2, jac=loop.jac,
                        y_ref=base.outputs(ref.y[:, -1]), loop=loop,
                        ref_setting={"method": ref_method, "rtol": ref_rtol},
                        info={"n": len(x0), "n2": n2})
