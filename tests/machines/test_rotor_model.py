"""Rotor time-domain model: the modal matrices, Friswell's whirl frequencies from its Jacobian, energy balance."""
import dataclasses

import numpy as np
import pytest

from cvtfem.assembly.model import Model
from cvtfem.machines import layout
from cvtfem.machines.rotor import build_model
from cvtfem.scene.loader import load_scene

RPM = np.pi / 30


@pytest.fixture(scope="module")
def friswell():
    return dataclasses.replace(build_model(load_scene("friswell_5_9_1")), speed=4000 * RPM)


def test_linearize_is_the_modal_matrices(friswell):
    lin = friswell.linearize(friswell.initial_state())
    assert isinstance(friswell, Model)
    assert lin.M is friswell.M and lin.C is friswell.C and lin.G is friswell.G and lin.K is friswell.K


def test_jacobian_eigenvalues_are_friswell_whirl_frequencies(friswell):
    """Friswell et al. example 5.9.1 at 4000 rpm (the values of tests/modal/test_friswell.py), from x' = J x."""
    lam = np.linalg.eigvals(friswell.jac(0.0, friswell.initial_state()).toarray())
    wd = np.sort(np.abs(lam.imag))
    for ref in (85.39, 87.80, 251.78, 294.71, 600.18, 650.41):
        assert np.min(np.abs(wd - ref)) <= 1e-3 * ref


def test_rhs_is_linear_in_the_state(friswell):
    x = np.random.default_rng(0).normal(size=friswell.size)
    assert np.allclose(friswell.rhs(0.0, x), friswell.jac(0.0, x) @ x, rtol=1e-10, atol=1e-10 * np.abs(x).max())


def test_energy_balance_with_damping_and_gyroscopics():
    """dE/dt = -(v C v) - (v K_a u): gyroscopic forces do no work."""
    m = dataclasses.replace(build_model(load_scene("cvt_sheave_shaft")), speed=300.0)
    x = np.random.default_rng(1).normal(size=m.size) * np.repeat([1e-7, 1e-3], m.n2)  # E not >> dE/dt (rounding)
    f = m.rhs(0.0, x)
    h = 1e-6                 # E is quadratic: the central difference is exact but for rounding
    dE = (m.energy(x + h * f) - m.energy(x - h * f)) / (2 * h)
    P = m.power(0.0, x)
    assert abs(dE + P["dissipated"] + P["circulatory"]) <= 1e-6 * max(abs(dE), P["dissipated"])


def test_outputs_match_layout():
    scene = load_scene("cvt_sheave_shaft")
    m = build_model(scene)
    out = m.outputs(0.0, np.random.default_rng(2).normal(size=m.size))
    specs = [o for part in layout(scene) for o in part.outputs]
    assert specs == list(m.output_specs) and list(out) == [s.name for s in specs]
    assert all(np.size(out[s.name]) == s.size for s in specs)
