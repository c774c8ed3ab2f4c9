"""Overhung disk on a (nearly massless) cantilever: whirl frequencies against the closed form.

(k11 - m w^2)(k22 - B w^2 + s A Omega w) - k12^2 = 0 with s = +1 forward, -1 backward
(spec §4.4 review note; Friswell et al. 2010), k the Euler-Bernoulli tip stiffness.
"""
import numpy as np
import pytest

from cvtfem.assembly import assemble
from cvtfem.elements.beam import BeamFamily, BeamOptions
from cvtfem.elements.disk import DiskFamily
from cvtfem.modal import ModalProblem

E, L, D = 2.1e11, 0.4, 0.03
m, B, A = 12.0, 0.05, 0.09      # disk mass, diametral and polar inertia


def model():
    beam = BeamFamily(nodes=np.array([[0, 1]]), L=np.array([L]), Do=np.array([D]), Di=np.array([0.0]),
                      E=np.array([E]), G=np.array([8e10]), rho=np.array([1e-3]),
                      options=BeamOptions(shear=False, rotary_inertia=False, gyroscopic=False))
    disk = DiskFamily(np.array([1]), np.array([m]), np.array([B]), np.array([A]))
    n = 12
    M = assemble(n, [(beam.mass(), beam.dofs), (disk.mass(), disk.dofs)])
    K = assemble(n, [(beam.stiffness(), beam.dofs)])
    G = assemble(n, [(beam.gyroscopic(), beam.dofs), (disk.gyroscopic(), disk.dofs)])
    keep = np.array([6, 7, 9, 10])          # tip u1, u2, theta1, theta2 (root clamped)
    sub = [X[keep][:, keep] for X in (M, K, G)]
    return sub, np.array([0, 1, 3, 4])


def closed_form(speed):
    EI = E * np.pi * D**4 / 64
    k11, k12, k22 = 12 * EI / L**3, -6 * EI / L**2, 4 * EI / L
    roots = {}
    for label, s in (("forward", 1.0), ("backward", -1.0)):
        poly = np.polysub(np.polymul([-m, 0, k11], [-B, s * A * speed, k22]), [k12**2])
        r = np.roots(poly)
        roots[label] = np.sort(r[(abs(r.imag) < 1e-9 * abs(r)) & (r.real > 0)].real)
    return roots


@pytest.mark.parametrize("speed", [0.0, 500.0, 3000.0])
def test_overhung_disk_whirl(speed):
    (M, K, G), kind = model()
    r = ModalProblem(M, K, 0 * K, G, kind, method="dense").solve(speed, 4)
    exact = closed_form(speed)
    for label in ("forward", "backward"):
        got = np.sort(r.wd[np.array(r.whirl) == label])
        np.testing.assert_allclose(got, exact[label], rtol=1e-6)
    if speed:
        assert r.wd[np.array(r.whirl) == "forward"][0] > r.wd[np.array(r.whirl) == "backward"][0]


def test_campbell_of_a_small_model_tracks_all_its_modes():
    """4 DOF give 4 oscillatory modes: the Campbell sweep asks for spares but must not fail."""
    from cvtfem.modal import campbell

    (M, K, G), kind = model()
    res = campbell(ModalProblem(M, K, 0 * K, G, kind, method="dense"), np.linspace(0, 3000, 7), 4)
    for i, s in enumerate(res.speeds):
        exact = closed_form(s)
        np.testing.assert_allclose(np.sort(res.wd[i]), np.sort(np.concatenate([exact["forward"],
                                                                               exact["backward"]])), rtol=1e-6)
