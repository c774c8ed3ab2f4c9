"""The band CVT model: one-pass outputs, control families, Jacobian pattern, power balance."""
import numpy as np
import pytest

from cvtfem.analysis.summary import sample_outputs
from cvtfem.assembly.model import Model
from cvtfem.control.stabilisation import OpenLoop, Stabilisation
from cvtfem.machines import layout
from cvtfem.machines.cvt import closed_loop
from cvtfem.scene.loader import load_scene, scene_from_dict

PRESETS = ("band-4dof", "band-6+2n", "band-6+2n+8")


def _state(model):
    """A state away from steady running (ratio 1.3, every velocity + 0.01)."""
    x = model.initial_state(ratio=1.3)
    x[model.n2:2 * model.n2] += 1e-2
    return x


@pytest.mark.parametrize("name", PRESETS)
def test_outputs_are_the_recorded_set(name):
    scene = load_scene(name)
    model = closed_loop(scene)
    x = _state(model)
    out = model.outputs(0.01, x)
    assert isinstance(model, Model)
    assert list(out) == [s.name for s in model.output_specs] == [o.name for p in layout(scene) for o in p.outputs]
    assert all(np.size(out[s.name]) == s.size for s in model.output_specs)
    ref = sample_outputs(model, 0.01, x)        # what the run driver records
    assert all(np.array_equal(out[k], ref[k]) for k in out)


def test_output_sizes_follow_the_built_model():
    """A quadrature override changes the normal-force output with the model (the scene is read once)."""
    model = closed_loop(load_scene("band-6+2n"), n_gauss=7)
    spec = {s.name: s.size for s in model.output_specs}
    assert spec["band.normal_force"] == 14 == np.size(model.outputs(0.0, model.initial_state())["band.normal_force"])


@pytest.mark.parametrize("name", PRESETS)
def test_power_balance(name):
    """d(T + V)/dt = M1 w1 + M2 w2 + P_clamp - D along the flow (the rates of the work integrals)."""
    model = closed_loop(load_scene(name))
    x = _state(model)
    f = model.rhs(0.01, x)
    h = 1e-6
    dE = (model.energy(x + h * f) - model.energy(x - h * f)) / (2 * h)
    P = model.power(0.01, x)
    assert dE == pytest.approx(P[0] - P[1] + P[3] - P[2], rel=1e-8)


@pytest.mark.parametrize("name", PRESETS)
def test_jacobian_lies_on_its_pattern_and_is_the_linearization(name):
    model = closed_loop(load_scene(name))
    x = _state(model)
    J = model.jac(0.01, x)
    assert not J[~model.jac_sparsity.toarray()].any()
    assert np.array_equal(model.linearize(x, t=0.01).A, J)
    assert np.allclose(J[:model.n2, model.n2:2 * model.n2], np.eye(model.n2), rtol=0, atol=1e-8)  # FD for 4dof


def test_control_family_adds_its_states_and_forces():
    data = {"preset": "band-4dof"}
    closed = closed_loop(scene_from_dict(data))
    open_ = closed_loop(scene_from_dict({**data, "cvt": {"effects": {"stabilisation": False}}}))
    assert isinstance(closed.control, Stabilisation) and isinstance(open_.control, OpenLoop)
    assert closed.size - open_.size == Stabilisation.size == 4
    assert [b.name for b in closed.layout.blocks][-4:] == ["control.speed", "control.F1_integral",
                                                           "control.b2_integral", "work"]
    assert closed.layout.index("control.speed").tolist() == [8, 9]
    assert "control.resistance" in {s.name for s in closed.output_specs} - {s.name for s in open_.output_specs}
    x = open_.initial_state()
    w1d, M1, i_d = open_.regime.targets(0.0)
    F, M, dz, _, _ = open_._controls(0.0, x[[6, 7]], np.zeros(0))      # shaft speeds: v[2], v[3]
    assert dz.size == 0 and M[1] == -M1 * i_d / (w1d / i_d) * x[7]     # fixed resistance b20
    assert np.array_equal(F, open_.clamping.forces(M1, i_d))
