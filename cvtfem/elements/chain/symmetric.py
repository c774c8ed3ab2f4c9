"""Symmetric chain models S1, S2, S3 as vectorised families (spec chain-models-1 §2, §3, §8).

Coordinates, in block order (pin ``p`` = row ``p`` of each block):

* ``u_perp`` (n, 2) m: in-plane position of the pin-axis end at ``x3 > 0`` (eq. 1.64), all models;
* ``u_axial`` (n,) m: its axial coordinate ``u_{p,3}`` (S2, S3; S1 keeps ``l/2``, a free span);
* ``u_tangent`` (n, 2) -: the S3 bending coordinate ``u'_p`` (half the end slope, eq. 1.96).

The mass matrix couples only the coordinates of one pin.  Equations of motion
``M q'' = Q(q, q') + Q_ext`` (§1.3) with ``Q = -dPi/dq - dPhi/dq'``.  Every kernel is a function of
link differences built with cyclic index arrays (no loop over pins) and accepts complex states, which the
Jacobian uses (complex-step differentiation over a pin colouring, exact to round-off, §8.4).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from cvtfem.elements.base import Block
from cvtfem.elements.chain.geometry import ChainGeometry, h1
from cvtfem.errors import InputError
from cvtfem.outputs import OutputSpec

#: End slope of an S3 pin = END_SLOPE_FACTOR * u'_p (§3.2, §3.8); 1 reproduces the printed (1.117).
END_SLOPE_FACTOR = 2.0


_KX = np.array([-1.0, 1.0])


def _kx(v):
    """``k x v`` for in-plane vectors, (n, 2)."""
    return v[:, ::-1] * _KX


def _dot(a, b):
    """Row-wise dot product of (n, 2) arrays."""
    return (a * b).sum(axis=1)


@dataclass(frozen=True)
class ChainDamping:
    """Damping parameters: ``b = beta c`` per link and pin, joint damping ``b_joint`` (§2.6, §3.7).

    Attributes
    ----------
    beta_link : s
        Link (plate tension) damping, ``b_{p,p+1} = beta_link c_{p,p+1}`` (1.79, 1.113).
    beta_pin : s
        Pin axial damping ``b_p = beta_pin c_p`` (1.85), S2/S3.
    b_joint : N m s
        Damping of the relative rotation of adjacent links (1.80), a fitting parameter.
    beta_bend : s
        Co-rotational pin bending damping (1.114), S3.
    """

    beta_link: float = 0.0
    beta_pin: float = 0.0
    b_joint: float = 0.0
    beta_bend: float = 0.0


def damping_from_ratio(geom: ChainGeometry, nu: float, b_joint: float = 0.0) -> ChainDamping:
    """``beta = 2 nu / k`` (1.86) with ``k`` the link (``sqrt(2 c / m)``), pin axial (``sqrt(12 c_p / m)``)
    and single-pin bending (``sqrt(720 A / (m l^3))``, §8.5) frequencies of the stiffest, lightest pin."""
    if not 0.0 <= nu < 1.0:
        raise InputError("damping_from_ratio.nu", nu, "0 <= nu < 1")
    m = geom.m_eff.min()
    a = max(geom.A_tau, geom.A_n)
    return ChainDamping(beta_link=float(2 * nu / np.sqrt(2 * geom.c_link.max() / m)),
                        beta_pin=float(2 * nu / np.sqrt(12 * geom.c_pin.max() / m)), b_joint=b_joint,
                        beta_bend=float(2 * nu / np.sqrt(720 * a / (m * geom.l ** 3))) if a > 0 else 0.0)


class SymmetricChain:
    """What S1, S2 and S3 share: layout, link stretch, joint damping, mass solve, Jacobian, loads.

    Parameters
    ----------
    geom : ChainGeometry
    damping : ChainDamping
    name : str
        Prefix of block and output names.
    """

    kind = ""
    ndof = 2   # coordinates per pin

    def __init__(self, geom: ChainGeometry, damping: ChainDamping = ChainDamping(), name: str = "chain"):
        self.geom, self.damping, self.name = geom, damping, name
        n = geom.n
        self.n = n
        self.L = np.asarray(geom.L, float)
        self.on = geom.link_on
        self.iL = self.on / self.L                       # 1/L of existing links, 0 for an absent one
        self.iLm = np.roll(self.iL, 1)                   # the same for link p-1
        self.m = geom.m_eff
        self.c = geom.c_link
        self.b = damping.beta_link * self.c
        self.ip1, self.im1 = (np.arange(n) + 1) % n, (np.arange(n) - 1) % n
        self.bj = damping.b_joint * self.on * np.roll(self.on, 1)   # joint p between links p-1 and p
        self.size = self.ndof * n
        self.dof_index = self._dof_index()
        self._pattern()
        self.M = None

    # ----- layout ---------------------------------------------------------------------------------
    @property
    def blocks(self) -> tuple[Block, ...]:
        """State blocks (coordinates; velocities carry unit/s)."""
        n, b = self.n, [Block(f"{self.name}.u_perp", 2 * self.n, "m")]
        if self.ndof >= 3:
            b.append(Block(f"{self.name}.u_axial", n, "m"))
        if self.ndof == 5:
            b.append(Block(f"{self.name}.u_tangent", 2 * n, "-"))
        return tuple(b)

    def _dof_index(self) -> np.ndarray:
        """Global index of local coordinate ``j`` of pin ``p``, (n, ndof): u1, u2, [u3, [u'1, u'2]]."""
        n, p = self.n, np.arange(self.n)
        cols = [2 * p, 2 * p + 1, 2 * n + p, 3 * n + 2 * p, 3 * n + 2 * p + 1]
        return np.stack(cols[:self.ndof], axis=1)

    def split(self, q):
        """Views ``u`` (n, 2), ``u3`` (n,), ``up`` (n, 2) of a coordinate (or velocity) vector;
        S1: ``u3 = None``, S1/S2: ``up = None``."""
        n = self.n
        u = q[:2 * n].reshape(n, 2)
        u3 = q[2 * n:3 * n] if self.ndof >= 3 else None
        up = q[3 * n:].reshape(n, 2) if self.ndof == 5 else None
        return u, u3, up

    def join(self, u, u3=None, up=None) -> np.ndarray:
        """Coordinate vector from its parts (inverse of :meth:`split`)."""
        parts = [np.ravel(u)] + ([np.ravel(u3)] if self.ndof >= 3 else []) + ([np.ravel(up)] if self.ndof == 5 else [])
        return np.concatenate(parts)

    # ----- shared kernels -------------------------------------------------------------------------
    def _rear_front(self, f):
        """Pin forces from link forces ``f`` on their rear pin (front pin gets ``-f``), (n, ...)."""
        return f - f[self.im1]

    def _links(self, u):
        """Link direction ``tt`` (1.74), ``tt.tt`` and stretch ``Delta`` (1.76), m."""
        tt = (u[self.ip1] - u) / self.L[:, None]
        tt2 = _dot(tt, tt)
        return tt, tt2, 0.5 * self.L * (tt2 - 1.0)

    def _joint_rates(self, tt, tt2, dd):
        """``W`` of §2.8 (1/m) and the link angular rates ``omega_{p,p+1}`` (1.82), rad/s."""
        W = _kx(tt) / (self.L * tt2)[:, None]
        return W, _dot(W, dd)

    def _joint_forces(self, W, om):
        """Exact joint damping force ``-dPhi_joints/du'_perp`` (§2.8), (n, 2) N."""
        mu = self.bj * (om - om[self.im1])
        return self._rear_front((mu - mu[self.ip1])[:, None] * W)

    def _joint_rayleigh(self, om):
        """``Phi_joints`` (1.80), W."""
        return 0.5 * (self.bj * (om - om[self.im1]) ** 2).sum()

    def _kernel(self, q, qd, elastic: bool, dissipative: bool):
        raise NotImplementedError

    # ----- public physics -------------------------------------------------------------------------
    def forces(self, q, qd):
        """``Q = -dPi/dq - dPhi/dq'`` (elastic plus dissipative), N."""
        return self._kernel(q, qd, True, True)

    def elastic_forces(self, q):
        """``Q^Pi = -dPi/dq``, N."""
        return self._kernel(q, np.zeros_like(q), True, False)

    def dissipative_forces(self, q, qd):
        """``Q^d = -dPhi/dq'``, N."""
        return self._kernel(q, qd, False, True)

    def energy(self, q, qd) -> float:
        """Kinetic plus potential energy ``T + Pi``, J."""
        return self.kinetic_energy(qd) + self.potential_energy(q)

    def kinetic_energy(self, qd) -> float:
        """``T = qd . M qd / 2``, J (1.67, 1.69, 1.101)."""
        if self.M is None:
            self.M = self.mass_matrix()
        return 0.5 * float(qd @ (self.M @ qd))

    def solve_mass(self, f):
        """``M^-1 f`` per pin, closed form (§8.3)."""
        raise NotImplementedError

    def external_forces(self, F, M=None):
        """Generalized forces of mirror-symmetric end loads (1.87)-(1.88), (1.117).

        ``F`` (n, 3) N: force on the ``x3 > 0`` end (its mirror acts on the other end): ``2 F_perp`` on
        ``u_perp``, ``2 F_3`` on ``u3`` (S1 on a free span: no axial coordinate, ``F_3`` does no work).
        ``M`` (n, 2) N m (S3): in-plane end moment on both ends; work ``2 M . d(theta_end)`` with the end
        rotation ``theta_end = END_SLOPE_FACTOR k x u'`` gives ``2 END_SLOPE_FACTOR M x k`` on ``u'``.
        """
        F = np.asarray(F, float)
        Q = np.zeros(self.size)
        u, u3, up = self.split(Q)
        u[:] = 2 * F[:, :2]
        if u3 is not None:
            u3[:] = 2 * F[:, 2]
        if M is not None:
            if up is None:
                raise InputError(f"{self.kind}.external_forces.M", "end moments", "only S3 pins take end moments")
            M = np.asarray(M, float)
            up[:] = 2 * END_SLOPE_FACTOR * np.stack([M[:, 1], -M[:, 0]], axis=1)
        return Q

    # ----- Jacobian -------------------------------------------------------------------------------
    def _pattern(self):
        """Sparsity of ``dQ/dq`` and ``dQ/dq'``: all coordinates of pins ``p-2..p+2`` (cyclic, §8.4)."""
        n, nd = self.n, self.ndof
        reach = min(2, n // 2)
        pins = np.arange(n)
        r_pin = np.repeat(pins, 2 * reach + 1)
        s_pin = (r_pin + np.tile(np.arange(-reach, reach + 1), n)) % n
        pairs = np.unique(np.stack([r_pin, s_pin], axis=1), axis=0)
        a, b = np.meshgrid(np.arange(nd), np.arange(nd), indexing="ij")
        rows = self.dof_index[pairs[:, 0]][:, a.ravel()].ravel()
        cols = self.dof_index[pairs[:, 1]][:, b.ravel()].ravel()
        k = next((k for k in range(5, n + 1) if n % k == 0 or n % k >= 5), n)   # pins >= 5 apart share a colour
        pin_of = np.empty(self.size, int)
        kind_of = np.empty(self.size, int)
        pin_of[self.dof_index] = pins[:, None]
        kind_of[self.dof_index] = np.arange(nd)[None, :]
        key = (pin_of[cols] % k) * nd + kind_of[cols]
        order = np.argsort(key, kind="stable")
        self._rows, self._cols, self._key = rows[order], cols[order], key[order]
        self._seeds = [(c, j) for c in range(k) for j in range(nd)]
        self._pin_of, self._kind_of, self._ncolour = pin_of, kind_of, k
        self.jac_sparsity = sp.csr_matrix((np.ones(len(rows), bool), (rows, cols)), shape=(self.size, self.size))

    def jacobian(self, q, qd, part: str = "all", wrt: tuple = (0, 1)):
        """``(dQ/dq, dQ/dq')`` as CSR matrices (complex step over ``5..9`` pin colours: ``2 ndof k``
        complex force evaluations, exact to round-off); ``part="dissipative"``: of ``Q^d`` alone;
        ``wrt=(0,)`` / ``(1,)``: only ``dQ/dq`` / ``dQ/dq'``."""
        h = 1e-30
        forces = {"all": self.forces, "dissipative": self.dissipative_forces}[part]
        out = []
        for k in wrt:
            data = np.empty(len(self._rows))
            start = 0
            for key, (c, j) in enumerate(self._seeds):
                e = ((self._pin_of % self._ncolour == c) & (self._kind_of == j)) * (1j * h)
                Qi = forces(q + e, qd).imag if k == 0 else forces(q, qd + e).imag
                stop = np.searchsorted(self._key, key, side="right")
                data[start:stop] = Qi[self._rows[start:stop]] / h
                start = stop
            out.append(sp.csr_matrix((data, (self._rows, self._cols)), shape=(self.size, self.size)))
        return tuple(out)

    # ----- outputs --------------------------------------------------------------------------------
    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        n, p = self.n, self.name
        specs = [OutputSpec(f"{p}.link_tension", "N", "Link tension N, elastic plus damping part (one per link).", n),
                 OutputSpec(f"{p}.link_tension_elastic", "N", "Elastic part of the link tension (one per link).", n),
                 OutputSpec(f"{p}.joint_rate", "rad/s", "Relative rotation rate of adjacent links at each pin.", n)]
        if self.ndof >= 3:
            specs.append(OutputSpec(f"{p}.pin_axial_force", "N",
                                    "Pin axial force c_p Delta_p + b_p Delta_p' (negative: compression).", n))
        return tuple(specs)

    def _common_outputs(self, q, qd, N_el, N_d):
        u, u3, _ = self.split(q)
        ud, u3d, _ = self.split(qd)
        tt, tt2, _ = self._links(u)
        dd = ud[self.ip1] - ud
        _, om = self._joint_rates(tt, tt2, dd)
        out = {f"{self.name}.link_tension": (N_el + N_d) * self.on, f"{self.name}.link_tension_elastic": N_el * self.on,
               f"{self.name}.joint_rate": (om - om[self.im1]) * self.on * np.roll(self.on, 1)}
        if u3 is not None:
            out[f"{self.name}.pin_axial_force"] = (self.geom.c_pin * (2 * u3 - self.geom.l)
                                                   + self.damping.beta_pin * self.geom.c_pin * 2 * u3d)
        return out


class ChainS1(SymmetricChain):
    """S1 (§2): 2 coordinates per pin, mass lumped at the pin middle, rigid straight pins at
    ``u3 = l/2`` (free span), links as springs with damping, joint damping."""

    kind = "chain-S1"
    ndof = 2

    def _kernel(self, q, qd, elastic, dissipative):
        u, _, _ = self.split(q)
        ud, _, _ = self.split(qd)
        tt, tt2, D = self._links(u)
        dd = ud[self.ip1] - ud
        N = (self.c * D if elastic else 0.0) + (self.b * _dot(tt, dd) if dissipative else 0.0)   # (1.92)
        Q = self._rear_front(N[:, None] * tt)
        if dissipative:
            Q = Q + self._joint_forces(*self._joint_rates(tt, tt2, dd))
        return self._axial(Q, q, qd, elastic, dissipative)

    def _axial(self, Qu, q, qd, elastic, dissipative):
        """Generalized force vector from the in-plane part (S1: no axial coordinate)."""
        return Qu.ravel()

    def potential_energy(self, q) -> float:
        """``Pi = sum c Delta^2 / 2`` (1.77), J."""
        _, _, D = self._links(self.split(q)[0])
        return 0.5 * float((self.c * D ** 2).sum())

    def rayleigh(self, q, qd) -> float:
        """``Phi = Phi_links + Phi_joints`` (1.78)-(1.83), W."""
        u, ud = self.split(q)[0], self.split(qd)[0]
        tt, tt2, _ = self._links(u)
        dd = ud[self.ip1] - ud
        _, om = self._joint_rates(tt, tt2, dd)
        return 0.5 * float((self.b * _dot(tt, dd) ** 2).sum()) + self._joint_rayleigh(om)

    def mass_matrix(self) -> sp.csr_matrix:
        """``M = diag(m_p, m_p)`` per pin (1.67), kg."""
        return sp.diags(np.repeat(self.m, 2)).tocsr()

    def solve_mass(self, f):
        return f / np.repeat(self.m, 2)

    def linear_momentum(self, qd):
        """In-plane momentum ``sum m u'_perp``, kg m/s, (2,)."""
        return (self.m[:, None] * self.split(qd)[0]).sum(axis=0)

    def angular_momentum(self, q, qd) -> float:
        """Angular momentum about ``k`` through the origin, kg m^2/s."""
        u, ud = self.split(q)[0], self.split(qd)[0]
        return float((self.m * (u[:, 0] * ud[:, 1] - u[:, 1] * ud[:, 0])).sum())

    def outputs(self, q, qd) -> dict[str, np.ndarray]:
        """Named outputs (:attr:`output_specs`)."""
        u, ud = self.split(q)[0], self.split(qd)[0]
        tt, _, D = self._links(u)
        return self._common_outputs(q, qd, self.c * D, self.b * _dot(tt, ud[self.ip1] - ud))


class ChainS2(ChainS1):
    """S2 (§2): S1 plus the independent axial coordinate ``u3`` with uniform mass along the pin,
    axial spring ``c_p`` and dashpot ``b_p`` (1.69, 1.71, 1.85)."""

    kind = "chain-S2"
    ndof = 3

    def _axial(self, Qu, q, qd, elastic, dissipative):
        u3, u3d = self.split(q)[1], self.split(qd)[1]
        cp, bp = self.geom.c_pin, self.damping.beta_pin * self.geom.c_pin
        Q3 = (-2 * cp * (2 * u3 - self.geom.l) if elastic else 0.0) - (4 * bp * u3d if dissipative else 0.0)
        return np.concatenate([Qu.ravel(), np.broadcast_to(Q3, (self.n,))])

    def potential_energy(self, q) -> float:
        """``Pi = Pi_links + sum c_p Delta_p^2 / 2`` (1.70), (1.71), J."""
        u3 = self.split(q)[1]
        return super().potential_energy(q) + 0.5 * float((self.geom.c_pin * (2 * u3 - self.geom.l) ** 2).sum())

    def rayleigh(self, q, qd) -> float:
        """``Phi = Phi_links + Phi_joints + Phi_pins`` (1.84)-(1.85), W."""
        u3d = self.split(qd)[1]
        return super().rayleigh(q, qd) + 0.5 * float((self.damping.beta_pin * self.geom.c_pin * (2 * u3d) ** 2).sum())

    def mass_matrix(self) -> sp.csr_matrix:
        """``diag(m_p, m_p | m_p / 3)`` (1.69), kg."""
        return sp.diags(np.concatenate([np.repeat(self.m, 2), self.m / 3])).tocsr()

    def solve_mass(self, f):
        return f / np.concatenate([np.repeat(self.m, 2), self.m / 3])


class ChainS3(SymmetricChain):
    """S3 (§3): S2 plus parabolic pin bending ``u'_p`` (5 coordinates per pin), orthotropic bending
    stiffness oriented by the link bisector, per-plate strains ``Delta + h1(xi^k) Delta'`` homogenised
    into ``c, c', c''``, stiffness-proportional link and co-rotational bending damping."""

    kind = "chain-S3"
    ndof = 5

    def __init__(self, geom: ChainGeometry, damping: ChainDamping = ChainDamping(), name: str = "chain"):
        super().__init__(geom, damping, name)
        self.c1, self.c2 = geom.c1_link, geom.c2_link
        self.cp, self.bp = geom.c_pin, damping.beta_pin * geom.c_pin

    def _bisector(self, tt):
        """Pin section axes ``tau_p``, ``n_p`` and ``|x_p|`` of ``x_p = tt_{p-1,p} + tt_{p,p+1}`` (1.103)."""
        t = tt * self.on[:, None]
        x = t[self.im1] + t
        nx = np.sqrt(_dot(x, x))
        tau = x / nx[:, None]
        return tau, _kx(tau), nx

    def _scatter_orientation(self, v):
        """Forces on pins ``p-1, p, p+1`` from ``v_p = dPi_p/dx_p`` (corrected 1.121/1.127 stencil), (n, 2)."""
        iL, iLm = self.iL[:, None], self.iLm[:, None]
        return -v[self.im1] * iLm + (iL - iLm) * v + v[self.ip1] * iL

    def _ahat(self, tau, nv, y):
        """``a_hat . y = A_tau (tau.y) tau + A_n (n.y) n`` (1.104, §3.5), per pin."""
        return self.geom.A_tau * _dot(tau, y)[:, None] * tau + self.geom.A_n * _dot(nv, y)[:, None] * nv

    def _strains(self, q, qd):
        """Link quantities shared by forces, energies and outputs."""
        u, u3, up = self.split(q)
        ud, u3d, upd = self.split(qd)
        tt, tt2, D = self._links(u)
        dp = up[self.ip1] - up
        ttp = dp / self.L[:, None]                                     # tilde tau' (1.107)
        dd = ud[self.ip1] - ud
        dpd = upd[self.ip1] - upd
        Dp = _dot(tt, dp)                                              # Delta' (1.107)
        Dd = _dot(tt, dd)                                              # (1.81)
        Dpd = _dot(tt, dpd) + _dot(ttp, dd)                            # (1.129)
        return u, u3, up, ud, u3d, upd, tt, tt2, D, ttp, dd, Dp, Dd, Dpd

    def _spin(self, tt, dd, nv, nx):
        """Pin spin rate ``omega_p = n_p . x_p' / |x_p|`` (1.116), rad/s."""
        t = (dd / self.L[:, None]) * self.on[:, None]
        return _dot(nv, t[self.im1] + t) / nx

    def _kernel(self, q, qd, elastic, dissipative):
        u, u3, up, ud, u3d, upd, tt, tt2, D, ttp, dd, Dp, Dd, Dpd = self._strains(q, qd)
        tau, nv, nx = self._bisector(tt)
        l, beta = self.geom.l, self.damping.beta_link
        N = np.zeros_like(D)
        Np = np.zeros_like(D)
        Qu = np.zeros_like(u)
        Qp = np.zeros_like(up)
        Q3 = np.zeros_like(u3)
        dA = self.geom.A_tau - self.geom.A_n
        if elastic:
            N = N + self.c * D + self.c1 * Dp                        # (1.123)
            Np = Np + self.c1 * D + self.c2 * Dp
            v = (16 * dA / l) * (_dot(nv, up) * _dot(tau, up) / nx)[:, None] * nv
            Qu = Qu + self._scatter_orientation(v)                   # (1.121)
            Qp = Qp - (16 / l) * self._ahat(tau, nv, up)              # (1.122)
            Q3 = Q3 - 2 * self.cp * (2 * u3 - l)                     # (1.124)
        if dissipative:
            N = N + beta * (self.c * Dd + self.c1 * Dpd)             # (1.130)
            Np = Np + beta * (self.c1 * Dd + self.c2 * Dpd)
            Qu = Qu + self._joint_forces(*self._joint_rates(tt, tt2, dd))
            om = self._spin(tt, dd, nv, nx)
            unabla = upd - om[:, None] * _kx(up)                     # (1.114)
            a_un = self._ahat(tau, nv, unabla)
            w = (-16 * self.damping.beta_bend / l) * (_dot(_kx(up), a_un) / nx)[:, None] * nv   # (1.126)
            Qu = Qu + self._scatter_orientation(w)                   # corrected (1.127)
            Qp = Qp - (16 * self.damping.beta_bend / l) * a_un       # (1.128)
            Q3 = Q3 - 4 * self.bp * u3d                              # (1.131)
        Qu = Qu + self._rear_front(N[:, None] * tt + Np[:, None] * ttp)
        Qp = Qp + self._rear_front(Np[:, None] * tt)
        return np.concatenate([Qu.ravel(), Q3, Qp.ravel()])

    def potential_energy(self, q) -> float:
        """``Pi = Pi_links (1.108) + Pi_bend (1.106) + Pi_ext (1.71)``, J."""
        z = np.zeros_like(q)
        u, u3, up, _, _, _, tt, _, D, _, _, Dp, _, _ = self._strains(q, z)
        tau, nv, _ = self._bisector(tt)
        links = 0.5 * (self.c * D ** 2 + 2 * self.c1 * D * Dp + self.c2 * Dp ** 2).sum()
        bend = (8 / self.geom.l) * _dot(up, self._ahat(tau, nv, up)).sum()
        return float(links + bend + 0.5 * (self.cp * (2 * u3 - self.geom.l) ** 2).sum())

    def rayleigh(self, q, qd) -> float:
        """``Phi`` of (1.112)-(1.114) with the joint term (1.80), W."""
        u, u3, up, ud, u3d, upd, tt, tt2, D, ttp, dd, Dp, Dd, Dpd = self._strains(q, qd)
        tau, nv, nx = self._bisector(tt)
        links = 0.5 * self.damping.beta_link * (self.c * Dd ** 2 + 2 * self.c1 * Dd * Dpd + self.c2 * Dpd ** 2).sum()
        unabla = upd - self._spin(tt, dd, nv, nx)[:, None] * _kx(up)
        bend = (8 / self.geom.l) * self.damping.beta_bend * _dot(unabla, self._ahat(tau, nv, unabla)).sum()
        _, om = self._joint_rates(tt, tt2, dd)
        return float(links + bend + 0.5 * (self.bp * (2 * u3d) ** 2).sum()) + self._joint_rayleigh(om)

    def mass_matrix(self) -> sp.csr_matrix:
        """Per pin ``m [[I, -l/3 I, 0], [-l/3 I, 2 l^2/15 I, 0], [0, 0, 1/3]]`` (1.101), kg (kg m, kg m^2)."""
        m, l, n = self.m, self.geom.l, self.n
        i = self.dof_index
        rows = [i[:, 0], i[:, 1], i[:, 2], i[:, 3], i[:, 4], i[:, 0], i[:, 3], i[:, 1], i[:, 4]]
        cols = [i[:, 0], i[:, 1], i[:, 2], i[:, 3], i[:, 4], i[:, 3], i[:, 0], i[:, 4], i[:, 1]]
        vals = [m, m, m / 3, 2 * l ** 2 / 15 * m, 2 * l ** 2 / 15 * m] + [-l / 3 * m] * 4
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(5 * n, 5 * n))

    def solve_mass(self, f):
        """Closed-form inverse of the 2x2 coupling block (§3.4)."""
        fu, f3, fp = self.split(f)
        l, m = self.geom.l, self.m[:, None]
        au = (6 * fu + (15 / l) * fp) / m
        ap = ((15 / l) * fu + (45 / l ** 2) * fp) / m
        return np.concatenate([au.ravel(), 3 * f3 / self.m, ap.ravel()])

    def linear_momentum(self, qd):
        """In-plane momentum ``sum m (u'_perp - l/3 u'')``, kg m/s, (2,)."""
        ud, _, upd = self.split(qd)
        return (self.m[:, None] * (ud - self.geom.l / 3 * upd)).sum(axis=0)

    def angular_momentum(self, q, qd) -> float:
        """Angular momentum about ``k`` through the origin of the pins' distributed mass, kg m^2/s."""
        u, _, up = self.split(q)
        ud, _, upd = self.split(qd)
        l = self.geom.l

        def cross(a, b):
            return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        return float((self.m * (cross(u, ud) - l / 3 * (cross(u, upd) + cross(up, ud))
                                 + 2 * l ** 2 / 15 * cross(up, upd))).sum())

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        n, p, k = self.n, self.name, self.geom.xi.shape[1]
        return super().output_specs + (
            OutputSpec(f"{p}.plate_tension", "N",
                       "Plate tension c^k (Delta + h1 Delta') + damping part, link-major (0 for absent plates).", n * k),
            OutputSpec(f"{p}.pin_bending_moment", "N m",
                       "Pin bending moment a . kappa, components along tau_p and n_p, pin-major.", 2 * n))

    def outputs(self, q, qd) -> dict[str, np.ndarray]:
        """Named outputs (:attr:`output_specs`); §7."""
        u, u3, up, ud, u3d, upd, tt, tt2, D, ttp, dd, Dp, Dd, Dpd = self._strains(q, qd)
        beta = self.damping.beta_link
        N_el = self.c * D + self.c1 * Dp
        out = self._common_outputs(q, qd, N_el, beta * (self.c * Dd + self.c1 * Dpd))
        hk = h1(self.geom.xi, self.geom.l)
        plates = self.geom.c_plate * ((D[:, None] + hk * Dp[:, None]) + beta * (Dd[:, None] + hk * Dpd[:, None]))
        out[f"{self.name}.plate_tension"] = (plates * self.on[:, None]).ravel()
        tau, nv, _ = self._bisector(tt)
        kappa = (4 / self.geom.l) * _kx(up)
        M = self.geom.A_n * _dot(tau, kappa)[:, None] * tau + self.geom.A_tau * _dot(nv, kappa)[:, None] * nv
        out[f"{self.name}.pin_bending_moment"] = np.stack([_dot(M, tau), _dot(M, nv)], axis=1).ravel()
        return out
