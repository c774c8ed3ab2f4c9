"""Bearings between two nodes (ROSS ``n_link``): a shaft on pedestals that sit on their own supports."""
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.scene.loader import scene_from_dict

K1, K2, M2, M_DISK = 3.0e6, 5.0e6, 20.0, 80.0   # N/m shaft-pedestal, N/m pedestal-ground, kg, kg


def pedestal_rotor(E=2.0e11, rho=7800.0, length=0.8, diameter=0.05, k1=K1, k2=K2):
    """Two elements, a disk at the middle node 1, bearings at nodes 0 and 2 linked to pedestal nodes 3 and 4.

    Each pedestal carries ``M2`` on a support ``k2``; the bearings carry ``k1`` on ``u_shaft - u_pedestal``.
    Axial and torsion are held by the same links (kzz, kphi); pedestal tilts by their supports (ktt).
    """
    link = dict(kxx=k1, kyy=k1, kzz=1e7, kphi=1e5)
    ground = dict(kxx=k2, kyy=k2, kzz=1e7, kphi=1e5, ktt=1e5, mass=M2, Id=0.1, Ip=0.2)
    return {"material": [{"name": "steel", "E": E, "G": E / 2.6, "rho": rho}],
            "shaft": [{"length": length / 2, "outer_diameter": diameter, "material": "steel", "repeat": 2}],
            "disk": [{"node": 1, "mass": M_DISK, "Id": 0.5, "Ip": 1.0}],
            "bearing": [{"node": 0, "link_node": 3, **link}, {"node": 2, "link_node": 4, **link},
                        {"node": 3, **ground}, {"node": 4, **ground}]}


def test_static_deflection_is_beam_plus_springs_in_series():
    """Midspan force F: F L^3 / 48 EI + F L / (4 kappa G A) of the Timoshenko beam (exact with a node under the
    load) plus the support's (F / 2)(1/k1 + 1/k2): the link and pedestal springs in series."""
    data = pedestal_rotor()
    model = build_model(scene_from_dict(data))
    assert model.n_dof == 6 * 5
    F = 1000.0
    f = np.zeros(model.n_dof)
    f[6 * 1] = F
    u = spla.spsolve(model.K.tocsc(), f)
    b = model.beam
    L = 0.8
    EI, kGA = b.E[0] * b.inertia[0], b.shear_coefficient[0] * b.G[0] * b.area[0]
    expected = F * L**3 / (48 * EI) + F * L / (4 * kGA) + F / 2 * (1 / K1 + 1 / K2)
    assert u[6] == pytest.approx(expected, rel=1e-12)
    assert u[6 * 3] == pytest.approx(F / 2 / K2, rel=1e-12)   # the pedestal carries half the load on k2
    # the bearing force of a link is k1 (u_shaft - u_pedestal) = F/2; the pedestal's support also carries F/2
    D, _ = model.bearing_force_map()
    np.testing.assert_allclose((D @ u)[[0, 2, 4, 6]], [F / 2] * 4, rtol=1e-12)
    np.testing.assert_allclose((D @ u)[[1, 3, 5, 7]], 0.0, atol=1e-12 * F)


def lowest(model, k=10):
    """Lowest squared frequencies by shift-invert (dense eigh loses ~1e-5 on them: the stiff shaft's axial
    modes make w^2 span 1e11)."""
    return spla.eigsh(model.K.tocsc(), k, model.M.tocsc(), sigma=0.0, v0=np.ones(model.n_dof),
                      return_eigenvectors=False)


def test_stiff_shaft_has_the_rigid_rotor_on_pedestal_frequencies():
    """A (nearly) rigid shaft: its bounce modes are those of the 2-DOF model rotor mass m on 2 k1 to pedestal
    mass 2 M2 on 2 k2, [[2k1, -2k1], [-2k1, 2k1 + 2k2]] x = w^2 diag(m, 2 M2) x, m = disk + shaft mass
    (the consistent mass is exact for a rigid translation)."""
    data = pedestal_rotor(E=1e13, diameter=0.4, length=0.2, rho=1.0)
    model = build_model(scene_from_dict(data))
    m_rotor = M_DISK + 1.0 * np.pi / 4 * 0.4**2 * 0.2
    k = np.array([[2 * K1, -2 * K1], [-2 * K1, 2 * K1 + 2 * K2]])
    w2 = sla.eigh(k, np.diag([m_rotor, 2 * M2]), eigvals_only=True)
    w2_model = lowest(model)
    b = model.beam   # the shaft's midspan compliance against the links': the model's only departure from 2 DOF
    compliance = K1 * (0.2**3 / (48 * b.E[0] * b.inertia[0]) + 0.2 / (4 * b.shear_coefficient[0] * b.G[0] * b.area[0]))
    assert 1e-7 < compliance < 1e-6
    for value in w2:   # each twice (x and y)
        close = np.abs(w2_model / value - 1)
        assert np.sum(close < 2 * compliance) == 2, (value, np.sort(close)[:3])
    # without the pedestal (links to ground, k1 only) the bounce mode is sqrt(2 k1 / m): the links are relative
    ground = dict(data, bearing=[{**b, "link_node": -1} for b in data["bearing"][:2]])
    w2_ground = lowest(build_model(scene_from_dict(ground)))
    assert np.sum(np.abs(w2_ground / (2 * K1 / m_rotor) - 1) < 1e-6) == 2


