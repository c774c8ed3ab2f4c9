"""Spinning flexible sheaves inside the rotor model (issue 20): the Omega^2 stiffness (prestress, spin softening, the
turning of the waves) of the reduced harmonics in ``ModalProblem`` through the rotor's speed terms, and the waves of
n >= 2 nodal diameters solved with the shaft, labelled forward/backward, the backward one standing still at the
closed-form critical speed of the clamped-free annular plate."""
import numpy as np
import pytest

from cvtfem.machines.rotor import build_model
from cvtfem.machines.sheave import reduced_harmonics
from cvtfem.modal import ModalProblem
from cvtfem.scene.loader import load_scene
from tests.elements.test_sheave_solid import PLATE, SHEAVE, _plate_rigidity, _southwell, kirchhoff_clamped_free


def plate_rotor_text(model_diameters: int = 3) -> str:
    """A 0.2 m steel shaft on two bearings carrying the annular plate ``PLATE`` (2 mm, 40 / 200 mm, flat face, no
    hub sleeve) as a reduced sheave at its middle node."""
    return ('[[material]]\nname = "steel"\nE = 2.1e11\nG = 8.076923076923077e10\nrho = 7850.0\n'
            + '[[shaft]]\nlength = 0.05\nouter_diameter = 0.04\nmaterial = "steel"\nrepeat = 4\n'
            + '[[disk]]\nnode = 2\ngeometry = "sheave"\nmaterial = "steel"\ninner_diameter = 0.04\n'
              'outer_diameter = 0.2\nhub_diameter = 0.041\nhub_length = 0.0\nrim_thickness = 0.002\ncone_angle = 0.0\n'
            + ''.join(f'[[bearing]]\nnode = {n}\nkxx = 1e8\nkyy = 1e8\nkzz = 1e8\nktt = 1e4\nkphi = 1e4\n'
                      for n in (0, 4))
            + f'[sheave]\nflexibility = "reduced"\nmodes = 4\ncells_radial = 40\ncells_axial = 2\n'
              f'model_diameters = {model_diameters}\n')


@pytest.fixture(scope="module")
def plate_rotor(tmp_path_factory):
    path = tmp_path_factory.mktemp("plate") / "plate_rotor.toml"
    path.write_text(plate_rotor_text())
    model = build_model(load_scene(str(path)))
    return model, ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, speed_terms=model.speed_terms)


def _waves(model, problem, speed, n):
    """``(Hz, whirl)`` of the rotor's modes at ``speed`` that store most of their strain energy in the sheave's
    waves of ``n`` nodal diameters, ascending."""
    modes = problem.solve(speed, 30)
    share, diameters = model.sheave_share(modes.shapes)
    return [(modes.wd[i] / (2 * np.pi), modes.whirl[i]) for i in range(len(modes.wd))
            if share[i] > 0.5 and diameters[i] == n]


def _closed_form(n):
    """Kirchhoff clamped-free ``w_0`` (rad/s) and Southwell ``lambda_n`` of ``PLATE``, critical speed (rad/s)."""
    k = kirchhoff_clamped_free(n, PLATE.bore_radius, PLATE.outer_radius, PLATE.nu, 1)[0] / PLATE.outer_radius
    w0 = k * k * np.sqrt(_plate_rigidity(PLATE) / (PLATE.rho * PLATE.rim_thickness))
    lam = _southwell(n, PLATE)
    return w0, lam, w0 / np.sqrt(n * n - lam)


@pytest.mark.parametrize("n", [2, 3])
def test_backward_wave_stands_still_at_the_closed_form_critical_speed(plate_rotor, n):
    """In the rotor's modes, the lowest wave of ``n`` diameters runs backward below the critical speed
    ``Omega_c = w_0 / sqrt(n^2 - lambda_n)`` (1549 and 1746 rad/s) and forward above it; its signed fixed-frame
    frequency, interpolated between 0.97 and 1.03 Omega_c, crosses zero within 1 % of the closed form (observed
    -0.27 % and -0.30 %, the FE plate's w_0 being 0.27 % below Kirchhoff's)."""
    model, problem = plate_rotor
    _, _, critical = _closed_form(n)
    below, above = (_waves(model, problem, f * critical, n)[0] for f in (0.97, 1.03))
    assert below[1] == "backward" and above[1] == "forward"
    assert max(below[0], above[0]) < 0.05 * n * critical / (2 * np.pi)       # near zero against the shift n Omega
    zero = 0.97 + 0.06 * below[0] / (below[0] + above[0])
    assert zero * critical == pytest.approx(critical, rel=0.01)


