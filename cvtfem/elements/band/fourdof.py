"""Four-DOF band model ``q = [phi, sigma, phi1, phi2]`` (spec section 4.3).

Lagrange form (erratum 3): ``Acal phi'' + Acal' phi'^2 / 2 = kappa sum F_k tan(gamma_k) r_k' + Q_phi``,
``m sigma'' = Q_sigma``, ``J_k phi_k'' = M_k + Q_phi_k`` with ``Acal = A(phi) + sum m_k (tan(gamma_k) r_k')^2``
(A from the corrected (1.45)).  Friction forces (1.51, corrected: theta instead of theta/r_k,
N_k inside the sum) are Gauss-Legendre quadratures along each arc; the normal forces N_k are
the constraint reactions of the per-sheave axial balance, solved with the phi-equation as the
3x3 linear system of section 4.3.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cvtfem.elements.band import compressible_kernel, fourdof_kernel
from cvtfem.elements.contact.friction import friction_gain
from cvtfem.elements.band.geometry import radii, wrap_half_angles
from cvtfem.elements.band.inertia import band_inertia
from cvtfem.elements.band.params import BandParams, gauss_nodes


def arc_geometry(phi, p: BandParams):
    """Per-pulley geometry at span angle phi: r, r', r'', tan(gamma), d tan(gamma)/dr, theta*, z0; each ``(2,)``."""
    r, dr, ddr = radii(phi, p.length, p.L)
    s1, s2 = p.sheaves
    if s1 == s2:  # equal faces (the usual case): one vectorised evaluation for both pulleys
        tg, dtg, z0 = s1.tan_gamma(r), -s1.d2z0(r), s1.z0(r)
    else:
        tg = np.stack([p.sheaves[k].tan_gamma(r[k]) for k in range(2)])
        dtg = np.stack([-p.sheaves[k].d2z0(r[k]) for k in range(2)])
        z0 = np.stack([p.sheaves[k].z0(r[k]) for k in range(2)])
    return r, dr, ddr, tg, dtg, wrap_half_angles(phi), z0


def generalized_inertia(phi, p: BandParams):
    """``Acal(phi) = A(phi) + sum_k m_k (tan(gamma_k) r_k')^2``, kg m^2 (may be complex)."""
    r, dr, _, tg, _, _, _ = arc_geometry(phi, p)
    return band_inertia(phi, p.length, p.L, p.mass) + sum(p.m_sheave[k] * (tg[k] * dr[k]) ** 2 for k in range(2))


