"""Compiled gather/scatter of pin-axis points and point loads against ChainA1's numpy methods."""
import numpy as np

from cvtfem.elements.chain.a_loads_kernel import axis_points_kernel, point_loads_kernel
from cvtfem.elements.chain.asymmetric import ChainA1


def test_gather_and_scatter_equal_the_numpy_methods():
    """Random states, 200 loads on repeated pins at random stations (ends included): the kernels equal
    ChainA1.axis_points and point_loads to 1e-14, and the scatter is the transpose of the gather
    (virtual work F . dU = Q . dq for the forces)."""
    rng = np.random.default_rng(0)
    n = 7
    ch = ChainA1(pitch=np.full(n, 0.009), plate_xi=np.zeros((n, 1)), n_plates=np.ones(n, int), plate_stiffness=1e6,
                 plate_bending_stiffness=0.1, plate_torsion_stiffness=1.0, pin_length=0.03, pin_mass=np.full(n, 0.01),
                 pin_axial_stiffness=1e7, pin_bending_tau=1.0, pin_bending_n=1.0, use_numba=False)
    q = rng.normal(size=ch.n2) * 1e-2
    pins = rng.integers(0, n, 200)
    xi = np.r_[-1.0, 1.0, rng.uniform(-1, 1, 198)]
    force, moment = rng.normal(size=(200, 3)) * 1e3, rng.normal(size=(200, 2))
    pts = np.empty((200, 3))
    axis_points_kernel(q, n, ch.l, pins, xi, pts)
    ref = ch.axis_points(q, pins, xi)
    assert np.abs(pts - ref).max() <= 1e-14 * np.abs(ref).max()
    Q = np.zeros(ch.n2)
    point_loads_kernel(n, ch.l, pins, xi, force, moment, Q)
    ref = ch.point_loads(pins, xi, force, moment)
    assert np.abs(Q - ref).max() <= 1e-14 * np.abs(ref).max()
    dq = rng.normal(size=ch.n2)
    dU = np.empty((200, 3))
    axis_points_kernel(dq, n, ch.l, pins, xi, dU)                       # U is linear in q
    Qf = np.zeros(ch.n2)
    point_loads_kernel(n, ch.l, pins, xi, force, np.zeros((200, 2)), Qf)
    assert abs(Qf @ dq - np.sum(force * dU)) <= 1e-12 * np.abs(force * dU).sum()
