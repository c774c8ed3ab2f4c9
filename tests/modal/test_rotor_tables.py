"""Speed-dependent bearing coefficients, sleeve (parallel) elements, static deflection and the critical-speed map:
closed forms and cross-checks between independent routes."""
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from cvtfem.elements.bearing import interpolate_over_speed
from cvtfem.errors import InputError
from cvtfem.machines.rotor import build_model
from cvtfem.modal import ModalProblem
from cvtfem.modal.forced import displacement, unbalance_response
from cvtfem.modal.maps import critical_speed_map, static_deflection
from cvtfem.scene.loader import load_scene

E, G, RHO, D, L = 2.11e11, 8.12e10, 7810.0, 0.05, 1.5

SHAFT = """
[rotor]
theory = "{theory}"
[[material]]
name = "steel"
E = {E}
G = {G}
rho = {rho}
[[shaft]]
length = {le}
outer_diameter = 0.05
material = "steel"
repeat = {n}
"""

DISKS = """
[[disk]]
node = 2
mass = 32.59
Id = 0.1781
Ip = 0.3296
[[disk]]
node = 4
mass = 51.53
Id = 0.4236
Ip = 0.8051
"""


def _scene(tmp_path, text, name="s"):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return load_scene(str(path))


def _shaft(n=6, theory="timoshenko", E=E, G=G, rho=RHO):
    return SHAFT.format(theory=theory, E=E, G=G, rho=rho, le=L / n, n=n)


TABLE_BEARINGS = """
[[bearing]]
node = 0
speeds = [100.0, 300.0, 500.0, 800.0]
kxx_table = [1.0e6, 1.4e6, 1.6e6, 1.7e6]
kyy_table = [0.8e6, 1.1e6, 1.5e6, 1.6e6]
kxy_table = [0.0, 1e5, 2e5, 4e5]
kyx_table = [0.0, -1e5, -2e5, -4e5]
cxx_table = [500.0, 400.0, 300.0, 250.0]
cyy_table = [600.0, 450.0, 350.0, 300.0]
[[bearing]]
node = 6
speeds = [200.0, 600.0]
kxx_table = [1.2e6, 0.9e6]
cxx = 300.0
cyy = 300.0
kyy = 1.0e6
"""


def _tabled(tmp_path, speed=0.0, name="t"):
    base = _shaft().replace('theory = "timoshenko"', f'theory = "timoshenko"\nspeed = {speed}')
    return build_model(_scene(tmp_path, base + DISKS + TABLE_BEARINGS, name))


def test_interpolation_follows_ross_rules():
    """PCHIP through the points, linear with two points, linear continuation with the end slopes outside."""
    s = np.array([100.0, 300.0, 500.0, 800.0])
    v = np.array([[1.0, 4.0], [1.4, 3.0], [1.6, 1.0], [1.7, 0.5]])
    p = PchipInterpolator(s, v)
    for x in (100.0, 150.0, 420.0, 799.0):
        assert np.allclose(interpolate_over_speed(s, v, x), p(x), rtol=1e-14)
    slope = p.derivative()(800.0)
    assert np.allclose(interpolate_over_speed(s, v, 1000.0), v[-1] + 200.0 * slope, rtol=1e-14)
    assert np.allclose(interpolate_over_speed(s, v, 0.0), v[0] - 100.0 * p.derivative()(100.0), rtol=1e-14)
    # monotone data stay monotone between the points (no overshoot)
    fine = np.array([interpolate_over_speed(s, v, x) for x in np.linspace(100, 800, 141)])
    assert np.all(np.diff(fine[:, 0]) >= 0) and np.all(np.diff(fine[:, 1]) <= 0)
    two = interpolate_over_speed(s[:2], v[:2], 500.0)
    assert np.allclose(two, v[0] + (v[1] - v[0]) * 2.0, rtol=1e-14)
    assert np.allclose(interpolate_over_speed(s[:1], v[:1], 1e4), v[0])


