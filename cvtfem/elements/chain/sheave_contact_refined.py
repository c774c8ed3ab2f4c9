"""Refined pin–sheave contact H2 of a symmetric chain (S2, S3) on the rigid sheave pairs of two shafts.

The variant of :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact` (H1) with the refined biconvex
kinematics of the contact digest §5 (1.330)–(1.352): the pin end face is crowned and inclined,
``z = beta . xi + |xi|^2 / (2 R_f)`` about the pin-axis end in the pin frame (radius ``face_radius`` in both
directions, ``beta = tan(theta)`` towards the pin's outward radial side ``-n_perp``: the face normal tilted by
``face_inclination`` ``theta`` towards the sheave flank, turning with the pin spin), the sheave face is the
untilted face ``x3 = z_k + s(r)`` of model 1.  Both are quadratics about the in-plane pin point (1.331) and
the contact point, penetration (along ``k``) and normal are the closed form of §5.3
(:func:`~cvtfem.elements.contact.refined.refined_contact`, which the tests hold equal).  For this face and an
untilted sheave the closed form reads, in the frame of :mod:`cvtfem.elements.contact.refined` (sheave side
``s = -1``: its material on the ``+k`` side of the ``x3 > 0`` pin end)

    ``Delta = s (z_k - u3) + f(r) + ((f' + s gamma_e - q_e)^2 / m_e + (s gamma_n - q_n)^2 / m_n) / 2``,
    ``m_e = 1/R_f - f''``, ``m_n = 1/R_f - f'/r``, ``q = tan(theta) n_perp``,

with ``f(r) = -s(r)`` the face profile, ``r`` the radius of the pin end, ``gamma = END_SLOPE_FACTOR u'_p``
the world end slope of the pin axis (S3; zero for S2, where H2 is H1 shifted by ``x_*`` and
``(f' - q_e)^2/(2 m_e)``), ``gamma_e``, ``gamma_n`` its radial and circumferential parts and ``q`` the face slope
(the chain runs counter-clockwise, so ``n_perp = k x tau_p`` points inward on an arc: ``q_e = -tan(theta)``; a face
at the flank angle of a cone meets an untilted pin's face on its axis, ``x_* = 0``).  The face slope enters as the
digest's ``b = beta_phi - gamma``: its first-order cross terms with the end slope (``gamma . beta``, relative
``|gamma| tan(theta)``, ~1e-3 at end slopes of a few mrad) are dropped, so the face stays isotropic
(``B = E / R_f``) and the closed form scalar.

Forces.  The normal generalized forces are the exact gradient of the potential ``2/5 c Delta^{5/2}`` of this
closed form in the chain and sheave coordinates (pin end, end slope, ``z_k``, and through the inclined face's turn
``dDelta/dphi = tan(theta) x_* . tau_p`` the neighbours' positions): conservative to round-off.
The source's (1.351) applies ``N (k - g_*)`` at ``R_*``, which differs from the gradient by terms of third
order in the offset ``|x_*|`` (the cubic terms the quadratic surfaces drop; docs/chain.md).  Friction, the
regularised law on the slip of the material points at ``R_*`` (§5.6), acts through the kinematics (1.350):
``delta R_* = delta u + (k x delta gamma) x rho + delta phi (k + gamma) x rho`` with ``rho = R_* - R_pin``
and the pin spin ``phi`` the direction of the bisector of its two link chords (1.103)/(1.349) (unit chords:
the twist moment goes to pins ``p-1, p, p+1``), so its power ``F_fr . v_r`` is exactly the work rate of
its generalized forces.  Mirror symmetry doubles everything (chain-models-1 §2.7).

Per contact the local inputs are the positions of pins ``p-1, p, p+1`` (2 each), ``u3_p``, the slope
coordinates ``u'_p`` (S3), ``z_k``, the same velocities and the spin rate of the shaft; the outputs the
generalized forces on the same position coordinates and ``phi_k``, and the friction power (last column).
The pass runs compiled (:mod:`.sheave_contact_refined_kernel`); the numpy formulas here are its tested twin.
Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.chain.sheave_contact import central_local_jacobian
from cvtfem.elements.chain.sheave_contact_refined_kernel import refined_local_kernel
from cvtfem.elements.chain.symmetric import END_SLOPE_FACTOR
from cvtfem.elements.contact.friction import _check, friction_force
from cvtfem.elements.contact.hertz import hertz_force, hertz_potential
from cvtfem.elements.contact.kernels import LAW_CODES
from cvtfem.elements.contact.meridian import Meridian
from cvtfem.errors import InputError, NumericalError

_SIDE = -1.0   # sheave material on the +k side of the x3 > 0 pin end (as SheaveContact)


def face_meridian(face: Sheave) -> Meridian:
    """The profile ``f = -s(r)`` of the face as a :class:`~cvtfem.elements.contact.meridian.Meridian` (kernels)."""
    if face.profile == "conical":
        return Meridian("cone", tan_gamma=float(np.tan(face.gamma)))
    return Meridian("torus", R=face.R, y=face.y)


def face_derivatives(face: Sheave, r):
    """``(f, f', f'', f''')`` (m, -, 1/m, 1/m^2) of the profile ``f = -s(r)`` of the face at radii ``r`` (m)."""
    r = np.asarray(r, float)
    f, fp, fpp = face_meridian(face)(r)
    if face.profile == "conical":
        return f, fp, fpp, np.zeros_like(r)
    u = r + face.y
    return f, fp, fpp, -3.0 * face.R ** 2 * u / (face.R ** 2 - u * u) ** 2.5


def _kx(v):
    """``k x v`` of in-plane vectors (m, 2)."""
    return np.stack([-v[:, 1], v[:, 0]], axis=1)


def _dot(a, b):
    return np.sum(a * b, axis=-1)


@dataclass(frozen=True)
class RefinedSheaveContact:
    """H2 contact of all pin ends with the sheaves of two shafts (0 driving, 1 driven).

    Attributes as :class:`~cvtfem.elements.chain.sheave_contact.SheaveContact` (``centres``, ``faces``,
    ``c``, ``r_outer``, ``f0``, ``v0``, ``law``, ``eps``), plus:

    face_radius : float, m
        Crown radius ``R_f`` of the pin end faces (both directions): the face is the graph
        ``z = tan(theta) xi_o + |xi|^2 / (2 R_f)`` over the pin section (``xi_o`` the outward radial coordinate).
    face_inclination : float, rad
        Angle ``theta`` of the face normal at the pin-axis end from the pin axis, tilted outward in the pin's
        radial plane (towards the sheave flank); 0: the symmetric crowned face (digest §5.4 [A]).  The chain
        runs counter-clockwise (the models' frame), so the outward direction is ``-n_perp = -k x tau_p``.
    im1, ip1 : (n,) int
        Previous and next pin of each pin (the chain's cyclic neighbours).
    slopes : bool
        The chain has the S3 slope coordinates ``u'_p`` (end slope ``END_SLOPE_FACTOR u'_p``).
    """

    centres: np.ndarray
    faces: tuple
    c: np.ndarray
    r_outer: float
    f0: float
    v0: float
    face_radius: float
    im1: np.ndarray
    ip1: np.ndarray
    slopes: bool = False
    law: str = "linear-saturated"
    eps: float = 0.1
    face_inclination: float = 0.0

    def __post_init__(self):
        if not self.r_outer > 0 or not self.v0 > 0 or self.f0 < 0:
            raise InputError("RefinedSheaveContact", (self.r_outer, self.f0, self.v0), "r_outer > 0, f0 >= 0, v0 > 0")
        if not self.face_radius > 0:
            raise InputError("face_radius", self.face_radius, "must be > 0 (crown radius of the pin end face, m)")
        if not 0.0 <= self.face_inclination < np.pi / 4:
            raise InputError("face_inclination", self.face_inclination, "must be in [0, pi/4) rad (angle of the pin "
                             "end face's normal from the pin axis, tilted towards the sheave flank)")
        object.__setattr__(self, "centres", np.asarray(self.centres, float).reshape(2, 2))
        object.__setattr__(self, "c", np.broadcast_to(np.asarray(self.c, float), (2,)).copy())
        _check(self.law, self.eps)
        object.__setattr__(self, "_meridians", np.stack([face_meridian(f).params for f in self.faces]))

    @property
    def face(self) -> np.ndarray:
        """The kernels' face constants ``(R_f (m), T)``: ``beta_phi = T n_perp`` in the mirrored frame, ``T =
        tan(theta)`` (outward ``-n_perp`` on a counter-clockwise chain, the face sloping like the sheave's
        ``f' < 0``)."""
        return np.array([float(self.face_radius), float(np.tan(self.face_inclination))])

    # ----- layout --------------------------------------------------------------------------------
    @property
    def n_pos(self) -> int:
        """Position inputs per contact: ``u`` of pins ``p-1, p, p+1``, ``u3_p``, [``u'_p``], ``z_k``."""
        return 8 + 2 * self.slopes

    @property
    def n_in(self) -> int:
        """Local inputs per contact: positions, their rates, the shaft spin rate."""
        return 2 * self.n_pos + 1

    @property
    def n_out(self) -> int:
        """Local outputs per contact: forces on the position coordinates, on ``phi_k``, friction power."""
        return self.n_pos + 2

    def coordinates(self, pins, shafts, dof_index, iz, iphi):
        """Global indices (m, n_pos + 1) of the position coordinates of each contact and of ``phi_k`` (last):
        the rows of its force outputs; ``dof_index`` (n, ndof) of the chain, ``iz``, ``iphi`` of the shafts."""
        cols = [dof_index[self.im1[pins], :2], dof_index[pins, :2], dof_index[self.ip1[pins], :2], dof_index[pins, 2:3]]
        if self.slopes:
            cols.append(dof_index[pins, 3:5])
        return np.column_stack(cols + [iz[shafts], iphi[shafts]])

    def extra_approach(self, k: int, r):
        """Penetration beyond H1's of an untilted pin end at radius ``r`` (m) on shaft ``k`` whose face turns with
        the arc: ``(f' + tan(theta))^2 / (2 m_e)`` (m)."""
        _, fp, fpp, _ = face_derivatives(self.faces[k], np.asarray(r, float))
        P = fp + np.tan(self.face_inclination)
        return P * P / (2.0 * (1.0 / self.face_radius - fpp))

    def candidates(self, u):
        """Broad phase: ``(pin, shaft)`` index arrays of the pin ends ``u`` (n, 2) within the outer radius."""
        d = u[:, None, :] - self.centres[None, :, :]
        return np.nonzero((d[..., 0] ** 2 + d[..., 1] ** 2) < self.r_outer ** 2)

    # ----- local evaluation ------------------------------------------------------------------------
    def _unpack(self, X):
        n = self.n_pos
        P, V = X[:, :n], X[:, n:2 * n]
        zero = np.zeros((len(X), 2))
        slope = END_SLOPE_FACTOR * P[:, 7:9] if self.slopes else zero
        dslope = END_SLOPE_FACTOR * V[:, 7:9] if self.slopes else zero
        return P[:, 0:2], P[:, 2:4], P[:, 4:6], P[:, 6], slope, P[:, -1], \
            V[:, 0:2], V[:, 2:4], V[:, 4:6], V[:, 6], dslope, V[:, -1], X[:, -1]

    def _profile(self, shafts, r):
        """``(f, f', f'', f''')`` per contact (one vectorised call per distinct face)."""
        out = [np.empty_like(r) for _ in range(4)]
        same = self.faces[0] == self.faces[1]
        for k in ((0,) if same else (0, 1)):
            sel = np.ones(len(r), bool) if same else shafts == k
            for o, val in zip(out, face_derivatives(self.faces[k], r[sel])):
                o[sel] = val
        return out

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Local outputs ``Y`` (m, n_out) of contacts with inputs ``X`` (m, n_in) on shafts ``shafts``:
        generalized forces (both pin ends, ``2x``) on the position coordinates of :meth:`coordinates` and
        on ``phi_k``, and the friction power ``2 F_fr . v_r`` (W, <= 0); with ``details`` also a dict of
        per-contact quantities (``delta``, ``N``, ``radius``, ``slip``, ``F_fr``, ``F`` the force on one pin
        end's translation, ``potential``, ``offset`` ``x_*``, ``point`` ``R_*``, ``moment`` the end moment
        on the slope ``gamma``).  Without ``details`` the compiled kernel runs; ``reference=True`` (or
        ``details``) the numpy formulas, its tested twin."""
        if not (details or reference):
            return self._compiled(X, shafts)
        s = _SIDE
        um, up_, un, u3, g, z, vm, vp, vn, u3d, gd, zd, w = self._unpack(X)
        m = len(X)
        d = up_ - self.centres[shafts]
        r = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2)
        if not np.all(r > 0):
            raise NumericalError("H2 contact: a pin end on the shaft axis", component="contact.refined")
        e = d / r[:, None]
        nu = _kx(e)
        # pin spin: bisector of the unit chords, omega_p and the twist map (1.349)/(1.116)
        cp, cn = up_ - um, un - up_
        lp, ln = np.sqrt(_dot(cp, cp)), np.sqrt(_dot(cn, cn))
        ep, en = cp / lp[:, None], cn / ln[:, None]
        xb = ep + en
        nx = np.sqrt(_dot(xb, xb))
        nperp = _kx(xb / nx[:, None])
        # d(phi)/d(u_{p+1} - u_p) = (E - en en) n / (|x| ln), likewise for the rear chord
        tp = (nperp - _dot(nperp, ep)[:, None] * ep) / (nx * lp)[:, None]
        tn = (nperp - _dot(nperp, en)[:, None] * en) / (nx * ln)[:, None]
        om_p = _dot(tp, vp - vm) + _dot(tn, vn - vp)
        f, fp, fpp, f3 = self._profile(shafts, r)
        Rf, T = self.face
        q = T * nperp                                                  # face slope beta_phi (mirrored frame)
        me, mn = 1.0 / Rf - fpp, 1.0 / Rf - fp / r     # B - A > 0: the sheave faces have f'' <= 0, f' < 0
        ge, gn = _dot(g, e), _dot(g, nu)
        qe, qn = _dot(q, e), _dot(q, nu)
        P, Pn = fp + s * ge - qe, s * gn - qn
        xe, xn = P / me, Pn / mn                                      # x_* = M^-1 (a_vec - b_vec)
        delta = s * (z - u3) + f + 0.5 * (P * xe + Pn * xn)
        # exact gradient of Delta: in-plane pin position d, slope g; u3 -> -s, z -> +s; pin spin T x_* . tau_p
        dd = (e * (fp + xe * fpp + 0.5 * xe ** 2 * f3 + 0.5 * xn ** 2 * (fpp / r - fp / r ** 2))[:, None]
              + nu * ((xe * Pn - xn * (s * ge - qe)) / r)[:, None])
        x = xe[:, None] * e + xn[:, None] * nu                        # offset x_* (in-plane, world)
        dg = s * x
        N, _ = hertz_force(delta, self.c[shafts])
        # contact point R_* and the refined normal (§5.3), world frame
        Ax = (fpp * xe)[:, None] * e + (fp / r * xn)[:, None] * nu
        gstar = fp[:, None] * e + Ax                                   # common slope g_* (mirrored frame)
        z_pul = s * z + f + _dot(fp[:, None] * e, x) + 0.5 * _dot(x, Ax)
        z_pin = s * u3 - s * _dot(g, x) + _dot(q, x) + 0.5 * _dot(x, x) / Rf
        point3 = 0.5 * s * (z_pul + z_pin)
        grad = np.column_stack([gstar, np.full(m, -s)])
        normal = -grad / np.linalg.norm(grad, axis=1, keepdims=True)
        rho = np.column_stack([x, point3 - u3])
        arm = np.column_stack([d + x, point3 - z])
        k = np.array([0.0, 0.0, 1.0])
        g3 = np.column_stack([g, np.zeros(m)])
        gd3 = np.column_stack([gd, np.zeros(m)])
        lever = np.cross(k + g3, rho)                                     # (k + gamma) x rho
        v_pin = np.column_stack([vp, u3d]) + np.cross(np.cross(k, gd3), rho) + om_p[:, None] * lever
        v_sh = np.column_stack([-w * arm[:, 1], w * arm[:, 0], zd])
        v_rel = v_pin - v_sh
        slip = v_rel - _dot(normal, v_rel)[:, None] * normal
        F_fr, _ = friction_force(slip, N, self.f0, self.v0, self.law, self.eps)
        # generalized forces of one end, then x2
        Q_phi = _dot(F_fr, lever) - N * T * _dot(x, xb) / nx           # on the pin spin: friction, turning face
        Q_slope = -N[:, None] * dg + np.cross(np.cross(rho, F_fr), k)[:, :2]
        F_pin = np.column_stack([-N[:, None] * dd + F_fr[:, :2], s * N + F_fr[:, 2]])
        Q_rear = -Q_phi[:, None] * tp
        Q_front = Q_phi[:, None] * tn
        Qz = -s * N - F_fr[:, 2]
        Qphi_k = -(arm[:, 0] * F_fr[:, 1] - arm[:, 1] * F_fr[:, 0])
        cols = [Q_rear, F_pin[:, :2] - Q_rear - Q_front, Q_front, F_pin[:, 2:3]]
        if self.slopes:
            cols.append(END_SLOPE_FACTOR * Q_slope)
        Y = 2 * np.column_stack(cols + [Qz, Qphi_k, _dot(F_fr, slip)])
        if not details:
            return Y
        radius = np.sqrt(_dot(arm[:, :2], arm[:, :2]))
        return Y, {"delta": delta, "N": N, "radius": radius, "slip": slip, "F_fr": F_fr, "F": F_pin,
                   "potential": 2 * hertz_potential(delta, self.c[shafts]), "offset": x,
                   "point": np.column_stack([up_ + x, point3]), "moment": Q_slope, "normal": normal,
                   "spin_rate": om_p}

    def _compiled(self, X, shafts):
        """:meth:`local` by :func:`refined_local_kernel`."""
        m = len(X)
        Y, slip, fr = np.empty((m, self.n_out)), np.empty((m, 3)), np.empty((m, 3))
        bad = refined_local_kernel(np.ascontiguousarray(X, float), np.ascontiguousarray(shafts, np.int64),
                                   self.centres, self._meridians, self.face, bool(self.slopes),
                                   END_SLOPE_FACTOR, self.c, float(self.f0), float(self.v0), LAW_CODES[self.law],
                                   float(self.eps), Y, slip, fr)
        if bad >= 0:
            raise NumericalError(f"H2 contact: a pin end on the shaft axis (contact {bad})", component="contact.refined")
        return Y

    def local_jacobian(self, X, shafts):
        """``dY/dX`` (m, n_out, n_in) by central differences (:func:`central_local_jacobian`)."""
        scale = np.full(self.n_in, 1e-6)                     # m/s and slope rates
        scale[:self.n_pos] = 1e-9                            # m (slopes: 1e-9 too)
        scale[-1] = 1e-5                                     # rad/s
        return central_local_jacobian(self.local, X, shafts, scale, self.n_out)

    def scatter(self, Y, pins, shafts, n):
        """Sum local outputs: generalized forces on the pin coordinates ``(n, 3 + 2 slopes)`` (``u``, ``u3``,
        ``u'``: the chain's ``dof_index`` columns), on ``z`` (2), on ``phi`` (2), and the friction power (W)."""
        Qp = np.zeros((n, 3 + 2 * self.slopes))
        for j, who in enumerate((self.im1[pins], pins, self.ip1[pins])):
            for i in range(2):
                Qp[:, i] += np.bincount(who, Y[:, 2 * j + i], n)
        Qp[:, 2] = np.bincount(pins, Y[:, 6], n)
        if self.slopes:
            Qp[:, 3] = np.bincount(pins, Y[:, 7], n)
            Qp[:, 4] = np.bincount(pins, Y[:, 8], n)
        return Qp, np.bincount(shafts, Y[:, -3], 2), np.bincount(shafts, Y[:, -2], 2), float(Y[:, -1].sum())