def test_waves_split_forward_and_backward_as_the_closed_form(plate_rotor):
    """At rest the two waves of n = 2 share one frequency (the Kirchhoff plate's to 1 %); at half the critical speed
    they split into a forward wave at ``sqrt(w_0^2 + lambda Omega^2) + n Omega`` and a backward one at ``... - n
    Omega`` (closed form to 1 % of the forward frequency, observed 0.3 %), labelled so by their orbits."""
    model, problem = plate_rotor
    w0, lam, critical = _closed_form(2)
    rest = _waves(model, problem, 0.0, 2)[:2]
    assert rest[0][0] == pytest.approx(rest[1][0], rel=1e-9)
    assert rest[0][0] == pytest.approx(w0 / (2 * np.pi), rel=0.01)
    speed = 0.5 * critical
    spun = np.sqrt(w0 ** 2 + lam * speed ** 2)
    (f_bw, s_bw), (f_fw, s_fw) = _waves(model, problem, speed, 2)[:2]
    assert (s_bw, s_fw) == ("backward", "forward")
    assert f_fw == pytest.approx((spun + 2 * speed) / (2 * np.pi), rel=0.01)
    assert f_bw == pytest.approx((spun - 2 * speed) / (2 * np.pi), abs=0.01 * f_fw)


def test_spin_stiffness_vanishes_on_rigid_motions():
    """The fixed-frame stiffness per Omega^2 of the n = 0 and n = 1 harmonics is (nearly) zero on the rigid bore
    motions (axial, spin, sideways, tilt): a rigid spinning body has no Omega^2 stiffness in the fixed frame (for
    the spin and tilt rows through the virial of the centrifugal prestress, ``int (s_rr + s_tt) = int rho Omega^2
    r^2``); the rigid rows stay below 1e-3 of the own modes' (observed 5e-6 plate, 1e-4 sheave), while the own
    modes stiffen."""
    for section in (PLATE, SHEAVE):
        reduced, _, spin = reduced_harmonics(section, 4, (24, 2), 0.0)
        for n, keys in ((0, ((0, "cos"), (0, "sin"))), (1, ((1, "cos"), (1, "cos")))):
            first = reduced[keys[0]].M.shape[0]
            rigid = [0, first] if n == 0 else [0, 1, first, first + 1]
            own = np.setdiff1d(np.arange(spin[n].shape[0]), rigid)
            scale = np.abs(spin[n][np.ix_(own, own)]).max()
            assert np.abs(spin[n][rigid]).max() < 1e-3 * scale
            assert np.all(np.diag(spin[n])[own][:2] > 0.0)


def test_model_diameters_default_keeps_the_rotor_as_before(tmp_path):
    """Without ``model_diameters`` only n = 0, 1 enter the rotor (the layout's size), and the rotor's own-wave lines
    start above them."""
    from cvtfem.commands.sheave import own_waves
    from cvtfem.machines.rotor import layout

    path = tmp_path / "plate_rotor.toml"
    path.write_text(plate_rotor_text(1).replace("modes = 4", "modes = 2").replace("cells_radial = 40",
                                                                                 "cells_radial = 12"))
    scene = load_scene(str(path))
    model = build_model(scene)
    assert set(model.extra_diameters) == {0, 1}
    assert len(model.extra_kinds) == next(p.n2 for p in layout(scene) if p.name == "sheaves")
    labels = [label for label, _ in own_waves(scene, np.array([0.0, 100.0]))]
    assert labels[0] == "disk 0 sheave n=2 fw"
    three = load_scene(str(path), {"sheave": {"model_diameters": 3}})
    assert len(build_model(three).extra_kinds) == next(p.n2 for p in layout(three) if p.name == "sheaves")
    assert all("n=2" not in label and "n=3" not in label for label, _ in own_waves(three, np.array([0.0, 100.0])))


def test_campbell_tracks_the_backward_wave_through_its_critical_speed(plate_rotor):
    """The rotor's Campbell diagram from 0.85 to 1.15 of the closed-form critical speed of n = 2: MAC tracking follows
    the backward wave through zero frequency (it comes back as the conjugate shape, now running forward) without a
    jump; its tracked frequency, signed by the whirl, crosses zero within 1 % of the closed form (observed -0.29 %),
    and there is no 1x crossing (the wave stays far below the line there, none on a jump)."""
    from cvtfem.modal import campbell

    model, problem = plate_rotor
    _, _, critical = _closed_form(2)
    speeds = np.linspace(0.85, 1.15, 7) * critical
    result = campbell(problem, speeds, 8)
    assert not result.jumps
    j = int(np.argmin(result.wd.min(axis=0)))
    sign = np.where(result.whirl[:, j] == "backward", 1.0, -1.0)
    assert list(sign[:3]) == [1.0] * 3 and list(sign[-3:]) == [-1.0] * 3
    signed = sign * result.wd[:, j]
    i = int(np.flatnonzero(signed[:-1] * signed[1:] < 0)[0])
    zero = speeds[i] + signed[i] / (signed[i] - signed[i + 1]) * (speeds[i + 1] - speeds[i])
    assert zero == pytest.approx(critical, rel=0.01)
    assert not result.crossings
