"""Compiled pin–sheave contact evaluations, H1 and H2 with regularised friction (contact digest §4, §5, §10.1).

From the pin-end poses and rates and the sheave poses and rates of ``m`` contacts to the contact force on
the pin, its normal and friction parts, the loads on pin and sheave, penetration, contact radius and slip
velocity, in one compiled pass over the contacts with no temporaries per contact.  The numpy functions of
:mod:`.pin_axis`, :mod:`.refined`, :mod:`.hertz`, :mod:`.friction` and :mod:`.sheave` are the reference twin:
:func:`h1_reference` and :func:`h2_reference` chain them exactly as the kernels do (same formulas, same
order), and the tests hold the two equal to round-off.  :func:`h1_contacts` and :func:`h2_contacts` pick
the backend.  Without numba the kernels run as plain Python.

Conventions (SI, world frame, arrays over contacts): pin point ``R_pin`` (m), its velocity ``v_pin`` (m/s);
sheave centre ``R_c``, velocity ``v_c``, tilt rotation vector ``theta`` (rad, ``theta . k = 0``), angular
velocity ``omega`` (rad/s); ``side = +-1`` (sheave material on the ``-side k`` side); Hertz stiffness ``c``
(N/m^1.5); one :class:`~.meridian.Meridian` per call; friction ``f0``, ``v0`` (m/s), ``law``, ``eps`` of
:mod:`.friction`.  Forces on the pin are the exact gradient of ``2/5 c Delta^{5/2}`` plus friction
``-N psi(|v_r|) v_r``; the sheave gets ``-F`` at the contact point.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.contact.friction import LAWS, _check, friction_force
from cvtfem.elements.contact.hertz import hertz_force, normal_force
from cvtfem.elements.contact.meridian import Meridian, evaluate
from cvtfem.elements.contact.pin_axis import pin_axis_contact, pin_axis_slip
from cvtfem.elements.contact.refined import (pin_coefficients, pin_loads, refined_contact, refined_slip,
                                             sheave_coefficients)
from cvtfem.elements.contact.sheave import rotate, sheave_generalized
from cvtfem.elements.jit import njit
from cvtfem.errors import NumericalError

#: Friction-law codes of the kernels (``nonsmooth`` is ``linear-saturated``).
LAW_CODES = {"linear-saturated": 0, "nonsmooth": 0, "smooth": 1, "arctan": 2, "smoothed": 3, "tanh": 4}
_SMALL = 1e-4   # as friction._SMALL: series of arctan(x)/x, tanh(x)/x below


@dataclass(frozen=True)
class ContactLoads:
    """Results of :func:`h1_contacts` / :func:`h2_contacts` (arrays over the ``m`` contacts).

    Attributes
    ----------
    force : (m, 3) N
        Total contact force on the pin (normal plus friction), acting at :attr:`point`.
    friction : (m, 3) N
        Its friction part.
    normal : (m,) N
        Hertz normal force ``N = c max(Delta, 0)^{3/2}``.
    delta : (m,) m
        Penetration along the sheave axis (> 0 in contact).
    radius : (m,) m
        Contact radius: distance of the contact point from the sheave axis in the sheave frame.
    slip : (m, 3) m/s
        Tangential slip velocity ``v_r`` (pin material point relative to the sheave's).
    point : (m, 3) m
        Contact point: the pin-axis point (H1) or ``R_*`` (H2).
    pin_moment : (m, 3) N m
        H2: ``Q'_p = (rho x F) x k`` on the pin-end slope (1.351); H1: zero.
    pin_spin : (m,) N m
        H2: ``Q_phi`` on the pin spin ``delta phi`` (1.351); H1: zero.
    sheave_force, sheave_tilt : (m, 3) N, N m
        Generalized forces on the sheave translation and tilt rotation vector (exact tangent operator).
    sheave_spin : (m,) N m
        Generalized force on the sheave spin angle.
    """

    force: np.ndarray
    friction: np.ndarray
    normal: np.ndarray
    delta: np.ndarray
    radius: np.ndarray
    slip: np.ndarray
    point: np.ndarray
    pin_moment: np.ndarray
    pin_spin: np.ndarray
    sheave_force: np.ndarray
    sheave_tilt: np.ndarray
    sheave_spin: np.ndarray


# ---------------------------------------------------------------------------- scalar helpers (compiled)
@njit(cache=True)
def _coefficients(t2):
    """``(sin t/t, (1 - cos t)/t^2, (t - sin t)/t^3)`` with the series of :func:`.sheave._coefficients`."""
    if t2 <= 1e-6:
        return 1 - t2 / 6 + t2 * t2 / 120, 0.5 - t2 / 24 + t2 * t2 / 720, 1 / 6 - t2 / 120 + t2 * t2 / 5040
    t = np.sqrt(t2)
    return np.sin(t) / t, (1 - np.cos(t)) / t ** 2, (t - np.sin(t)) / t ** 3


@njit(cache=True)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True)
def _rotate(t0, t1, t2, s1, s2, v0, v1, v2, sign):
    """``P(theta) v`` (``sign = 1``) or ``P(theta)^T v`` (``sign = -1``), Rodrigues as :func:`.sheave.rotate`
    with the first two :func:`_coefficients` ``s1, s2`` of ``theta``."""
    c0, c1, c2 = _cross(t0, t1, t2, v0, v1, v2)
    d0, d1, d2 = _cross(t0, t1, t2, c0, c1, c2)
    return v0 + sign * s1 * c0 + s2 * d0, v1 + sign * s1 * c1 + s2 * d1, v2 + sign * s1 * c2 + s2 * d2


@njit(cache=True)
def _gain(v, f0, v0, law, eps):
    """``psi(v) = f(v)/v`` (s/m) of :func:`.friction.friction_gain`."""
    x = v / v0
    if law == 4:
        g = np.tanh(x) / x if x > _SMALL else 1.0 - x * x / 3
    elif law == 2:
        y = 0.5 * np.pi * x
        g = np.arctan(y) / y if x > _SMALL else 1.0 - y * y / 3
    elif law == 3:
        g = 1.5 - 0.5 * x * x if x < 1.0 else 1.0 / max(x, 1.0)
    elif law == 1:
        if x < 1 - eps:
            g = 1.0
        else:
            xi = (x - (1 - eps)) / (2 * eps)
            f = 1.0 if x > 1 + eps else 1 + eps * (-1 + 2 * xi - xi * xi)
            g = f / max(x, 1 - eps)
    else:
        g = 1.0 if x < 1.0 else 1.0 / max(x, 1.0)
    return (f0 / v0) * g


@njit(cache=True)
def _slip_and_friction(i, w0, w1, w2, n0, n1, n2, N, f0, v0, law, eps, slip, friction):
    """Project the relative velocity ``w`` on the tangent plane of the unit normal ``n``, write the slip and
    the friction force ``-N psi(|v_r|) v_r`` of contact ``i``."""
    wn = n0 * w0 + n1 * w1 + n2 * w2
    s0, s1, s2 = w0 - wn * n0, w1 - wn * n1, w2 - wn * n2
    slip[i, 0], slip[i, 1], slip[i, 2] = s0, s1, s2
    g = N * _gain(np.sqrt(s0 * s0 + s1 * s1 + s2 * s2), f0, v0, law, eps)
    friction[i, 0], friction[i, 1], friction[i, 2] = -g * s0, -g * s1, -g * s2


@njit(cache=True)
def _sheave_loads(i, t0, t1, t2, s1, s2, s3, a0, a1, a2, force, sheave_force, sheave_tilt, sheave_spin):
    """Sheave loads of the pin force ``force[i]`` at ``R_c + arm`` (:func:`.sheave.sheave_generalized`);
    ``s1, s2, s3`` the :func:`_coefficients` of ``theta``."""
    F0, F1, F2 = force[i, 0], force[i, 1], force[i, 2]
    m0, m1, m2 = _cross(a0, a1, a2, F0, F1, F2)
    m0, m1, m2 = -m0, -m1, -m2
    sheave_force[i, 0], sheave_force[i, 1], sheave_force[i, 2] = -F0, -F1, -F2
    c0, c1, c2 = _cross(t0, t1, t2, m0, m1, m2)
    d0, d1, d2 = _cross(t0, t1, t2, c0, c1, c2)
    sheave_tilt[i, 0] = m0 - s2 * c0 + s3 * d0
    sheave_tilt[i, 1] = m1 - s2 * c1 + s3 * d1
    sheave_tilt[i, 2] = m2 - s2 * c2 + s3 * d2
    k0, k1, k2 = _rotate(t0, t1, t2, s1, s2, 0.0, 0.0, 1.0, 1.0)
    sheave_spin[i] = k0 * m0 + k1 * m1 + k2 * m2


# ---------------------------------------------------------------------------- H1
@njit(cache=True)
def h1_kernel(R_pin, v_pin, R_c, v_c, theta, omega, side, c, prof, f0, v0, law, eps,
              force, friction, normal, delta, radius, slip, sheave_force, sheave_tilt, sheave_spin):
    """H1 contacts (pin-axis point, (1.317)-(1.329)), outputs written in place; arguments as :func:`h1_contacts`."""
    for i in range(R_pin.shape[0]):
        t0, t1, t2 = theta[i, 0], theta[i, 1], theta[i, 2]
        s1, s2, s3 = _coefficients(t0 * t0 + t1 * t1 + t2 * t2)
        a0, a1, a2 = R_pin[i, 0] - R_c[i, 0], R_pin[i, 1] - R_c[i, 1], R_pin[i, 2] - R_c[i, 2]
        d0, d1, d2 = _rotate(t0, t1, t2, s1, s2, a0, a1, a2, -1.0)
        r = np.hypot(d0, d1)
        f, fp, _ = evaluate(prof, r)
        rr = r if r > 0 else 1.0
        s = side[i]
        g0, g1, g2 = _rotate(t0, t1, t2, s1, s2, fp * d0 / rr, fp * d1 / rr, -s, 1.0)   # dDelta/dR_pin
        gn = np.sqrt(g0 * g0 + g1 * g1 + g2 * g2)
        dl = f - s * d2
        dd = max(dl, 0.0)
        N = c[i] * dd * np.sqrt(dd)
        o0, o1, o2 = _cross(omega[i, 0], omega[i, 1], omega[i, 2], a0, a1, a2)
        _slip_and_friction(i, v_pin[i, 0] - v_c[i, 0] - o0, v_pin[i, 1] - v_c[i, 1] - o1,
                           v_pin[i, 2] - v_c[i, 2] - o2, -g0 / gn, -g1 / gn, -g2 / gn, N, f0, v0, law, eps,
                           slip, friction)
        force[i, 0] = -N * g0 + friction[i, 0]
        force[i, 1] = -N * g1 + friction[i, 1]
        force[i, 2] = -N * g2 + friction[i, 2]
        normal[i], delta[i], radius[i] = N, dl, r
        _sheave_loads(i, t0, t1, t2, s1, s2, s3, a0, a1, a2, force, sheave_force, sheave_tilt, sheave_spin)


def h1_reference(R_pin, v_pin, R_c, v_c, theta, omega, side, c, meridian, f0, v0, law="smooth", eps=0.1) -> ContactLoads:
    """The numpy twin of :func:`h1_kernel`: :func:`.pin_axis.pin_axis_contact` -> Hertz -> slip -> friction -> loads."""
    con = pin_axis_contact(R_pin, R_c, theta, meridian, side)
    N, _ = hertz_force(con.delta, c)
    v_r = pin_axis_slip(con, v_pin, v_c, omega)
    F_fr, _ = friction_force(v_r, N, f0, v0, law, eps)
    F = normal_force(con.grad, N) + F_fr
    F_s, Q_theta, Q_phi = sheave_generalized(F, con.arm, theta)
    m = F.shape[0]
    return ContactLoads(F, F_fr, N, con.delta, con.radius, v_r, np.asarray(R_pin, float), np.zeros((m, 3)),
                        np.zeros(m), F_s, Q_theta, Q_phi)


# ---------------------------------------------------------------------------- H2
@njit(cache=True)
def _tilted(c0, l0, l1, q00, q01, q11, g0, g1):
    """Tilted quadratic graph (:func:`.refined._tilted`, symmetric ``C2``): ``(c0, lin, quad)`` as scalars."""
    ga = g0 * l0 + g1 * l1
    cg0, cg1 = q00 * g0 + q01 * g1, q01 * g0 + q11 * g1
    return (c0, l0 * (1 - ga) - g0, l1 * (1 - ga) - g1,
            q00 * (1 - ga) - 2 * cg0 * l0, q01 * (1 - ga) - cg0 * l1 - l0 * cg1, q11 * (1 - ga) - 2 * cg1 * l1)


@njit(cache=True)
def h2_kernel(R_pin, v_pin, omega_pin, slope, tau, beta0, beta, Bcal, H, R_c, v_c, theta, omega, side, c, prof,
              f0, v0, law, eps, force, friction, normal, delta, radius, slip, point, pin_moment, pin_spin,
              sheave_force, sheave_tilt, sheave_spin):
    """H2 contacts (closed-form contact point, §5), outputs written in place; returns the index of the first
    contact whose ``B - A`` is not positive definite, or -1.  Arguments as :func:`h2_contacts`."""
    bad = -1
    for i in range(R_pin.shape[0]):
        s = side[i]
        t0, t1, t2 = theta[i, 0], theta[i, 1], theta[i, 2]
        # sheave quadratic about x0 = in-plane pin point ((1.339)-(1.343), mirrored for side -1)
        gs0, gs1 = s * t1, -s * t0                                  # s (theta x k)
        xt0, xt1 = R_pin[i, 0] - R_c[i, 0], R_pin[i, 1] - R_c[i, 1]
        f_xt, _, _ = evaluate(prof, np.sqrt(xt0 * xt0 + xt1 * xt1))
        xi0, xi1 = xt0 - f_xt * gs0, xt1 - f_xt * gs1
        r = np.sqrt(xi0 * xi0 + xi1 * xi1)
        f, fp, fpp = evaluate(prof, r)
        e0, e1 = xi0 / r, xi1 / r
        n0, n1 = -e1, e0
        a, av0, av1, A00, A01, A11 = _tilted(s * R_c[i, 2] + f - (gs0 * xt0 + gs1 * xt1), fp * e0, fp * e1,
                                             fpp * e0 * e0 + fp / r * n0 * n0, fpp * e0 * e1 + fp / r * n0 * n1,
                                             fpp * e1 * e1 + fp / r * n1 * n1, gs0, gs1)
        # pin-face quadratic ((1.344)-(1.345), re-centred for beta0 != 0)
        gp0, gp1 = s * slope[i, 0], s * slope[i, 1]
        p0, p1 = tau[i, 0], tau[i, 1]                               # P_phi = [[p0, -p1], [p1, p0]]
        B00, B01, B11 = Bcal[i, 0, 0], Bcal[i, 0, 1], Bcal[i, 1, 1]
        z0, z1 = -beta0[i] * (p0 * gp0 + p1 * gp1), -beta0[i] * (-p1 * gp0 + p0 * gp1)
        bb0 = beta0[i] + beta[i, 0] * z0 + beta[i, 1] * z1 + 0.5 * (z0 * (B00 * z0 + B01 * z1) + z1 * (B01 * z0 + B11 * z1))
        be0, be1 = beta[i, 0] + B00 * z0 + B01 * z1, beta[i, 1] + B01 * z0 + B11 * z1
        bp0, bp1 = p0 * be0 - p1 * be1, p1 * be0 + p0 * be1
        PB00, PB01, PB10, PB11 = p0 * B00 - p1 * B01, p0 * B01 - p1 * B11, p1 * B00 + p0 * B01, p1 * B01 + p0 * B11
        b, bv0, bv1, Bq00, Bq01, Bq11 = _tilted(s * R_pin[i, 2] + bb0, bp0, bp1, PB00 * p0 - PB01 * p1,
                                                PB00 * p1 + PB01 * p0, PB10 * p1 + PB11 * p0, gp0, gp1)
        # closed-form contact point (§5.3)
        M00, M01, M11 = Bq00 - A00, Bq01 - A01, Bq11 - A11
        det = M00 * M11 - M01 * M01
        if not (det > 0.0 and M00 > 0.0):
            if bad < 0:
                bad = i
            det = 1.0
        da0, da1 = av0 - bv0, av1 - bv1
        x0, x1 = (M11 * da0 - M01 * da1) / det, (M00 * da1 - M01 * da0) / det
        dl = a - b + 0.5 * (da0 * x0 + da1 * x1)
        Ax0, Ax1 = A00 * x0 + A01 * x1, A01 * x0 + A11 * x1
        z_pul = a + av0 * x0 + av1 * x1 + 0.5 * (x0 * Ax0 + x1 * Ax1)
        z_pin = b + bv0 * x0 + bv1 * x1 + 0.5 * (x0 * (Bq00 * x0 + Bq01 * x1) + x1 * (Bq01 * x0 + Bq11 * x1))
        P0, P1, P2 = R_pin[i, 0] + x0, R_pin[i, 1] + x1, 0.5 * s * (z_pul + z_pin)
        point[i, 0], point[i, 1], point[i, 2] = P0, P1, P2
        g0, g1, g2 = av0 + Ax0, av1 + Ax1, -s                        # dDelta/d(pin translation)
        gn = np.sqrt(g0 * g0 + g1 * g1 + g2 * g2)
        dd = max(dl, 0.0)
        N = c[i] * dd * np.sqrt(dd)
        # slip of the material points at R_* (§5.6)
        rho0, rho1, rho2 = P0 - R_pin[i, 0], P1 - R_pin[i, 1], P2 - R_pin[i, 2]
        ar0, ar1, ar2 = P0 - R_c[i, 0], P1 - R_c[i, 1], P2 - R_c[i, 2]
        o0, o1, o2 = _cross(omega_pin[i, 0], omega_pin[i, 1], omega_pin[i, 2], rho0, rho1, rho2)
        w0, w1, w2 = _cross(omega[i, 0], omega[i, 1], omega[i, 2], ar0, ar1, ar2)
        _slip_and_friction(i, v_pin[i, 0] + o0 - v_c[i, 0] - w0, v_pin[i, 1] + o1 - v_c[i, 1] - w1,
                           v_pin[i, 2] + o2 - v_c[i, 2] - w2, -g0 / gn, -g1 / gn, -g2 / gn, N, f0, v0, law, eps,
                           slip, friction)
        F0, F1, F2 = -N * g0 + friction[i, 0], -N * g1 + friction[i, 1], -N * g2 + friction[i, 2]
        force[i, 0], force[i, 1], force[i, 2] = F0, F1, F2
        normal[i], delta[i] = N, dl
        # pin loads (1.350)-(1.351): Q'_p = (rho x F) x k, Q_phi = F . [(k + u') x rho + H n_perp]
        m0, m1, _ = _cross(rho0, rho1, rho2, F0, F1, F2)
        pin_moment[i, 0], pin_moment[i, 1], pin_moment[i, 2] = m1, -m0, 0.0
        l0, l1, l2 = _cross(slope[i, 0], slope[i, 1], 1.0, rho0, rho1, rho2)
        pin_spin[i] = F0 * (l0 - H[i] * p1) + F1 * (l1 + H[i] * p0) + F2 * l2
        s1, s2, s3 = _coefficients(t0 * t0 + t1 * t1 + t2 * t2)
        d0, d1, _ = _rotate(t0, t1, t2, s1, s2, ar0, ar1, ar2, -1.0)
        radius[i] = np.hypot(d0, d1)
        _sheave_loads(i, t0, t1, t2, s1, s2, s3, ar0, ar1, ar2, force, sheave_force, sheave_tilt, sheave_spin)
    return bad


def h2_reference(R_pin, v_pin, omega_pin, slope, tau, beta0, beta, Bcal, H, R_c, v_c, theta, omega, side, c,
                 meridian, f0, v0, law="smooth", eps=0.1) -> ContactLoads:
    """The numpy twin of :func:`h2_kernel`: coefficients -> closed form -> Hertz -> slip -> friction -> loads."""
    R_pin, theta, slope = (np.asarray(x, float) for x in (R_pin, theta, slope))
    m = R_pin.shape[0]
    side = np.broadcast_to(np.asarray(side, float), (m,))
    x0 = R_pin[:, :2]
    gamma = np.stack([theta[:, 1], -theta[:, 0]], -1)                # theta x k
    sh = sheave_coefficients(x0, R_c, gamma, meridian, side)
    pin = pin_coefficients(R_pin[:, 2], slope, tau, beta0, beta, Bcal, side)
    con = refined_contact(x0, *sh, *pin, side)
    N, _ = hertz_force(con.delta, c)
    v_r = refined_slip(con, R_pin, v_pin, omega_pin, R_c, v_c, omega)
    F_fr, _ = friction_force(v_r, N, f0, v0, law, eps)
    F = normal_force(con.grad, N) + F_fr
    tau = np.asarray(tau, float)
    n_perp = np.stack([-tau[:, 1], tau[:, 0], np.zeros(m)], -1)
    _, Qp_slope, Qp_spin = pin_loads(F, con.point - R_pin, np.column_stack([slope, np.zeros(m)]), H, n_perp)
    arm = con.point - R_c
    F_s, Q_theta, Q_phi = sheave_generalized(F, arm, theta)
    d = rotate(theta, arm, inverse=True)
    return ContactLoads(F, F_fr, N, con.delta, np.hypot(d[:, 0], d[:, 1]), v_r, con.point, Qp_slope, Qp_spin,
                        F_s, Q_theta, Q_phi)


# ---------------------------------------------------------------------------- front ends
def _f(x, shape):
    return np.ascontiguousarray(np.broadcast_to(np.asarray(x, float), shape))


def _outputs(m):
    return dict(force=np.empty((m, 3)), friction=np.empty((m, 3)), normal=np.empty(m), delta=np.empty(m),
                radius=np.empty(m), slip=np.empty((m, 3)))


def _sheave_outputs(m):
    return dict(sheave_force=np.empty((m, 3)), sheave_tilt=np.empty((m, 3)), sheave_spin=np.empty(m))


def h1_contacts(R_pin, v_pin, R_c, v_c, theta, omega, side, c, meridian: Meridian, f0: float, v0: float,
                law: str = "smooth", eps: float = 0.1, use_numba: bool = True) -> ContactLoads:
    """H1 loads of ``m`` contacts at pin-axis points ``R_pin`` (m, 3); compiled kernel or numpy twin.

    ``R_pin, v_pin, R_c, v_c, theta, omega`` (m, 3), ``side`` and ``c`` (m,) or scalars (module docstring).
    """
    if not use_numba:
        return h1_reference(R_pin, v_pin, R_c, v_c, theta, omega, side, c, meridian, f0, v0, law, eps)
    _check(law, eps)
    m = np.shape(R_pin)[0]
    vec = [_f(x, (m, 3)) for x in (R_pin, v_pin, R_c, v_c, theta, omega)]
    out, sh = _outputs(m), _sheave_outputs(m)
    h1_kernel(*vec, _f(side, (m,)), _f(c, (m,)), meridian.params, float(f0), float(v0), LAW_CODES[law], float(eps),
              *out.values(), *sh.values())
    zeros = np.zeros((m, 3))
    return ContactLoads(point=vec[0], pin_moment=zeros, pin_spin=np.zeros(m), **out, **sh)


def h2_contacts(R_pin, v_pin, omega_pin, slope, tau, beta0, beta, Bcal, H, R_c, v_c, theta, omega, side, c,
                meridian: Meridian, f0: float, v0: float, law: str = "smooth", eps: float = 0.1,
                use_numba: bool = True) -> ContactLoads:
    """H2 loads of ``m`` contacts of crowned pin faces at the pin-axis ends ``R_pin`` (m, 3); kernel or twin.

    Pin end: velocity ``v_pin``, angular velocity ``omega_pin`` (m, 3), axis slope ``slope = u'_p`` (m, 2),
    unit in-plane pin direction ``tau`` (m, 2), face ``z = beta0 + beta.xi + xi.Bcal xi/2`` in the pin frame
    (``beta0`` (m,) m, ``beta`` (m, 2), ``Bcal`` (m, 2, 2) 1/m, symmetric), half offset ``H`` (m,) (0: whole
    pin).  Sheave and friction as :func:`h1_contacts`.  Raises :class:`~cvtfem.errors.NumericalError` where
    ``B - A`` is not positive definite.
    """
    if not use_numba:
        return h2_reference(R_pin, v_pin, omega_pin, slope, tau, beta0, beta, Bcal, H, R_c, v_c, theta, omega,
                            side, c, meridian, f0, v0, law, eps)
    _check(law, eps)
    m = np.shape(R_pin)[0]
    pin = [_f(R_pin, (m, 3)), _f(v_pin, (m, 3)), _f(omega_pin, (m, 3)), _f(slope, (m, 2)), _f(tau, (m, 2)),
           _f(beta0, (m,)), _f(beta, (m, 2)), _f(Bcal, (m, 2, 2)), _f(H, (m,))]
    sheave = [_f(x, (m, 3)) for x in (R_c, v_c, theta, omega)]
    out, sh = _outputs(m), _sheave_outputs(m)
    extra = dict(point=np.empty((m, 3)), pin_moment=np.empty((m, 3)), pin_spin=np.empty(m))
    bad = h2_kernel(*pin, *sheave, _f(side, (m,)), _f(c, (m,)), meridian.params, float(f0), float(v0),
                    LAW_CODES[law], float(eps), *out.values(), extra["point"], extra["pin_moment"],
                    extra["pin_spin"], *sh.values())
    if bad >= 0:
        raise NumericalError(f"H2 contact: B - A not positive definite at contact {bad}", component="contact.refined")
    return ContactLoads(**out, **extra, **sh)


__all__ = ["LAWS", "LAW_CODES", "ContactLoads", "h1_contacts", "h1_kernel", "h1_reference", "h2_contacts",
           "h2_kernel", "h2_reference"]
