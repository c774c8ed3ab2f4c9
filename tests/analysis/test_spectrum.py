"""Noise spectra of the CVT sheave shaft: pin-entry lines, torque ripple, ERP; modal sweep against direct solves."""
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.analysis.spectrum import (PinEntry, Ripple, UserLine, pin_entry_force, read_user_lines, scene_spectrum,
                                      sheave_faces)
from cvtfem.elements.link_pattern import link_lengths
from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.modal.forced import OutputMap, frf_direct
from cvtfem.modal.radiation import C_AIR, RHO_AIR
from cvtfem.scene.loader import load_scene

N = 84
SPEEDS = np.linspace(0.0, 6000.0, 25) * np.pi / 30


@pytest.fixture(scope="module")
def scene():
    return load_scene("cvt_sheave_shaft")


@pytest.fixture(scope="module")
def uniform(scene):
    pin = PinEntry(np.full(N, 0.009), 0.06, 1e-3, 0.3, 2)
    return scene_spectrum(scene, SPEEDS, 4, pin=pin, ripples=[Ripple(4, 2.0, 5.0)], n_freqs=20, n_modes=12)


@pytest.fixture(scope="module")
def randomised(scene):
    pin = PinEntry(link_lengths(N, 0.008, 0.010, 0.5, np.random.default_rng(7)), 0.06, 1e-3, 0.3, 1)
    return pin, scene_spectrum(scene, SPEEDS, 4, pin=pin, n_freqs=20, n_modes=12)


def test_uniform_chain_excites_only_multiples_of_f_link(uniform):
    """Lines k = 1 .. 2N of the chain order: only k = N and 2N (f_link, 2 f_link) move the shaft or radiate."""
    pin_lines = uniform.line_amplitude[1:, :2 * N]
    on = (np.arange(1, 2 * N + 1) % N) == 0
    assert pin_lines[:, on].min() > 0
    assert pin_lines[:, ~on].max() < 1e-11 * pin_lines[:, on].max()
    assert uniform.line_erp[1:, :2 * N][:, ~on].max() < 1e-22 * uniform.line_erp[1:, :2 * N][:, on].max()


def test_torque_ripple_moves_only_the_torsion_block(uniform):
    """The ripple line (last) twists the shaft: no lateral or axial motion at the node and no face ERP, exactly
    (independent DOF blocks are reduced and solved apart)."""
    assert uniform.line_labels[-1].startswith("ripple 2x")
    assert np.all(uniform.line_amplitude[:, -1] == 0.0) and np.all(uniform.line_erp[:, -1] == 0.0)
    assert np.allclose(uniform.line_freqs[:, -1], 2 * SPEEDS)


def test_lines_and_erp_against_direct_solves(scene, randomised):
    """At two speeds between the basis speeds (ends and middle of the sweep) every pin-entry line's response at the
    node and its ERP equal a direct sparse solve with the same force, the ERP from the closed form of rigid faces
    (two per sheave, hub to rim), to 1e-5 (measured 6e-7 on the amplitudes; the issue asks 1e-3)."""
    pin, res = randomised
    model = build_model(scene)
    n = model.n_dof
    f = pin_entry_force(scene, model, pin)
    node = [6 * 4, 6 * 4 + 1, 6 * 4 + 2]
    sheave_dofs = [6 * int(model.disks.nodes[i]) + np.array([2, 3, 4]) for i in range(2)]
    rows = np.concatenate([node] + sheave_dofs)
    out = OutputMap(sp.csr_matrix((np.ones(len(rows)), (np.arange(len(rows)), rows)), shape=(len(rows), n)),
                    sp.csr_matrix((len(rows), n)), tuple(map(str, rows)))
    from cvtfem.modal.excitation import pin_entry_lines

    _, _, amp = pin_entry_lines(pin.link_lengths, pin.radius, pin.impulse, pin.n_link_harmonics)
    for i in (5, 17):
        s = SPEEDS[i]
        w = res.line_freqs[i]
        y = frf_direct(model.M, model.K, model.C, model.G, f, out, w, s)[..., 0] * (amp * s)[:, None]
        assert np.allclose(res.line_amplitude[i], np.linalg.norm(y[:, :3], axis=1), rtol=1e-5, atol=0)
        power = 0.0
        for j, d in enumerate(scene.disk):
            ri, ro = d.hub_diameter / 2, d.outer_diameter / 2
            u3, t1, t2 = y[:, 3 + 3 * j], y[:, 4 + 3 * j], y[:, 5 + 3 * j]
            power = power + 2 * 0.5 * RHO_AIR * C_AIR * w**2 * (
                np.pi * (ro**2 - ri**2) * abs(u3) ** 2 + np.pi * (ro**4 - ri**4) / 4 * (abs(t1) ** 2 + abs(t2) ** 2))
        assert np.allclose(res.line_erp[i], power, rtol=1e-5, atol=0)
        assert res.erp_db[i] == pytest.approx(10 * np.log10(power.sum() / 1e-12), abs=1e-4)


