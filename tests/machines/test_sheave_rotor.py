"""Flexible sheaves in the rotor model (issue 20): Craig–Bampton sheave harmonics n = 0, 1 on the shaft nodes.

A shaft (10 elements) on two bearings carries two toroidal sheaves facing each other, as in a CVT pulley.
"""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from cvtfem.errors import InputError


def scene_text(flexibility: str = "reduced", modes: int = 6, cells: tuple[int, int] = (12, 2),
               E_sheave: float = 2.1e11, mirrored: bool = False) -> str:
    """The test rotor as TOML; ``mirrored`` turns it end for end (shaft reversed, sheaves facing the other way)."""
    lengths, diameters = [0.02] * 2 + [0.025] * 6 + [0.02] * 2, [0.035] * 2 + [0.045] * 6 + [0.035] * 2
    nodes, facings = (3, 7), ("+z", "-z")
    if mirrored:
        lengths, diameters, nodes, facings = lengths[::-1], diameters[::-1], (7, 3), ("-z", "+z")
    shafts = "".join(f'[[shaft]]\nlength = {a}\nouter_diameter = {d}\ninner_diameter = 0.012\nmaterial = "steel"\n'
                     for a, d in zip(lengths, diameters))
    disks = "".join(f'[[disk]]\nnode = {n}\ngeometry = "sheave"\nmaterial = "sheave"\ninner_diameter = 0.045\n'
                    f'outer_diameter = 0.18\nhub_diameter = 0.07\nhub_length = {h}\nrim_thickness = 0.008\n'
                    f'cone_angle = 0.192\nface = "toroidal"\ntorus_radius = 0.5\nfacing = "{f}"\n'
                    for n, f, h in zip(nodes, facings, (0.03, 0.045)))
    bearings = "".join(f"[[bearing]]\nnode = {n}\nkxx = 2e8\nkyy = 2e8\nkzz = 1e8\nktt = 1e4\nkphi = 1e4\n"
                       for n in (0, 10))
    return (f'[[material]]\nname = "steel"\nE = 2.1e11\nG = 8.1e10\nrho = 7850.0\n'
            f'[[material]]\nname = "sheave"\nE = {E_sheave}\nG = {E_sheave / 2.6}\nrho = 7850.0\n'
            f'{shafts}{disks}{bearings}[sheave]\nflexibility = "{flexibility}"\nmodes = {modes}\n'
            f'cells_radial = {cells[0]}\ncells_axial = {cells[1]}\n')


def build(tmp_path, **kw):  # noqa: ANN001, ANN201
    from cvtfem.machines.rotor import build_model
    from cvtfem.scene.loader import load_scene

    path = tmp_path / "rotor.toml"
    path.write_text(scene_text(**kw))
    return build_model(load_scene(path))


def frequencies(model, speed: float, count: int = 30) -> np.ndarray:  # noqa: ANN001
    """Damped natural frequencies (Hz) at ``speed`` (rad/s)."""
    from cvtfem.modal import ModalProblem

    modes = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind).solve(speed, count)
    return modes.wd / (2 * np.pi)


def test_beam_rotations_are_the_sheave_tilts():
    """The conventions the attachment relies on: a rigid rotation of the shaft about +y is ``u1 = beta z,
    theta2 = beta`` (and about +x ``u2 = -alpha z, theta1 = alpha``): the beam stiffness has it in its null space,
    not the opposite sign; the sheave's tilt coordinate moves the bore as the rotation about +y through the
    tilt centre (U_r = z - z_c, U_z = -r at theta = 0)."""
    from cvtfem.assembly import assemble
    from cvtfem.elements.sheave_reduction import craig_bampton
    from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection
    from cvtfem.machines.rotor import build_model
    from cvtfem.scene.loader import load_scene

    m = build_model(load_scene("cvt_sheave_shaft"))
    K = assemble(m.n_dof, [(m.beam.stiffness(0.0), m.beam.dofs)])
    z, nodes = m.z[:m.n_shaft_nodes], m.n_shaft_nodes
    scale = abs(K).max() * abs(z).max()
    for translation, rotation, slope in ((0, 4, 1.0), (1, 3, -1.0)):
        for sign, null in ((1.0, True), (-1.0, False)):
            q = np.zeros(m.n_dof)
            q[translation:6 * nodes:6], q[rotation:6 * nodes:6] = slope * z, sign
            assert (np.linalg.norm(K @ q) < 1e-9 * scale) == null
    section = SheaveSection(0.02, 0.03, 0.09, 0.02, 0.008, 0.19)
    model = HarmonicSheave(section, 1, "cos", 8, 1)
    red = craig_bampton(model, 0, tilt_centre=0.004)
    bore = model.bore_dofs()
    comp = np.empty(model.basis.N, int)
    for c, idx in enumerate(model.basis.split_indices()):
        comp[idx] = c
    r, zz = model.basis.doflocs[:, bore]
    tilt = red.basis[bore, red.index("tilt_y")]
    np.testing.assert_allclose(tilt[comp[bore] == 0], (zz - 0.004)[comp[bore] == 0], atol=1e-15)
    np.testing.assert_allclose(tilt[comp[bore] == 2], -r[comp[bore] == 2], atol=1e-15)


