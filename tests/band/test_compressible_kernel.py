"""Compiled 6+2n / 6+2n+8 right-hand side against its numpy twin; the loop's chain-rule Jacobian."""
import dataclasses

import numpy as np
import pytest

from cvtfem.elements.band import compressible_kernel as ker
from cvtfem.elements.band.geometry import admissible_phi, radii
from cvtfem.machines.cvt import band_model, closed_loop
from cvtfem.scene.loader import load_scene

pytest.importorskip("numba")

CASES = [(name, profile, law) for name in ("band-6+2n", "band-6+2n+8") for profile in ("toroidal", "conical")
         for law in ("tanh", "linear-saturated")] + [("band-6+2n+8", "toroidal", "smoothed")]


def _scene(name, profile="toroidal", law="tanh"):
    return load_scene(name, {"cvt": {"geometry": {"sheave_profile": profile}, "friction": {"law": law}}})


def _random_states(m, rng, count):
    """Admissible random states: span angle inside 60 % of the admissible range, elastic coordinates
    around the static state (band compressed, partly lifted off), slips around v0 on both arcs."""
    lo, hi = admissible_phi(m.p.length, m.p.L)
    for _ in range(count):
        phi = rng.uniform(0.6 * lo, 0.6 * hi)
        F = rng.uniform(5e3, 4e4, 2)
        q = m.static_state(phi, F)
        el = m._elastic_index()
        q[el] += 1e-5 * rng.standard_normal(el.size)  # m (rad for tilts): strains of the static order
        q[1:4] = rng.uniform(-10, 10, 3)
        r = radii(phi, m.p.length, m.p.L)[0]
        v = 1e-3 * rng.standard_normal(m.n2)
        v[0] = 0.1 * rng.normal()
        v[2] = 366 * (1 + 0.01 * rng.normal())
        v[1] = r[0] * v[2] + 0.02 * rng.normal()
        v[3] = (v[1] + 0.02 * rng.normal()) / r[1]
        yield q, v, F, np.array([200.0, -480.0]) * rng.uniform(0.5, 1.5)


def _rounding_scale(m, q, v, F, M):
    """How far two correct evaluations may differ: the change of the numpy twin's outputs when

    - the axial sheave coordinates move by one rounding unit of z0: the strain eps = z - z0(r) + ... keeps
      only ~5 of z0's 16 digits on the toroidal reference sheaves (|z0| ~ 1.5 m, eps ~ 1e-5 m);
    - the band and shaft speeds move by one rounding unit each (the slip ``v - r omega`` cancels ~20 m/s
      to ~1e-2 m/s);

    and, for the dissipation ``-Qf . v``, the rounding bound of that dot product, ``n eps sum |Qf_i v_i|``:
    the friction powers on band and shafts (~1e5 W each) cancel to ~1e2 W, so the dissipation keeps only
    ~12 digits (issue 11: 1.2e-12 relative between the kernel and the twin under the Sandybridge OpenBLAS
    kernel, whose dot products round differently)."""
    a0, i0 = m.accel_numpy(q, v, F, M)
    g = {k: val.real for k, val in m.arcs(q[0]).items()}
    Qf = m._friction(q, v, g, m.strain(q, g))[0]
    dot_bound = v.size * np.finfo(float).eps * float(np.abs(Qf * v).sum())
    qp, vp = q.copy(), v.copy()
    qp[4:6] += np.spacing(np.abs(m.arcs(q[0])["z0"]).max())
    vp[1:4] += np.spacing(np.abs(v[1:4]))
    out = {"a": 0.0, "N": 0.0, "dissipation": dot_bound}
    for qq, vv in ((qp, v), (q, vp)):
        ap, ip = m.accel_numpy(qq, vv, F, M)
        for key, new, ref in (("a", ap, a0), ("N", ip["N"], i0["N"]), ("dissipation", ip["dissipation"],
                                                                        i0["dissipation"])):
            out[key] = max(out[key], float(np.abs(np.asarray(new) - ref).max()))
    return out


