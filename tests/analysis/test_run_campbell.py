"""Campbell diagrams along a run from the structure block J11 (cvtfem.analysis.run_campbell)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cvtfem.analysis.run_campbell import run_campbell, structure_rows
from cvtfem.errors import InputError
from cvtfem.machines.cvt import closed_loop
from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem, campbell
from cvtfem.scene.loader import load_scene
from tests.machines.test_chain_cvt_elastic import _frequencies, _rotor_scene

#: The chain on elastic shafts at the chapter-2 regime (ratio 0.45: its quasi-static start is the cheapest).
SCENE = "chain-S2,regime-chapter2,shafts-elastic"


@pytest.fixture(scope="module")
def scene():
    return load_scene(SCENE)


@pytest.fixture(scope="module")
def running(scene):
    """The closed loop and its start state (chain on the sheaves, shafts turning)."""
    model = closed_loop(scene)
    x0, _ = model.start()
    return model, x0


def _chain_removed(model, x0, speeds=(0.0, 0.0)):
    """The model with contact stiffness zero and the state with the structure at rest but its shafts' nodes
    spinning at ``speeds`` (rad/s; every node of shaft k)."""
    z_ref, rigid_start = model._reference                  # the faces' references of the running model, solved now
    free = replace(model, contact=replace(model.contact, c=np.zeros(2)), z_ref=z_ref, rigid_start=rigid_start)
    s, nc, n2 = model.structure, model.family.size, model.n2
    x = x0.copy()
    x[n2 + nc:2 * n2] = 0.0
    for k, w in enumerate(speeds):
        first = n2 + nc + s.offset[k]
        x[first + 5:first + 6 * len(s.x[k]):6] = w
    return free, x


def test_standstill_without_contact_stiffness_gives_the_rotor_codes_frequencies(scene, running, tmp_path):
    """Acceptance of issue 14: at standstill with the contact stiffness zero the Campbell lines of J11 equal the
    natural frequencies of the same shafts and sheaves from the rotor code (`cvtfem modes`' path, one rotor scene
    per shaft) to 0.5 % (they agree to 1e-6): every bending and torsion mode below 5 kHz of both shafts. Axial
    modes differ by design (the movable sheave slides on its shaft) and are left out."""
    free, x = _chain_removed(*running)
    result = run_campbell(free, [0.0], x[None, :], n_modes=20)
    mine = result.wd[0] / (2 * np.pi)
    mine = np.sort(mine[(result.whirl[0] != "axial") & (mine < 5e3)])
    ref = []
    for k in range(2):
        rotor = build_model(_rotor_scene(tmp_path, scene, k))
        f, whirl = _frequencies(rotor.M, rotor.K, rotor.C, rotor.dof_kind, n=24)
        ref.append(f[(whirl != "axial") & (f < 5e3)])
    ref = np.sort(np.concatenate(ref))
    assert len(ref) >= 16 and len(mine) == len(ref)
    np.testing.assert_allclose(mine, ref, rtol=5e-3)
    np.testing.assert_allclose(mine, ref, rtol=1e-6)          # what it really is: the same structure
    assert np.all(result.mac == 1.0) and not result.jumps


def test_tracking_follows_the_gyroscopic_split_of_the_rotor_code(running):
    """States with the shafts spinning up (driving 40 -> 900 rad/s, driven 1 / 0.45 times faster: the chapter-2
    ratio), chain removed: the MAC-tracked curves of J11 equal the rotor code's Campbell diagram
    (``modal.campbell`` on the structure's M, K, C and the speed-weighted G of both shafts) to 1e-6 at every speed;
    every curve is continuous (MAC with the previous speed above 0.95, no jump), forward whirl curves rise and
    backward ones fall with the speed (gyroscopic stiffening and softening)."""
    model, x0 = running
    s = model.structure
    w1 = np.linspace(40.0, 900.0, 12)
    ratio = 0.45
    states = np.array([_chain_removed(model, x0, (w, w / ratio))[1] for w in w1])
    free, _ = _chain_removed(model, x0)
    result = run_campbell(free, w1, states, n_modes=10)
    problem = ModalProblem(s.M, s.K, s.C, s.G[0] + s.G[1] / ratio, s.dof_kind)
    reference = campbell(problem, w1, 10, orders=())
    np.testing.assert_allclose(result.wd, reference.wd, rtol=1e-6)
    assert result.mac.min() > 0.95 and not result.jumps
    np.testing.assert_allclose(result.speed, np.column_stack([w1, w1 / ratio]))
    step = np.diff(result.wd, axis=0)
    for j in range(result.wd.shape[1]):
        kinds = set(result.whirl[:, j])
        assert len(kinds) == 1                                    # one mode, one whirl along its curve
        if kinds == {"forward"}:
            assert np.all(step[:, j] > 0)
        elif kinds == {"backward"}:
            assert np.all(step[:, j] < 0)
    assert {"forward", "backward"} <= set(result.whirl.ravel())


def test_bad_input_is_named(running):
    model, x0 = running
    with pytest.raises(InputError, match="states"):
        run_campbell(model, [0.0, 1.0], x0[None, :], 4)
    with pytest.raises(InputError, match="n_modes"):
        run_campbell(model, [0.0], x0[None, :], 0)
    with pytest.raises(InputError, match="elastic shafts"):
        structure_rows(model.rigid())