def test_fixed_frame_gyroscopic_of_the_sheave_holds_the_rigid_polar_inertia(tmp_path):
    """Two implementations: the rotor's rigid disk gyroscopic matrix (``Ip`` from Green's theorem on the section
    polygon) and the interface block of the flexible sheave's fixed-frame gyroscopic matrix (Coriolis coupling of
    the harmonic families, less ``2 n M J``, projected on the rigid bore motions), for a sheave facing +z and one
    facing -z: the tilt coupling is ``Ip`` with the same sign to 2e-5 (observed 1.03e-5: the rotor's 64 chords fall
    1e-5 short of the toroidal arc), the sideways
    translations are not coupled (the Coriolis and frame terms cancel), nor is the axial motion to the spin."""
    rigid, flexible = build(tmp_path, flexibility="rigid"), build(tmp_path)
    for node in (3, 7):
        dofs = 6 * node + np.arange(6)
        Gr, Gf = (m.G.toarray()[np.ix_(dofs, dofs)] for m in (rigid, flexible))
        beam = rigid.G.toarray()[np.ix_(dofs, dofs)] - rigid.disks.gyroscopic()[0 if node == 3 else 1]
        np.testing.assert_allclose(Gf - beam, Gr - beam, rtol=2e-5, atol=1e-10 * abs(Gr).max())
        assert abs(Gr[3, 4]) > 1e-3 and Gr[3, 4] * Gf[3, 4] > 0


def test_reduced_sheaves_match_full_sheaves_below_10_khz(tmp_path):
    """Two ways to the same rotor: 6 fixed-interface modes per harmonic against all of them (the unreduced
    harmonic models with a rigid bore), at 1000 rad/s: every frequency below 10 kHz to 0.5 % (it is 0.1 %), and
    the mirrored rotor (shaft end for end, sheaves facing the other way) has the same frequencies to 1e-9."""
    reduced = frequencies(build(tmp_path, cells=(8, 1)), 1000.0)
    full = frequencies(build(tmp_path, cells=(8, 1), flexibility="full"), 1000.0)
    band = full < 10e3
    assert band.sum() >= 18
    np.testing.assert_allclose(reduced[band], full[band], rtol=5e-3)
    mirrored = frequencies(build(tmp_path, cells=(8, 1), mirrored=True), 1000.0)
    np.testing.assert_allclose(mirrored, reduced, rtol=1e-9)


@pytest.mark.slow
def test_campbell_with_reduced_sheaves_matches_full_sheaves(tmp_path):
    """The acceptance of issue 20: the shaft-plus-sheaves Campbell diagram (0..1500 rad/s, forward and backward
    modes tracked) with reduced sheaves matches the one with full sheaves to 0.5 % below 10 kHz."""
    from cvtfem.modal import ModalProblem, campbell

    speeds = np.linspace(0.0, 1500.0, 4)
    curves = {}
    for flexibility in ("reduced", "full"):
        m = build(tmp_path, flexibility=flexibility)
        curves[flexibility] = campbell(ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind), speeds, 24).wd
    band = curves["full"] < 2 * np.pi * 10e3
    np.testing.assert_allclose(curves["reduced"][band], curves["full"][band], rtol=5e-3)