@pytest.mark.parametrize("name,profile,law", CASES)
def test_numba_kernel_equals_numpy_twin(name, profile, law):
    """Equal to 1e-12 relative, or to 10x the rounding sensitivity of the strain where that is larger."""
    m = band_model(_scene(name, profile, law))
    assert m.backend == "numba"
    rng = np.random.default_rng(5)
    lift_off = False
    for q, v, F, M in _random_states(m, rng, 6):
        a1, i1 = m.accel(q, v, F, M)
        a0, i0 = m.accel_numpy(q, v, F, M)
        unit = _rounding_scale(m, q, v, F, M)
        assert i0["N"].max() > 0
        lift_off |= bool(i0["N"].min() == 0.0)
        assert np.abs(i0["slip"]).min() < 2 * m.p.v0  # the unsaturated part of the friction law is used
        assert np.abs(i1["eps"] - i0["eps"]).max() <= 1e-15 * np.abs(m.arcs(q[0])["z0"]).max()
        for key, ref, val in [("a", a0, a1)] + [(k, np.asarray(i0[k], float), np.asarray(i1[k], float))
                                                for k in ("N", "slip", "slip_max", "dissipation", "clamp_power")]:
            tol = max(1e-12 * np.abs(ref).max(), 10 * unit.get(key, 0.0))
            assert np.abs(val - ref).max() <= tol, key
    assert lift_off  # the clipped branch N = 0 is compared too


@pytest.mark.parametrize("name", ["band-6+2n", "band-6+2n+8"])
def test_model_jacobian_kernel_equals_numpy_twin(name):
    """Same forward differences: equal to 1e-6 per column, or to the rounding noise of the right-hand side
    over the increment (10 x the strain's rounding sensitivity / h) where that is larger (phi column)."""
    m = band_model(_scene(name))
    q, v, F, M = next(_random_states(m, np.random.default_rng(2), 1))
    J1, J0 = m.jacobian(q, v, F, M), m.jacobian_numpy(q, v, F, M)
    x = np.concatenate([q, v, F, M])
    n2 = m.n2
    h = np.where(np.arange(x.size) < n2, 1e-8 * np.maximum(1e-3, np.abs(x)),
                 np.where(np.arange(x.size) < 2 * n2, 1e-7, 1e-6) * np.maximum(1.0, np.abs(x)))
    noise = 10 * _rounding_scale(m, q, v, F, M)["a"] / h
    tol = np.maximum(1e-6 * np.abs(J0).max(axis=0), noise)
    assert (np.abs(J1 - J0).max(axis=0) <= tol).all()


@pytest.mark.parametrize("name", ["band-6+2n", "band-6+2n+8"])
def test_loop_jacobian_equals_finite_differences_of_the_loop(name):
    """Chain rule (model Jacobian, loops' outputs) against differences of the whole right-hand side."""
    loop = closed_loop(_scene(name))
    x = loop.initial_state(ratio=2.3, speed_factor=0.96)  # loops away from their targets, integrators busy
    n = loop.model.n2
    x[n:2 * n] *= 1 + 0.01 * np.random.default_rng(3).standard_normal(n)
    J1, J0 = loop.jac(0.0, x), loop.jac_fd(0.0, x)
    scale = np.abs(J0).max(axis=0)
    cols = scale > 0
    assert np.array_equal(np.abs(J1).max(axis=0) > 0, cols)  # same sparsity of columns
    assert (np.abs(J1 - J0).max(axis=0)[cols] / scale[cols]).max() < 1e-6


def test_without_numba_the_numpy_twin_runs(monkeypatch):
    m = band_model(_scene("band-6+2n"))
    monkeypatch.setattr(ker, "HAVE_NUMBA", False)
    assert m.backend == "numpy"
    assert dataclasses.replace(m, use_numba=False).backend == "numpy"
    q, v, F, M = next(_random_states(m, np.random.default_rng(4), 1))
    assert np.array_equal(m.accel(q, v, F, M)[0], m.accel_numpy(q, v, F, M)[0])