@dataclass(frozen=True)
class FourDofBand:
    """The 4-DOF band model as a pure kernel around :class:`BandParams`.

    ``use_numba``: :meth:`accel` runs the compiled kernel of ``fourdof_kernel`` (when numba is
    installed); :meth:`accel_numpy` is its reference twin.
    """

    p: BandParams
    names: tuple[str, ...] = ("phi", "sigma", "phi1", "phi2")
    use_numba: bool = True
    _xi: np.ndarray = field(init=False, repr=False)
    _wq: np.ndarray = field(init=False, repr=False)
    _packed: tuple = field(init=False, repr=False)

    def __post_init__(self) -> None:
        xi, wq = gauss_nodes(self.p.n_gauss)
        object.__setattr__(self, "_xi", xi)
        object.__setattr__(self, "_wq", wq)
        object.__setattr__(self, "_packed", fourdof_kernel.pack(self))

    @property
    def backend(self) -> str:
        """``"numba"`` (compiled right-hand side) or ``"numpy"`` (numba off or not installed)."""
        return "numba" if self.use_numba and compressible_kernel.HAVE_NUMBA else "numpy"

    n2 = 4

    def arc_nodes(self, phi: float) -> np.ndarray:
        """Local arc angles theta of the quadrature nodes, ``(2, n_gauss)``, rad."""
        return wrap_half_angles(phi)[:, None] * self._xi

    def accel(self, q, v, F, M):
        """Accelerations and diagnostics (see :meth:`accel_numpy`), compiled when :attr:`backend` is numba."""
        if self.backend == "numpy":
            return self.accel_numpy(q, v, F, M)
        c = np.ascontiguousarray  # one compiled signature (C-contiguous float64)
        a, N, slip, slip_max, dissipation, clamp_power = fourdof_kernel.accel4_kernel(
            c(q, float), c(v, float), c(F, float), c(M, float), *self._packed)
        return a, {"N": N, "dissipation": dissipation, "slip": slip, "slip_max": slip_max,
                   "clamp_power": clamp_power}

    def accel_numpy(self, q, v, F, M):
        """Accelerations and diagnostics (numpy reference of the compiled kernel).

        Parameters
        ----------
        q, v : arrays (4,)
            Coordinates and velocities.
        F : (2,) N
            Clamping force per sheave of each pulley.
        M : (2,) N m
            Shaft torques.

        Returns
        -------
        a : (4,) accelerations
        info : dict with ``N`` (2,) N/m, ``dissipation`` W, ``clamp_power`` W, ``slip`` (2,) m/s
            (circumferential slip at the arc middles), ``slip_max`` (2,) m/s.
        """
        p = self.p
        phi, dphi = q[0], v[0]
        geo = arc_geometry(phi + 1e-30j, p)  # one complex evaluation gives values and phi-derivatives
        r, dr, ddr, tg, dtg, ts = (g.real for g in geo[:6])
        Ac = (band_inertia(phi + 1e-30j, p.length, p.L, p.mass, geo[0])
              + np.sum(np.asarray(p.m_sheave) * (geo[3] * geo[1]) ** 2))
        A, dA = Ac.real, Ac.imag / 1e-30
        rhs_phi = p.kappa * np.sum(F * tg * dr) - 0.5 * dA * dphi ** 2
        a = np.empty(4)
        info = {"N": np.zeros(2), "dissipation": 0.0, "slip": v[1] - r * v[2:4], "slip_max": np.zeros(2)}
        if p.friction:
            th = ts[:, None] * self._xi
            ds = (r * ts)[:, None] * self._wq  # (2, g)
            a_r = dr * dphi  # radial slip, uniform on each arc
            a_z = tg * a_r  # axial slip
            vt = v[1] - th * a_r[:, None] - (r * v[2:4])[:, None]
            Gd = friction_gain(np.sqrt(vt * vt + (a_r * a_r + a_z * a_z)[:, None]), p.f0, p.v0, p.law) * ds
            I_G, I_Gt, I_Gtt = Gd.sum(axis=1), (Gd * vt).sum(axis=1), (Gd * vt * th).sum(axis=1)
            # generalized friction forces per unit N_k (1.51, corrected): f t = G v_r
            G_phi = -2 * dr * (a_r * (1 + tg * tg) * I_G - I_Gtt)
            G_sig = -2 * I_Gt
            G_shaft = 2 * r * I_Gt
            P = -2 * r * ts / np.sqrt(1 + tg * tg) - a_z * I_G  # int k.p ds
            msh = np.asarray(p.m_sheave)
            alpha = (0.5 * msh * (ddr * tg + dr ** 2 * dtg) * dphi ** 2 - F) / P
            beta = 0.5 * msh * dr * tg / P
            a[0] = (rhs_phi + alpha @ G_phi) / (A - beta @ G_phi)
            N = alpha + beta * a[0]
            a[1] = (N @ G_sig) / p.mass
            a[2:4] = (M + N * G_shaft) / np.asarray(p.J)
            Q = np.array([N @ G_phi, N @ G_sig, N[0] * G_shaft[0], N[1] * G_shaft[1]])
            slip_max = np.sqrt(np.max(vt * vt, axis=1) + a_r * a_r + a_z * a_z)
            info.update(N=N, dissipation=-float(Q @ v), slip_max=slip_max)
        else:
            a[0] = rhs_phi / A
            a[1] = 0.0
            a[2:4] = M / np.asarray(p.J)
        info["clamp_power"] = float(p.kappa * np.sum(F * tg * dr) * dphi)
        return a, info

    def energies(self, q, v) -> tuple[float, float]:
        """Kinetic and elastic energy ``(T, V)``, J; compiled when :attr:`backend` is numba (twin:
        :meth:`kinetic_energy`, :meth:`elastic_energy`)."""
        if self.backend == "numpy":
            return self.kinetic_energy(q, v), self.elastic_energy(q)
        c = np.ascontiguousarray
        return float(fourdof_kernel.kinetic4_kernel(c(q, float), c(v, float), *self._packed[:4])), 0.0

    def kinetic_energy(self, q, v) -> float:
        """``T = (Acal phi'^2 + m sigma'^2 + sum J_k phi_k'^2) / 2``, J (1.40), (1.44); numpy reference."""
        A = generalized_inertia(q[0], self.p)
        return 0.5 * (A * v[0] ** 2 + self.p.mass * v[1] ** 2 + np.sum(np.asarray(self.p.J) * v[2:4] ** 2))

    def elastic_energy(self, q) -> float:
        """The 4-DOF band stores no elastic energy, J."""
        return 0.0

    def clamp_positions(self, q):
        """Axial sheave positions ``z_k = z0_k(r_k(phi))`` (2,), m; ``kappa sum F_k z_k`` is the clamping potential."""
        return arc_geometry(q[0], self.p)[6]

    def initial_state(self, phi0: float, omega1: float, omega2: float, F) -> tuple[np.ndarray, np.ndarray]:
        """Coordinates and velocities at span angle phi0 with shaft speeds omega1, omega2 (rad/s), no slip on pulley 1."""
        r, *_ = radii(phi0, self.p.length, self.p.L)
        return np.array([phi0, 0.0, 0.0, 0.0]), np.array([0.0, r[0] * omega1, omega1, omega2])

    def speed_indices(self) -> tuple[int, int]:
        """Indices of the driving and driven shaft angles in q."""
        return 2, 3
