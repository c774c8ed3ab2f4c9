"""Modal superposition on one basis for a speed sweep; blocks with a rigid-body mode; the batched modal sum."""
import numpy as np
import pytest
import scipy.sparse as sp

from cvtfem.errors import InputError, NumericalError
from cvtfem.machines.rotor import build_model
from cvtfem.modal.forced import ModalBasis, OutputMap, displacement, frf_direct
from cvtfem.scene.loader import load_scene


@pytest.fixture(scope="module")
def sheave():
    return build_model(load_scene("cvt_sheave_shaft"))


def _rel(H, Hd):
    """Largest error per line relative to the line's largest output (outputs near zero do not count alone)."""
    return np.max(np.abs(H - Hd).max(axis=1) / np.abs(Hd).max(axis=1))


def test_sweep_basis_against_direct_between_its_speeds(sheave):
    """x force at the fixed sheave, x and y there: the basis from the right and left modes at 0, 3000 and 6000 rpm
    matches direct solves at 1000, 2200 and 5100 rpm from 50 Hz up to 0.9 x its highest mode to 1e-4 (measured
    1.6e-5), no worse than 3x the per-speed complex basis with as many modes (2.6e-5 .. 2.9e-5: both are limited by
    the neglected modes, not by the speed), also at a basis speed."""
    m = sheave
    n = m.n_dof
    f = np.zeros(n)
    f[6 * 4] = 1.0
    out = displacement([6 * 4, 6 * 4 + 1], n)
    top = 6000 * np.pi / 30
    basis = ModalBasis(m.M, m.K, m.C, m.G, f, 10, modes="sweep", basis_speeds=(0.0, top / 2, top))
    cplx = ModalBasis(m.M, m.K, m.C, m.G, f, 10, modes="complex")
    w = np.linspace(2 * np.pi * 50, 0.9 * basis.wmax(), 150)
    for rpm in (1000.0, 2200.0, 5100.0):
        s = rpm * np.pi / 30
        Hd = frf_direct(m.M, m.K, m.C, m.G, f, out, w, s)
        err = _rel(basis.frf(out, w, s), Hd)
        assert err < 1e-4 and err < 3 * _rel(cplx.frf(out, w, s), Hd), rpm
    Hd = frf_direct(m.M, m.K, m.C, m.G, f, out, w, top)
    assert _rel(basis.frf(out, w, top), Hd) < 3 * _rel(cplx.frf(out, w, top), Hd)


def test_rigid_body_torsion_block_against_direct(sheave):
    """A torque on the free-spinning shaft (the torsion block has a rigid-body mode: defective reduced state
    matrix): the batched reduced solves give the twist at both sheaves as the direct solves to 1e-4 (the rigid
    part -T / (J w^2) included; the rest is the neglected torsion modes), and the torque moves no lateral or axial DOF at all."""
    m = sheave
    n = m.n_dof
    f = np.zeros(n)
    f[6 * 4 + 5] = 3.0
    phi = displacement([6 * 4 + 5, 6 * int(m.disks.nodes[1]) + 5, 6 * 4, 6 * 4 + 2], n)
    basis = ModalBasis(m.M, m.K, m.C, m.G, f, 6, modes="sweep", basis_speeds=(0.0, 300.0))
    w = np.linspace(2 * np.pi * 20, 2 * np.pi * 3000, 40)
    H = basis.frf(phi, w, 200.0)[..., 0]
    Hd = frf_direct(m.M, m.K, m.C, m.G, f, phi, w, 200.0)[..., 0]
    assert _rel(H[:, :2], Hd[:, :2]) < 1e-4  # the neglected torsion modes
    assert np.all(H[:, 2:] == 0)
    J = m.M.diagonal()[5::6].sum()  # rigid spin inertia: the twist far below the first torsion mode
    assert H[0, 0] == pytest.approx(-3.0 / (J * w[0] ** 2), rel=2e-2)
    with pytest.raises(NumericalError, match="static"):
        basis.frf(phi, [0.0], 200.0)


def test_sweep_needs_basis_speeds(sheave):
    m = sheave
    f = np.zeros(m.n_dof)
    f[24] = 1.0
    with pytest.raises(InputError, match="basis_speeds"):
        ModalBasis(m.M, m.K, m.C, m.G, f, 4, modes="sweep")
    with pytest.raises(InputError, match="modes"):
        ModalBasis(m.M, m.K, m.C, m.G, f, 4, modes="left")


def test_columns_and_velocity_outputs(sheave):
    """``columns`` picks inputs; a velocity output is i w times the displacement (V part of the batched sum)."""
    m = sheave
    n = m.n_dof
    F = np.zeros((n, 2))
    F[24, 0], F[26, 1] = 1.0, 1.0
    basis = ModalBasis(m.M, m.K, m.C, m.G, F, 8, modes="sweep", basis_speeds=(0.0, 600.0))
    w = np.linspace(100.0, 8000.0, 30)
    both = basis.frf(displacement([24, 26], n), w, 300.0)
    assert np.allclose(basis.frf(displacement([24, 26], n), w, 300.0, columns=[1])[..., 0], both[..., 1], rtol=1e-13,
                       atol=0)
    vel = OutputMap(sp.csr_matrix((2, n)), displacement([24, 26], n).D, ("v1", "v3"))
    assert np.allclose(basis.frf(vel, w, 300.0), 1j * w[:, None, None] * both, rtol=1e-13, atol=0)
