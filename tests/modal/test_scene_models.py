"""Rotor scenes end to end: geometric disks, elastic sheave connections, nonlinear bearing tangents."""
import tomllib

import numpy as np
import pytest

from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem
from cvtfem.scene.loader import load_scene, preset_text, scene_from_dict


def modes(scene, speed=0.0, n=8):
    m = build_model(scene)
    return ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind).solve(speed, n)


def friswell_dict():
    return tomllib.loads(preset_text("friswell_5_9_1"))


def test_disks_from_geometry_reproduce_friswell():
    data = friswell_dict()
    data["disk"] = [{"node": 2, "geometry": "disc", "material": "steel", "width": 0.07, "inner_diameter": 0.05,
                     "outer_diameter": 0.28},
                    {"node": 4, "geometry": "disc", "material": "steel", "width": 0.07, "inner_diameter": 0.05,
                     "outer_diameter": 0.35}]
    r = modes(scene_from_dict(data), 4000 * np.pi / 30, 6)
    np.testing.assert_allclose(r.wd, [85.39, 87.80, 251.78, 294.71, 600.18, 650.41], rtol=1e-3)


def test_stiff_elastic_connection_tends_to_rigid():
    data = friswell_dict()
    rigid = modes(scene_from_dict(data), 300.0)
    for d in data["disk"]:
        d.update(connection="elastic", c_u=1e14, c_theta=1e12, c_3=1e14, c_phi=1e12)
    elastic = modes(scene_from_dict(data), 300.0)
    np.testing.assert_allclose(elastic.wd, rigid.wd, rtol=1e-5)
    for d in data["disk"]:
        d.update(c_u=1e7, c_theta=1e5)
    soft = modes(scene_from_dict(data), 300.0)
    assert np.all(soft.wd[:4] < rigid.wd[:4])                   # a softer connection lowers the bending modes


def test_nonlinear_bearing_tangent_splits_the_pairs():
    """Hardening f_r = c1 u + c3 u^3 preloaded along e1: radial tangent > tangential secant (spec §12.4)."""
    data = friswell_dict()
    for b in data["bearing"]:
        b.pop("kxx"), b.pop("kyy")
        b.update(law="polynomial", coeffs=[1e6, 0.0, 1e14], u0=[0.0, 0.0])
    at_rest = modes(scene_from_dict(data), 0.0, 2)
    np.testing.assert_allclose(at_rest.wd, [86.66, 86.66], rtol=1e-3)   # f'(0) = 1e6 N/m: the linear rotor
    for b in data["bearing"]:
        b["u0"] = [1e-4, 0.0]
    loaded = build_model(scene_from_dict(data))
    Kx = loaded.K[0, 0] - build_model(scene_from_dict(friswell_dict())).K[0, 0] + 1e6
    assert Kx == pytest.approx(1e6 + 3e14 * 1e-8)
    r = ModalProblem(loaded.M, loaded.K, loaded.C, loaded.G, loaded.dof_kind).solve(0.0, 2)
    assert r.wd[1] / r.wd[0] > 1.01                                     # anisotropic support splits the pair


def test_cvt_sheave_shaft_preset():
    scene = load_scene("cvt_sheave_shaft")
    m = build_model(scene)
    assert m.n_dof == 6 * (11 + 1)                                       # one elastically connected sheave
    assert m.disks.m[1] > m.disks.m[0]                                   # longer hub
    r = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind).solve(4000 * np.pi / 30, 6)
    assert np.all(r.damping_ratio > 0) and "axial" in r.whirl and "torsional" in r.whirl
    # the free torsion block (no torsional support) has a rigid rotation, not a mode: before issue 11 a
    # Cholesky definiteness test let it through as a 'torsional' mode at ~1e-3 rad/s under some BLAS kernels
    assert r.wd[0] > 3000.0 and r.whirl[0] == "backward"


@pytest.mark.parametrize("change,where", [
    ({"disk": [{"node": 2, "mass": 1.0, "Id": 0.0, "Ip": 1.0}]}, "disk[0].Id"),
    ({"disk": [{"node": 2, "geometry": "disc", "material": "steel", "outer_diameter": 0.2}]}, "disk[0].width"),
    ({"disk": [{"node": 2, "geometry": "disc", "material": "brass", "width": 0.1, "outer_diameter": 0.2}]},
     "disk[0].material"),
    ({"bearing": [{"node": 0, "law": "polynomial"}]}, "bearing[0].coeffs"),
    ({"rotor": {"theory": "bernoulli"}}, "rotor.theory"),
])
def test_bad_scenes_name_the_key(change, where):
    data = friswell_dict()
    data.update(change)
    with pytest.raises(InputError, match=where.replace("[", r"\[").replace("]", r"\]")):
        scene_from_dict(data)


def test_shear_coefficient_option():
    """kappa = Cowper's value reproduces the default; a smaller kappa (more shear) lowers the frequencies."""
    from cvtfem.elements.beam import cowper_kappa

    data = friswell_dict()
    base = modes(scene_from_dict(data), 0.0, 6)
    data["rotor"]["shear_coefficient"] = float(cowper_kappa(2.11e11 / (2 * 8.12e10) - 1, 0.0))
    np.testing.assert_allclose(modes(scene_from_dict(data), 0.0, 6).wd, base.wd, rtol=1e-12)
    data["rotor"]["shear_coefficient"] = 0.3
    assert np.all(modes(scene_from_dict(data), 0.0, 6).wd[[0, 1, 2, 3, 5]] < base.wd[[0, 1, 2, 3, 5]])
    data["rotor"]["theory"] = "euler-bernoulli"
    assert np.all(modes(scene_from_dict(data), 0.0, 6).wd[[0, 2, 5]] > base.wd[[0, 2, 5]])


def test_too_many_modes_is_a_numerical_error(cli):
    r = cli("modes", "friswell_5_9_1", "--n-modes", "500")
    assert r.returncode == 3 and "oscillatory modes" in r.stderr
    r = cli("modes", "reference_cvt")
    assert r.returncode == 2 and "rotor scene" in r.stderr


@pytest.mark.parametrize("speed", [0.0, 400.0])
def test_sparse_backend_on_damped_model_with_rigid_and_tiny_blocks(speed):
    """CVT shaft: damping, free torsion/axial, a 1-DOF block (the free-sliding sheave axially)."""
    m = build_model(load_scene("cvt_sheave_shaft"))
    dense = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method="dense").solve(speed, 10)
    p = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind, method="sparse")
    assert "sparse" in [p.backend(b, 10) for b in range(len(p.blocks))]
    sparse = p.solve(speed, 10)
    np.testing.assert_allclose(sparse.eigenvalues, dense.eigenvalues, rtol=1e-9)
    assert sparse.whirl == dense.whirl


def test_planar_modes_at_rest_take_the_label_of_the_spinning_limit():
    """Anisotropic (preloaded) bearings: x/y modes are planar at rest; labels = those at a small speed."""
    m = build_model(load_scene("cvt_sheave_shaft"))
    p = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind)
    rest, slow = p.solve(0.0, 10), p.solve(5.0, 10)
    lateral = np.isin(rest.whirl, ("forward", "backward"))
    assert np.all(np.abs(rest.whirl_ratio[lateral]) < 1e-6)      # planar at rest
    assert np.all(np.abs(slow.whirl_ratio[lateral]) > 1e-4)      # elliptic when spinning
    assert rest.whirl == slow.whirl