def test_link_between_two_shaft_nodes_is_symmetric_and_relative():
    """A link between shaft nodes 0 and 2 moves nothing under a rigid translation (K x = 0 for the link part)."""
    data = pedestal_rotor()
    data["bearing"] = [*data["bearing"], {"node": 0, "link_node": 2, "kxx": 1e6, "kyy": 2e6, "kxy": 3e5,
                                          "cxx": 50.0}]
    with_link, without = (build_model(scene_from_dict(d)) for d in (data, pedestal_rotor()))
    dK, dC = (with_link.K - without.K).toarray(), (with_link.C - without.C).toarray()
    shift = np.zeros(with_link.n_dof)
    shift[0::6] = 1.0
    np.testing.assert_allclose(dK @ shift, 0.0, atol=1e-9)
    np.testing.assert_allclose(dC @ shift, 0.0, atol=1e-12)
    assert dK[0, 1] == 3e5 and dK[12, 1] == -3e5 and dK[0, 13] == -3e5 and dC[12, 12] == 50.0


@pytest.mark.parametrize("change, key", [
    (lambda d: d["bearing"].append({"node": 1, "link_node": 1, "kxx": 1.0}), "bearing[4].link_node"),
    (lambda d: d["bearing"][1].update(link_node=5), "bearing[].link_node"),
    (lambda d: d["bearing"].append({"node": 7, "kxx": 1.0}), "bearing[4].node"),
    (lambda d: d["bearing"][0].update(speeds=[0.0, 10.0], kxx_table=[1e6, 2e6]), "bearing[0].speeds"),
])
def test_bad_links_are_rejected(change, key):
    data = pedestal_rotor()
    change(data)
    with pytest.raises(InputError) as err:
        build_model(scene_from_dict(data))
    assert err.value.where == key


def test_support_stiffness_holds_the_shaft_bearings_and_leaves_the_pedestals_on_their_springs():
    """The critical-speed map replaces the bearings on shaft nodes (here the links); the pedestal supports stay."""
    model = build_model(scene_from_dict(pedestal_rotor()))
    free = (model.K - model.support_stiffness()).toarray()
    shaft_only = build_model(scene_from_dict(dict(pedestal_rotor(), bearing=[]))).K.toarray()
    np.testing.assert_allclose(free[:18, :18], shaft_only, rtol=0, atol=1e-9 * np.abs(shaft_only).max())
    assert free[18, 18] == K2 and free[24, 24] == K2 and not np.any(free[:18, 18:])


def test_rotor_example_on_pedestals_matches_ross():
    """ROSS 3.1 ``rotor_example()`` with its bearings linked (``n_link``) to 20 kg pedestals on their own bearings
    (studies/rotor/ross_pedestal.py): the 8 lowest lateral frequencies at 0 and 400 rad/s.  The pedestals' axial,
    tilt and torsion DOFs (decoupled from the shaft: the links are lateral only) are held far above the band."""
    import tomllib
    from pathlib import Path

    from cvtfem.modal import ModalProblem

    data_dir = Path(__file__).parents[1] / "data" / "ross"
    data = tomllib.loads((data_dir / "rotor_example.toml").read_text())
    held = dict(kzz=1e9, ktt=1e9, kphi=1e9, mass=20.0, Id=1e-3, Ip=1e-3)
    data["bearing"] = [{"node": 0, "link_node": 7, "kxx": 1e6, "kyy": 0.8e6},
                       {"node": 6, "link_node": 8, "kxx": 1e6, "kyy": 0.8e6},
                       {"node": 7, "kxx": 5e6, "kyy": 4e6, **held}, {"node": 8, "kxx": 5e6, "kyy": 4e6, **held}]
    model = build_model(scene_from_dict(data))
    ref = __import__("json").loads((data_dir / "pedestal.json").read_text())
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind)
    for key in ("modal_0", "modal_400"):
        modes = problem.solve(ref[key]["speed"], 12)
        lateral = np.array([w not in ("torsional", "axial") for w in modes.whirl])
        np.testing.assert_allclose(modes.wd[lateral][:8], ref[key]["wd"], rtol=1e-10)