def test_randomised_chain_spreads_the_link_line(uniform, randomised):
    """Same chain length, pin count and force direction: the randomised chain's f_link line moves the node by
    |S_N| / N of the uniform chain's (the pattern's own spectrum), and its sidebands move the shaft too."""
    from cvtfem.modal.excitation import pattern_spectrum

    pin, res = randomised
    ratio = abs(pattern_spectrum(pin.link_lengths, [N])[0]) / N
    assert ratio < 0.7
    assert np.allclose(res.line_amplitude[1:, N - 1], ratio * uniform.line_amplitude[1:, N - 1], rtol=1e-6)
    assert res.line_amplitude[1:, :N - 1].max() > 0.1 * res.line_amplitude[1:, N - 1].max()


def test_a_weighted_erp_lies_within_the_weights_of_its_lines(randomised):
    """sum P_l 10^(A_l / 10) lies between min and max of 10^(A_l / 10) times sum P_l."""
    from cvtfem.modal.excitation import a_weighting_db

    _, res = randomised
    A = a_weighting_db(res.line_freqs[1:] / (2 * np.pi))
    gap = res.erp_a_db[1:] - res.erp_db[1:]
    assert np.all(gap >= A.min(axis=1) - 1e-9) and np.all(gap <= A.max(axis=1) + 1e-9)
    assert gap[0] < -5 and abs(gap[-1]) < 2  # 250 rpm: lines near 175 Hz; 6000 rpm: near 4 kHz


def test_bad_sources(scene, tmp_path):
    with pytest.raises(InputError, match="must lie on the sheave face"):
        scene_spectrum(scene, SPEEDS, 4, pin=PinEntry(np.full(N, 0.009), 0.5))
    with pytest.raises(InputError, match="sheaves"):
        scene_spectrum(load_scene("friswell_5_9_1"), SPEEDS, 2, pin=PinEntry(np.full(N, 0.009), 0.06))
    with pytest.raises(InputError, match="--ripple"):
        scene_spectrum(scene, SPEEDS, 4, ripples=[Ripple(99, 2.0, 1.0)])
    with pytest.raises(InputError, match="--orders"):
        scene_spectrum(scene, SPEEDS, 4)
    bad = tmp_path / "bad.csv"
    bad.write_text("node,dof,order\n1,u1,2\n")
    with pytest.raises(InputError, match="header"):
        read_user_lines(str(bad))
    bad.write_text("node,dof,order,freq_hz,amplitude,phase_deg\n1,u9,2,0,1,0\n")
    with pytest.raises(InputError, match="dof"):
        read_user_lines(str(bad))
    good = tmp_path / "good.csv"
    good.write_text("node,dof,order,freq_hz,amplitude,phase_deg\n4,u3,0,1000,10,30\n")
    assert read_user_lines(str(good)) == [UserLine(4, "u3", 0.0, 1000.0, 10.0, np.radians(30.0))]


def test_user_line_at_fixed_frequency_against_direct(scene, tmp_path):
    """A 10 N axial force at 1 kHz on the fixed sheave: the same response at every speed but for the gyroscopic
    coupling, equal to a direct solve at 0 and 6000 rpm to 1e-3."""
    model = build_model(scene)
    res = scene_spectrum(scene, SPEEDS, 4, user=[UserLine(4, "u3", 0.0, 1000.0, 10.0, 0.0)], n_freqs=20)
    f = np.zeros(model.n_dof)
    f[6 * 4 + 2] = 10.0
    out = OutputMap(sp.csr_matrix(([1.0, 1.0, 1.0], ([0, 1, 2], [24, 25, 26])), shape=(3, model.n_dof)),
                    sp.csr_matrix((3, model.n_dof)), ("u1", "u2", "u3"))
    for i in (0, -1):
        y = frf_direct(model.M, model.K, model.C, model.G, f, out, [2 * np.pi * 1000.0], SPEEDS[i])[0, :, 0]
        assert res.line_amplitude[i, 0] == pytest.approx(np.linalg.norm(y), rel=1e-3)
    assert sheave_faces(scene, model).area.sum() == pytest.approx(
        4 * np.pi * ((0.09**2) - (0.07 / 2) ** 2 / 2 - (0.075 / 2) ** 2 / 2), rel=1e-12)


def test_pin_entry_force_is_the_face_normal_impulse_and_its_moment(scene):
    """On each sheave: F = -(sin(alpha) e_r + facing cos(alpha) e3) at p = R e_r(angle), moment p x F (np.cross);
    the two sheaves face each other, so the axial forces cancel and the chain pushes them apart."""
    model = build_model(scene)
    pin = PinEntry(np.full(N, 0.009), 0.06, 1e-3, 2.2)
    f = pin_entry_force(scene, model, pin)
    er = np.array([np.cos(pin.angle), np.sin(pin.angle), 0.0])
    axial = []
    for i, d in enumerate(scene.disk):
        q = 6 * int(model.disks.nodes[i])
        facing = 1.0 if d.facing == "+z" else -1.0
        F = -(np.sin(d.cone_angle) * er + facing * np.cos(d.cone_angle) * np.array([0.0, 0.0, 1.0]))
        Mo = np.cross(pin.radius * er, F)
        assert np.allclose(f[q: q + 6], np.concatenate([F, Mo]), rtol=0, atol=1e-15)
        axial.append(F[2])
    assert axial[0] < 0 < axial[1] and abs(sum(axial)) < 1e-15  # fixed sheave faces +z, movable -z
