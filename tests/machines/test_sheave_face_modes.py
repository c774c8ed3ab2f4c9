"""The contact face of flexible sheaves as the rotor's modal coordinates move it (issue 20: the sheave-face normal
velocity of the radiated-power figure): the face profiles against an independent eigen-solve, the panel map
against the integral of the face motion, and the ERP of the flexible sheaves' own modes."""
import numpy as np
import pytest

from cvtfem.analysis.spectrum import sheave_faces
from cvtfem.elements.sheave_solid import HarmonicSheave
from cvtfem.machines.rotor import build_model
from cvtfem.machines.sheave import sheave_section
from cvtfem.machines.sheave_face_modes import face_nodes
from cvtfem.modal.radiation import Face, annulus_panels, erp, rigid_annulus
from cvtfem.scene.loader import load_scene
from tests.machines.test_sheave_spin_rotor import plate_rotor_text


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    path = tmp_path_factory.mktemp("plate") / "plate_rotor.toml"
    path.write_text(plate_rotor_text(2).replace("cells_radial = 40", "cells_radial = 24"))
    scene = load_scene(str(path))
    return scene, build_model(scene)


def test_face_profile_is_the_clamped_plate_mode(plate):
    """The face profile of the first ``n = 2`` coordinate (``cos``) and of its twin is the bore-clamped plate's
    lowest ``n = 2`` mode from its own eigen-solve (unit modal mass, at the contact-face nodes), to 1e-6 of its
    peak; its twin turns with ``sin 2a``."""
    scene, model = plate
    face = model.sheave_faces[0]
    k = np.flatnonzero((face.n == 2) & ~face.sine)[0]
    twin = np.flatnonzero((face.n == 2) & face.sine)[0]
    ref_model = HarmonicSheave(sheave_section(scene, 0), 2, "cos", 24, 2)
    _, shapes = ref_model.modes(1)
    x = shapes[:, 0] / np.sqrt(shapes[:, 0] @ (ref_model.matrices[1] @ shapes[:, 0]))
    radii, z_dofs = face_nodes(ref_model)
    np.testing.assert_allclose(face.radii, radii)
    ref = x[z_dofs] * np.sign(x[z_dofs][-1] * face.uz[-1, k])
    assert np.abs(face.uz[:, k] - ref).max() < 1e-6 * np.abs(ref).max()
    np.testing.assert_array_equal(face.uz[:, twin], face.uz[:, k])
    a = np.array([0.0, np.pi / 4])
    w = face.rows(model.n_dof, np.full(2, face.radii[-1]), a)
    assert w[0, face.dofs[twin]] == 0.0 and w[1, face.dofs[k]] == pytest.approx(0.0, abs=1e-12 * abs(ref[-1]))


def test_panel_erp_of_a_wave_converges_to_the_face_integral(plate):
    """ERP of a unit ``n = 2`` coordinate vibrating at 1 kHz on one face: the panel sum tends to
    ``rho c w^2 / 2 pi int U_z(r)^2 r dr`` (the ``cos^2 2a`` mean; the profile integrated finely), the error falling
    with the panel rings (8 -> 32: observed 0.35 % -> 0.022 %, second order)."""
    scene, model = plate
    face = model.sheave_faces[0]
    k = np.flatnonzero((face.n == 2) & ~face.sine)[0]
    d = scene.disk[0]
    rr = np.linspace(d.hub_diameter / 2, d.outer_diameter / 2, 20001)
    uz = np.interp(rr, face.radii, face.uz[:, k])
    omega = 2 * np.pi * 1e3
    exact = 0.5 * 1.204 * 343.2 * omega ** 2 * np.pi * np.sum(0.5 * (uz[1:] ** 2 * rr[1:] + uz[:-1] ** 2 * rr[:-1])
                                                              * np.diff(rr))
    q = np.zeros(model.n_dof)
    q[face.dofs[k]] = 1.0
    errors = []
    for rings in (8, 32):
        r, a, area = annulus_panels(d.hub_diameter / 2, d.outer_diameter / 2, rings, 16)
        errors.append(abs(erp(Face(area, face.rows(model.n_dof, r, a)), q, [omega])[0] / exact - 1))
    assert errors[1] < 0.005 and errors[0] / errors[1] > 8


def test_flexible_sheaves_radiate_their_own_modes(plate):
    """The spectrum's sheave faces: a rigid motion of the sheave node radiates as the rigid annulus (the own modes
    add nothing to it), and an ``n = 0`` (umbrella) coordinate, which leaves the node still, radiates from both
    faces."""
    scene, model = plate
    faces = sheave_faces(scene, model)
    d = scene.disk[0]
    node = 6 * int(model.disks.nodes[0])
    rigid = rigid_annulus(model.n_dof, (node + 2, node + 3, node + 4), d.hub_diameter / 2, d.outer_diameter / 2)
    q = np.zeros(model.n_dof)
    q[node + 2], q[node + 4] = 1e-6, 2e-5
    np.testing.assert_allclose(erp(faces, q, [1e3]), 2 * erp(rigid, q, [1e3]), rtol=1e-12)
    umbrella = np.zeros(model.n_dof)
    face = model.sheave_faces[0]
    umbrella[face.dofs[np.flatnonzero(face.n == 0)[0]]] = 1.0
    assert erp(faces, umbrella, [1e3])[0] > 0.0 and erp(rigid, umbrella, [1e3])[0] == 0.0