def test_a_stiff_sheave_tends_to_the_rigid_sheave(tmp_path):
    """The interface block of a reduced sheave is its rigid inertia, so as the sheave material stiffens the
    rotor's frequencies tend to those of the rigid-sheave rotor, the gap falling as 1/E (first-order
    perturbation): the log-log slope between 10 and 48 times steel is -1 within 0.15, and the gap is < 1.5 %."""
    rigid = frequencies(build(tmp_path, flexibility="rigid"), 1000.0, 12)
    gaps = [np.abs(frequencies(build(tmp_path, E_sheave=E), 1000.0, 12) / rigid - 1).max() for E in (2.1e12, 1e13)]
    slope = np.log(gaps[1] / gaps[0]) / np.log(1e13 / 2.1e12)
    assert abs(slope + 1) < 0.15 and gaps[1] < 0.015, (gaps, slope)


def test_strain_energy_share_of_the_sheaves(tmp_path):
    """`RotorModel.sheave_share`: Craig–Bampton leaves no stiffness between the nodes and the sheave modes, so
    the sheave's part of ``x^H K x`` is a clean split in [0, 1]; the sheave-rocking modes (n = 1) are found among
    the modes, and a sheave 48 times as stiff as steel stores less than 1 % in the 8 lowest modes (up to 2.3 kHz)."""
    from cvtfem.modal import ModalProblem

    for E, low, high in ((2.1e11, 0.0, 1.0), (1e13, 0.0, 0.01)):
        m = build(tmp_path, E_sheave=E)
        modes = ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind).solve(1000.0, 8 if E > 1e12 else 30)
        share, diameters = m.sheave_share(modes.shapes)
        assert np.all((share >= low - 1e-12) & (share <= high + 1e-12)), share
        if E < 1e12:
            assert np.any((share > 0.5) & (diameters == 1)) and np.any((share > 0.5) & (diameters == 0))
    rigid = build(tmp_path, flexibility="rigid")
    assert np.all(rigid.sheave_share(np.ones((rigid.n_dof, 3)))[0] == 0.0)


def test_rigid_sheaves_run_no_sheave_code():
    """``flexibility = "rigid"`` (the default) builds the rotor without importing the solid sheave modules."""
    code = ("import sys; from cvtfem.machines.rotor import build_model; from cvtfem.scene.loader import load_scene;"
            "m = build_model(load_scene('cvt_sheave_shaft')); assert m.extra_kinds == ();"
            "print(any(k.startswith('cvtfem.elements.sheave') or k == 'skfem' for k in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_flexible_sheaves_need_a_sheave_disk():
    from cvtfem.scene.loader import load_scene

    with pytest.raises(InputError, match="sheave.flexibility"):
        load_scene("friswell_5_9_1", {"sheave": {"flexibility": "reduced"}})


def test_reduced_fixed_frame_sheave_on_a_clamped_bore_sees_its_waves_shifted_by_omega():
    """The projected gyroscopic matrix on the sheave's own n = 1 modes (``C = Phi^T B P Phi + 2 M_r``), bore
    held: the two lowest fixed-frame frequencies at 6000 rpm are the Coriolis-coupled rotating-frame waves of
    the unreduced model shifted by ``-+ Omega / 2 pi`` to 1e-3; the ``Omega^2`` stiffness left out moves them by
    ``(n^2 - lambda) Omega^2 / 2 w`` (observed 1.7e-4)."""
    from cvtfem.elements.sheave_solid import HarmonicSheave
    from cvtfem.machines.sheave import reduced_harmonics, sheave_section
    from cvtfem.scene.loader import load_scene

    section = sheave_section(load_scene("cvt_sheave_shaft"), 0)
    reduced, gyro, _ = reduced_harmonics(section, 8, (12, 2), 0.0)
    red, omega = reduced[(1, "cos")], 6000 * np.pi / 30
    m = red.M.shape[0]
    own = np.r_[2:m, m + 2:2 * m]                               # the modes of the cos model and of its twin
    M, K = (np.kron(np.eye(2), X)[np.ix_(own, own)] for X in (red.M, red.K))
    n = len(own)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, omega * gyro[1][np.ix_(own, own)])]])
    lam = np.linalg.eigvals(A)
    fixed = np.sort(lam.imag[lam.imag > 0])[:2] / (2 * np.pi)
    axisym = HarmonicSheave(section, 0, "cos", 12, 2)
    f, sense = HarmonicSheave(section, 1, "cos", 12, 2).travelling_modes(
        omega, axisym.stress(axisym.centrifugal_displacement(omega)), 1)
    np.testing.assert_allclose(fixed, np.sort(f + sense * omega / (2 * np.pi)), rtol=1e-3)
