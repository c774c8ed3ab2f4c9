"""Pin–sheave contact of a symmetric chain (S2, S3) with the rigid sheave pairs of two rigid shafts.

Contact H1 (contact-models digest §4) at the pin-axis end ``R = (u_perp, u3)`` of every pin with the
sheave on the ``x3 > 0`` side of each shaft (shafts-sheaves-supports §1, model 1: the sheave pair of
shaft ``k`` moves symmetrically, ``+-z_k``, and spins with ``phi_k``); the mirror contact at the
``x3 < 0`` end is implied (chain-models-1 §2.7: generalized forces ``2F``).  The sheave face is
``x3 = z_k + s(r)`` with ``s`` the band models' face (:class:`~cvtfem.elements.band.geometry.Sheave`,
conical or toroidal, ``z_k`` its reference position), so the penetration (1.321) is
``Delta = u3 - z_k - s(r)`` (sheave material at ``x3 > surface``, side ``-1`` of
:func:`~cvtfem.elements.contact.pin_axis.pin_axis_contact`).  Normal force: the exact gradient of the
Hertz potential ``2/5 c Delta^{5/2}``; friction: the regularised law of
:mod:`cvtfem.elements.contact.friction` on the slip of the pin end against the sheave material point.

Broad phase: a pin is a contact candidate of shaft ``k`` when its end lies within the sheave's
outer radius; the narrow phase is ``Delta > 0``.  Everything is vectorised over candidate contacts.
Units SI.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.band.geometry import Sheave
from cvtfem.elements.contact.friction import friction_force
from cvtfem.elements.contact.hertz import (compliance, hertz_force, hertz_potential, hertz_stiffness, normal_force,
                                           relative_curvature, sheave_curvatures)
from cvtfem.elements.contact.pin_axis import pin_axis_contact, pin_axis_slip
from cvtfem.elements.contact.sheave import sheave_generalized
from cvtfem.errors import InputError

#: Local inputs of one contact: pin end position (3), sheave position z, pin end velocity (3), z', spin rate.
N_IN = 9
#: Local outputs: generalized forces on the pin end (3, already x2), on z, on phi, and the friction power.
N_OUT = 6
_SIDE = -1.0   # sheave material on the +k side of the face (pin_axis_contact convention)


def face_profile(face: Sheave):
    """``f(r) = -s(r)`` of the face ``x3 = z + s(r)`` and its derivatives (m, -, 1/m), the profile
    convention of :func:`~cvtfem.elements.contact.pin_axis.pin_axis_contact` with side -1."""
    flat = Sheave(face.profile, face.gamma, face.R, face.y, 0.0)

    def profile(r):
        return flat.z0(r), -flat.tan_gamma(r), flat.d2z0(r)
    return profile


def hertz_constant(face: Sheave, r: float, face_radius: float, E: float, nu: float, inclination: float = 0.0) -> float:
    """Hertz stiffness ``c`` (N/m^1.5) of a pin end crowned with ``face_radius`` (m, both directions) on the
    face at radius ``r`` (m), steel on steel (``E`` Pa, ``nu``), held constant (digest §4.3).  A face inclined by
    ``inclination`` (rad; the graph ``z = tan(theta) xi_o + |xi|^2 / (2 R_f)`` of the H2 kernel) has the true
    curvatures ``cos^3(theta) / R_f`` (radial, with the sheave's meridian) and ``cos(theta) / R_f``."""
    g = float(np.arctan(face.tan_gamma(r)))
    fp, fpp = -np.tan(g), float(face.d2z0(r))
    k_mer, k_circ = sheave_curvatures(r, fp, fpp)
    ci = np.cos(inclination)
    pin = np.diag([ci / face_radius, ci ** 3 / face_radius])[None]
    sheave = np.diag([float(k_circ), float(k_mer)])[None]
    sum_k, omega = relative_curvature(pin, sheave)
    return float(hertz_stiffness(sum_k, omega, compliance(E, nu, E, nu))[0])


@dataclass(frozen=True)
class SheaveContact:
    """H1 contact of all pin ends with the sheaves of two shafts (0 driving, 1 driven).

    Attributes
    ----------
    centres : (2, 2) m
        In-plane positions of the shaft axes.
    faces : (Sheave, Sheave)
        Face of each shaft's sheaves (mirror images about ``x3 = 0``).
    c : (2,) N/m^1.5
        Hertz stiffness per shaft.
    r_outer : float, m
        Outer radius of the sheaves (broad phase).
    f0, v0 : float
        Friction coefficient and saturation slip speed (m/s); ``law``, ``eps`` as in
        :func:`~cvtfem.elements.contact.friction.friction_force`.
    """

    centres: np.ndarray
    faces: tuple
    c: np.ndarray
    r_outer: float
    f0: float
    v0: float
    law: str = "linear-saturated"
    eps: float = 0.1

    def __post_init__(self):
        if not self.r_outer > 0 or not self.v0 > 0 or self.f0 < 0:
            raise InputError("SheaveContact", (self.r_outer, self.f0, self.v0), "r_outer > 0, f0 >= 0, v0 > 0")
        object.__setattr__(self, "centres", np.asarray(self.centres, float).reshape(2, 2))
        object.__setattr__(self, "c", np.broadcast_to(np.asarray(self.c, float), (2,)).copy())
        object.__setattr__(self, "_profiles", tuple(face_profile(f) for f in self.faces))

    def candidates(self, u):
        """Broad phase: ``(pin, shaft)`` index arrays of the pin ends ``u`` (n, 2) within the outer radius."""
        d = u[:, None, :] - self.centres[None, :, :]
        near = (d[..., 0] ** 2 + d[..., 1] ** 2) < self.r_outer ** 2
        pins, shafts = np.nonzero(near)
        return pins, shafts

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Local outputs ``Y`` (m, 6) of contacts with inputs ``X`` on shafts ``shafts``: ``2F`` on the pin end
        (N), the generalized forces on ``z`` (N) and ``phi`` (N m) of the shaft, and the friction power
        ``2 F_fr . v_slip`` (W, <= 0); with ``details`` also a dict of per-contact quantities.

        The untilted sheaves of model 1 get the closed forms of the H1 primitives at zero tilt;
        ``reference=True`` calls the primitives themselves (pin_axis_contact, pin_axis_slip,
        sheave_generalized: the tested reference, equal to round-off)."""
        m = len(X)
        arm = X[:, :3].copy()
        arm[:, :2] -= self.centres[shafts]
        arm[:, 2] -= X[:, 3]
        vc = np.zeros((m, 3))
        vc[:, 2] = X[:, 7]
        omega = np.zeros((m, 3))
        omega[:, 2] = X[:, 8]
        same = self.faces[0] == self.faces[1]
        delta, grad, normal, radius = np.zeros(m), np.zeros((m, 3)), np.zeros((m, 3)), np.zeros(m)
        for k in ((0,) if same else (0, 1)):  # one vectorised call per distinct face
            sel = np.ones(m, bool) if same else shafts == k
            if not sel.any():
                continue
            if reference:
                con = pin_axis_contact(arm[sel], np.zeros((sel.sum(), 3)), np.zeros((sel.sum(), 3)),
                                       self._profiles[k], _SIDE)
                delta[sel], grad[sel], normal[sel], radius[sel] = con.delta, con.grad, con.normal, con.radius
            else:                                   # (1.317)-(1.321) at zero tilt, side -1
                a = arm[sel]
                r = np.hypot(a[:, 0], a[:, 1])
                f, fp, _ = self._profiles[k](r)
                g = np.empty_like(a)
                g[:, :2] = (fp / r)[:, None] * a[:, :2]
                g[:, 2] = 1.0
                delta[sel], grad[sel], radius[sel] = f + a[:, 2], g, r
                normal[sel] = -g / np.sqrt(1.0 + fp * fp)[:, None]
        N, _ = hertz_force(delta, self.c[shafts])
        if reference:
            slip = pin_axis_slip(_Geometry(normal, arm), X[:, 4:7], vc, omega)
        else:
            w = X[:, 4:7] - vc
            w[:, 0] += X[:, 8] * arm[:, 1]                      # - omega k x arm
            w[:, 1] -= X[:, 8] * arm[:, 0]
            slip = w - np.sum(normal * w, axis=1, keepdims=True) * normal
        F_fr, _ = friction_force(slip, N, self.f0, self.v0, self.law, self.eps)
        F = normal_force(grad, N) + F_fr
        if reference:
            F_sheave, _, Q_phi = sheave_generalized(F, arm, np.zeros((m, 3)))
            Fz = F_sheave[:, 2]
        else:
            Fz, Q_phi = -F[:, 2], arm[:, 1] * F[:, 0] - arm[:, 0] * F[:, 1]    # k . (-(arm x F))
        Y = np.column_stack([2 * F, 2 * Fz, 2 * Q_phi, 2 * np.sum(F_fr * slip, axis=1)])
        if not details:
            return Y
        return Y, {"delta": delta, "N": N, "radius": radius, "slip": slip, "F_fr": F_fr, "F": F,
                   "potential": 2 * hertz_potential(delta, self.c[shafts])}

    def local_jacobian(self, X, shafts):
        """``dY/dX`` (m, 6, 9) by central differences (:func:`central_local_jacobian`)."""
        return central_local_jacobian(self.local, X, shafts, np.array([1e-9] * 4 + [1e-6] * 4 + [1e-5]), N_OUT)


def central_local_jacobian(local, X, shafts, scale, n_out: int):
    """``dY/dX`` (m, n_out, n_in) of ``local(X, shafts)`` by central differences with steps ``scale`` (one per
    input: m, m/s, rad/s), all contacts at once: each contact depends only on its own inputs, so one
    perturbation per input column serves all contacts."""
    J = np.empty((len(X), n_out, X.shape[1]))
    for j in range(X.shape[1]):
        Xp, Xm = X.copy(), X.copy()
        Xp[:, j] += scale[j]
        Xm[:, j] -= scale[j]
        J[:, :, j] = (local(Xp, shafts) - local(Xm, shafts)) / (2 * scale[j])
    return J


@dataclass(frozen=True)
class _Geometry:
    """The two fields of a contact geometry :func:`pin_axis_slip` reads."""

    normal: np.ndarray
    arm: np.ndarray