@pytest.mark.parametrize("method", ["dense", "sparse"])
def test_speed_terms_equal_a_model_frozen_at_that_speed(tmp_path, method):
    """Modes with the speed terms at Omega = modes of the model whose [rotor] speed is Omega (tables evaluated
    once in K and C): two routes through the tables."""
    model = _tabled(tmp_path)
    problem = ModalProblem(model.M, model.K, model.C, model.G, model.dof_kind, method, speed_terms=model.speed_terms)
    for speed in (0.0, 250.0, 640.0, 1200.0):
        frozen = _tabled(tmp_path, speed, f"f{int(speed)}")
        ref = ModalProblem(frozen.M, frozen.K, frozen.C, frozen.G, frozen.dof_kind, method).solve(speed, 8)
        mine = problem.solve(speed, 8)
        assert np.allclose(mine.eigenvalues, ref.eigenvalues, rtol=1e-10)


def test_unbalance_with_tables_equals_frozen_models(tmp_path):
    model = _tabled(tmp_path)
    out = displacement(np.array([12, 13, 24, 25]), model.n_dof)
    load = model.unbalance_load(3, 1e-4, 0.3)
    speeds = np.array([50.0, 280.0, 700.0, 950.0])
    mine = unbalance_response(model.M, model.K, model.C, model.G, load, out, speeds, speed_terms=model.speed_terms)
    for i, s in enumerate(speeds):
        f = _tabled(tmp_path, s, f"u{i}")
        ref = unbalance_response(f.M, f.K, f.C, f.G, load, out, [s])[0]
        assert np.allclose(mine[i], ref, rtol=1e-11, atol=1e-11 * np.abs(ref).max())
    # and the tables matter here: frozen at 0 the response differs
    frozen = unbalance_response(model.M, model.K, model.C, model.G, load, out, speeds)
    assert np.max(np.abs(frozen - mine) / np.abs(mine)) > 0.01


def test_constant_table_is_a_constant_bearing(tmp_path):
    constant = "[[bearing]]\nnode = {n}\nkxx = 1e6\nkyy = 8e5\ncxx = 200.0\n"
    table = "[[bearing]]\nnode = {n}\nspeeds = [10.0, 50.0, 90.0]\nkxx_table = [1e6, 1e6, 1e6]\n" \
            "kyy_table = [8e5, 8e5, 8e5]\ncxx_table = [200.0, 200.0, 200.0]\n"
    a = build_model(_scene(tmp_path, _shaft() + DISKS + constant.format(n=0) + constant.format(n=6), "a"))
    b = build_model(_scene(tmp_path, _shaft() + DISKS + table.format(n=0) + table.format(n=6), "b"))
    pa = ModalProblem(a.M, a.K, a.C, a.G, a.dof_kind).solve(400.0, 8)
    pb = ModalProblem(b.M, b.K, b.C, b.G, b.dof_kind, speed_terms=b.speed_terms).solve(400.0, 8)
    assert np.allclose(pa.eigenvalues, pb.eigenvalues, rtol=1e-12)


def test_sleeve_on_every_element_doubles_the_material(tmp_path):
    """An identical parallel element on every element = the shaft with rho, E and G doubled (K, M linear in them,
    the shear parameter and Poisson's ratio unchanged): the same matrices."""
    plain = _shaft(n=6)
    entries = "".join("[[shaft]]\nlength = 0.25\nouter_diameter = 0.05\nmaterial = \"steel\"\n"
                      "[[shaft]]\nlength = 0.25\nouter_diameter = 0.05\nmaterial = \"steel\"\nparallel = true\n"
                      for _ in range(6))
    head = plain.split("[[shaft]]")[0]
    a = build_model(_scene(tmp_path, head + entries + DISKS, "sleeved"))
    b = build_model(_scene(tmp_path, _shaft(n=6, E=2 * E, G=2 * G, rho=2 * RHO) + DISKS, "doubled"))
    assert a.n_dof == b.n_dof == 42 and np.allclose(a.z, b.z)
    for X, Y in ((a.M, b.M), (a.K, b.K), (a.G, b.G)):
        assert abs(X - Y).max() <= 1e-12 * abs(Y).max()


