"""The flexible faces of the band-6+2n models condensed onto the arc functions and tabulated in phi
(:mod:`cvtfem.elements.band.face_table`) against the exact face systems ``A = I + c' K_f D`` solved at every call."""
import dataclasses

import numpy as np
import pytest

from cvtfem.elements.band.face_table import face_table
from cvtfem.machines.cvt import band_model
from cvtfem.scene.loader import load_scene
from tests.band.test_compressible_kernel import _random_states

CHEAP = {"sheave": {"harmonics": 10, "cells_radial": 12, "cells_axial": 1}}     # physics unchanged, ~1 s to build


@pytest.fixture(scope="module")
def models():
    """The band-6+2n+8 model on flexible faces with its table, and the same with the exact face systems."""
    table = band_model(load_scene("band-6+2n-flexible", {**CHEAP, "cvt": {"model": "band-6+2n+8"}}))
    return table, dataclasses.replace(table, face_intervals=0)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_table_reproduces_the_exact_faces(models, backend):
    """Accelerations, normal forces, band-edge strain and powers from the table equal the exact face systems' within
    1e-8 relative (observed 1e-9 at the default 256 intervals) at random states of 6+2n+8; the elastic energy within
    1e-9 (observed 1.4e-10: the table holds ``dK`` to ~1e-9 of its size, and the faces' share is a third of it)."""
    if backend == "numba":
        pytest.importorskip("numba")
    table, exact = (dataclasses.replace(m, use_numba=backend == "numba") for m in models)
    for q, v, F, M in _random_states(exact, np.random.default_rng(3), 3):
        a1, i1 = table.accel(q, v, F, M)
        a0, i0 = exact.accel(q, v, F, M)
        assert np.abs(a1 - a0).max() <= 1e-8 * np.abs(a0).max()
        for key in ("N", "eps", "dissipation"):
            ref = np.asarray(i0[key])
            assert np.abs(np.asarray(i1[key]) - ref).max() <= 1e-8 * np.abs(ref).max(), key
        assert table.energies(q, v)[1] == pytest.approx(exact.energies(q, v)[1], rel=1e-9)


def test_condensed_strain_is_the_face_systems_solution(models):
    """The exact condensed strain ``eps_r + dG x~`` (numpy, no table) is ``A^-1 eps_r``, the definition of the
    quasi-static faces, within 10 rounding units of ``z0`` (the strain ``z - z0(r) + ...`` keeps ~5 of z0's 16 digits
    on the toroidal sheaves, |z0| ~ 1.5 m; observed 3e-16 m)."""
    exact = dataclasses.replace(models[1], use_numba=False)
    for q, v, F, M in _random_states(exact, np.random.default_rng(4), 2):
        g = exact.arcs(q[0])
        eps_r = exact.strain(q, g)
        direct = np.linalg.solve(exact.face_systems(g), eps_r[..., None])[..., 0]
        eps = exact.accel(q, v, F, M)[1]["eps"]
        assert np.abs(eps - direct).max() <= 10 * np.spacing(np.abs(g["z0"]).max())


def test_hermite_table_converges_at_fourth_order(models):
    """Doubling the grid (64 -> 128 intervals) divides the largest error of the tabulated ``dG, dK`` over 60 random
    angles by 2^4 (values; observed 2^4.2) and of their phi-derivatives by 2^3 (observed 2^2.9)."""
    exact = models[1]
    phis = np.random.default_rng(7).uniform(-0.25, 0.25, 60)
    ref = [exact.exact_face_terms(phi) for phi in phis]
    errors = []
    for intervals in (64, 128):
        tab = face_table(exact, intervals)
        errors.append([max(np.abs(tab.at(phi)[i] - r[i]).max() / np.abs(r[i]).max() for phi, r in zip(phis, ref))
                       for i in (0, 1)])
    value_order, slope_order = np.log2(np.array(errors[0]) / np.array(errors[1]))
    assert 3.5 < value_order < 4.5
    assert 2.5 < slope_order < 3.5


def test_off_the_table_the_exact_faces_answer(models):
    """Beyond the grid (contact radius past the faces' fitted range) both backends fall back on the exact systems."""
    table, exact = models
    grid = table._c["table"]
    q, v, F, M = next(_random_states(exact, np.random.default_rng(9), 1))
    q = exact.static_state(grid.hi + 0.02, F)
    assert not grid.covers(q[0])
    for use_numba in (True, False):
        a1 = dataclasses.replace(table, use_numba=use_numba).accel(q, v, F, M)[0]
        a0 = dataclasses.replace(exact, use_numba=use_numba).accel(q, v, F, M)[0]
        np.testing.assert_array_equal(a1, a0)