def test_static_deflection_euler_bernoulli_closed_form(tmp_path):
    """Simply supported uniform shaft under its weight: w x (L^3 - 2 L x^2 + x^3) / (24 E I) at the nodes (cubic
    Hermite elements with consistent loads are nodally exact)."""
    model = build_model(_scene(tmp_path, _shaft(n=8, theory="euler-bernoulli"), "eb"))
    u = static_deflection(model.M, model.K, model.dof_kind, model.support_dofs([0, 8]).ravel(), g=9.81)
    w = RHO * np.pi * D**2 / 4 * 9.81
    EI = E * np.pi * D**4 / 64
    x = model.z[:9]
    exact = -w * x * (L**3 - 2 * L * x**2 + x**3) / (24 * EI)
    assert np.allclose(u[1:54:6], exact, rtol=1e-10, atol=1e-12 * np.abs(exact).max())
    assert np.allclose(u[0:54:6], 0.0)


def test_critical_speed_map_soft_supports_rigid_body_closed_form(tmp_path):
    """Soft end supports (k each, both directions): bounce sqrt(2 k / m) and rocking sqrt(2 k (L/2)^2 / J),
    J = m L^2 / 12 + the shaft's rotary inertia m D^2 / 16. The shaft's flexibility adds a relative error that
    grows linearly with k (measured -4.35e-5 for the bounce at 100 N/m, -4.35e-4 at 1000 N/m)."""
    model = build_model(_scene(tmp_path, _shaft(n=8), "free"))
    m = RHO * np.pi * D**2 / 4 * L
    J = m * L**2 / 12 + m * D**2 / 16
    k = np.array([100.0, 1000.0])
    wn = critical_speed_map(model.M, model.K, model.dof_kind, model.support_dofs([0, 8]), k, 2)
    err = np.column_stack([wn[:, 0] / np.sqrt(2 * k / m), wn[:, 1] / np.sqrt(2 * k * (L / 2) ** 2 / J)]) - 1
    assert np.all(np.abs(err[0]) < 1e-4)
    assert np.allclose(err[1] / err[0], 10.0, rtol=0.05)  # first order in k: the flexibility, not round-off


@pytest.mark.parametrize("text, key", [
    ("[[bearing]]\nnode = 0\nspeeds = [1.0, 2.0]\nkxx_table = [1.0]\n", "kxx_table"),
    ("[[bearing]]\nnode = 0\nspeeds = [2.0, 1.0]\nkxx_table = [1.0, 2.0]\n", "speeds"),
    ("[[bearing]]\nnode = 0\nspeeds = [1.0, 2.0]\n", "speeds"),
    ("[[bearing]]\nnode = 0\nkxx_table = [1.0, 2.0]\n", "kxx_table"),
])
def test_bad_tables_are_refused(tmp_path, text, key):
    with pytest.raises(InputError, match=key):
        _scene(tmp_path, _shaft() + text, "bad")


@pytest.mark.parametrize("entries, key", [
    ("[[shaft]]\nlength = 0.25\nouter_diameter = 0.05\nmaterial = \"steel\"\nparallel = true\n", "parallel"),
    ("[[shaft]]\nlength = 0.25\nouter_diameter = 0.05\nmaterial = \"steel\"\n[[shaft]]\nlength = 0.2\n"
     "outer_diameter = 0.06\nmaterial = \"steel\"\nparallel = true\n", "parallel"),
])
def test_bad_sleeves_are_refused(tmp_path, entries, key):
    head = _shaft().split("[[shaft]]")[0]
    with pytest.raises(InputError, match=key):
        _scene(tmp_path, head + entries, "bad")
