"""The 6+2n band model (transversely compressible band, section 4.4) and its 6+2n+8 extension
with sheave shift and tilt from shaft compliance (section 4.5).

Coordinates ``q = [phi, sigma, phi1, phi2, z1, z2, h_11..h_1n, h_21..h_2n]`` and, for 6+2n+8,
``[U_11, U_12, psi_11, psi_12, U_21, U_22, psi_21, psi_22]`` (in-plane shift and tilt of each
sheave pair, components along i, j).

* Kinetic energy ``T = q'^T M(phi) q' / 2``: the band part ``rho int |du/dq q'|^2 ds`` with the
  Jacobian taken at ``h = 0`` (section 4.4 [C]: A(phi, 0) with Christoffel terms, M' by
  complex step), pair masses for ``z`` and ``U``, and per shaft
  ``J (phi_k' + k.(psi' x psi) / 2)^2 / 2 + Theta |psi'|^2 / 2`` (section 4.5 [C], reviewed factor 1/2).
* Strain ``eps = -z0(r) + E(phi)^T x`` per arc (1.55) / (1.63) in the (1.57) sign convention, with
  ``x_k = [z_k, h_k, U_k, psi_k]``; ``Pi = kappa sum F_k z_k + c' sum int eps^2 ds + shaft springs``,
  ``c' = c`` (consistent, section 4.6) or ``c/2`` (source_literal: (1.56) as printed).
* Normal force ``N = c eps / (k.p)`` clipped at 0 (lift-off), friction ``R = -f N t`` with the slip
  ``v_r = J(phi) q'`` of the band edge against the sheave point; the same J gives the generalized
  friction forces, so friction only dissipates (``D = -Q^f . q' >= 0``).
* Band damping: Rayleigh function ``beta c' int eps'^2 ds`` with ``beta = 2 nu / omega_z``; shaft
  damping (6+2n+8): ``2 nu sqrt(c m)`` on each shift and tilt (effects.damping, ratio ``damping_ratio``).
* Flexible sheaves (``faces``, issue 20): the faces open under the arc's own edge forces, quasi-statically:
  ``eps = eps_r + w``, ``w = -c' K_f D eps`` (``eps_r`` the strain on rigid faces, ``K_f`` the face compliance
  between the Gauss nodes, :class:`~cvtfem.elements.sheave_face.FaceCompliance`, ``D`` the arc-length weights),
  so ``eps = A^-1 eps_r`` with ``A = I + c' K_f D``; the sheaves' strain energy joins the band's,
  ``V = c' int eps eps_r ds`` (the minimum over ``w``), whose gradient in ``x`` is ``2 c' int E eps ds``.
  Condensed onto the arc functions ``E`` and tabulated in phi (:mod:`cvtfem.elements.band.face_table`):
  ``eps = eps_r + dG x~``, ``V = c' int eps_r^2 ds + c' x~^T dK x~`` with ``x~ = x - z0 e_0``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cvtfem.elements.band import compressible_kernel as ker
from cvtfem.elements.band.face_table import INTERVALS, face_table
from cvtfem.elements.contact.friction import friction_vector
from cvtfem.elements.band.geometry import radii
from cvtfem.elements.band.inertia import band_inertia
from cvtfem.elements.band.params import BandParams, gauss_nodes
from cvtfem.elements.band.ritz import ritz_alpha, ritz_shapes

H = 1e-30  # complex step
#: Steady state accepted when the Newton correction is below this, relative to the speeds and to 1 mm for the
#: elastic coordinates: far below anything a run resolves.  Round-off leaves a median of 1e-12 and at most 5e-10
#: on the operating grid of ``studies/band/steady_start_grid.py`` (6+2n+8 at ratio 1, Jacobian condition ~1e7).
STEADY_TOL = 1e-8
#: Newton steps after scipy's hybr before the steady state counts as not found.
POLISH_STEPS = 4


@dataclass(frozen=True)
class CompressibleBand:
    """6+2n (``shaft_compliance=False``) or 6+2n+8 band model as a kernel around :class:`BandParams`.

    ``use_numba``: evaluate :meth:`accel` and :meth:`jacobian` with the compiled kernels of
    ``compressible_kernel`` (when numba is installed); :meth:`accel_numpy` is their reference twin.
    ``faces``: the face compliance of the driving and driven sheaves
    (:class:`~cvtfem.elements.sheave_face.FaceCompliance`), or None for rigid faces; ``face_intervals``: grid
    intervals of their table in phi (:mod:`~cvtfem.elements.band.face_table`), 0 for the exact face systems at
    every call (the reference the table is checked against).
    """

    p: BandParams
    shaft_compliance: bool = False
    use_numba: bool = True
    faces: tuple | None = None
    face_intervals: int = INTERVALS
    _c: dict = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self) -> None:
        p, n = self.p, self.p.n_ritz
        xi, wq = gauss_nodes(p.n_gauss)
        F, dF = ritz_shapes(xi, n)
        r0 = radii(0.0, p.length, p.L)[0][0]
        c_edge = p.c / 2 if p.source_literal else p.c
        omega_z = np.sqrt(2 * c_edge * np.pi * r0 / min(p.m_sheave))
        nx = 1 + n + (4 if self.shaft_compliance else 0)
        # x_k = q[xidx[k]] (disjoint index rows, so scatter-adds can use fancy indexing)
        xidx = np.array([np.r_[4 + k, 6 + k * n:6 + (k + 1) * n]
                         if not self.shaft_compliance else
                         np.r_[4 + k, 6 + k * n:6 + (k + 1) * n, 6 + 2 * n + 4 * k:10 + 2 * n + 4 * k]
                         for k in range(2)])
        self._c.update(xi=xi, wq=wq, F=F, dF=dF, nx=nx, c_edge=c_edge, xidx=xidx, bidx=np.r_[0, 1, 6:6 + 2 * n],
                       ones=np.ones((2, 1, len(xi))), mdF=-dF[None],
                       beta=2 * p.damping_ratio / omega_z if p.damping else 0.0, alpha=ritz_alpha(n))
        self._c["table"] = face_table(self, self.face_intervals) if self.faces and self.face_intervals else None
        self._c["packed"] = ker.pack(self)

    @property
    def backend(self) -> str:
        """``"numba"`` (compiled right-hand side) or ``"numpy"`` (numba off or not installed)."""
        return "numba" if self.use_numba and ker.HAVE_NUMBA else "numpy"

    @property
    def n2(self) -> int:
        return 6 + 2 * self.p.n_ritz + (8 if self.shaft_compliance else 0)

    @property
    def names(self) -> tuple[str, ...]:
        n = self.p.n_ritz
        out = ["phi", "sigma", "phi1", "phi2", "z1", "z2"] + [f"h{k}{i}" for k in (1, 2) for i in range(1, n + 1)]
        if self.shaft_compliance:
            out += [f"{v}{k}{c}" for k in (1, 2) for v in ("U", "psi") for c in (1, 2)]
        return tuple(out)

    def speed_indices(self) -> tuple[int, int]:
        return 2, 3

    def arc_nodes(self, phi: float) -> np.ndarray:
        """Local arc angles theta of the quadrature nodes, ``(2, n_gauss)``, rad."""
        return np.stack([np.pi / 2 + phi, np.pi / 2 - phi])[:, None] * self._c["xi"]

    # --- index helpers -------------------------------------------------------------------------
    def _x(self, q, k: int):
        """Elastic coordinates ``x_k = [z_k, h_k, U_k, psi_k]`` of arc k."""
        return q[self._c["xidx"][k]]

    def _scatter_x(self, out, k: int, values) -> None:
        n = self.p.n_ritz
        out[4 + k] += values[0]
        out[6 + k * n:6 + (k + 1) * n] += values[1:1 + n]
        if self.shaft_compliance:
            out[6 + 2 * n + 4 * k:10 + 2 * n + 4 * k] += values[1 + n:]

    def _band_index(self) -> np.ndarray:
        return self._c["bidx"]

    # --- kernels -------------------------------------------------------------------------------
    def arcs(self, phi):
        """Per-arc geometry at ``phi`` (complex allowed): dict of ``(2,)`` and ``(2, g)`` arrays."""
        p, c = self.p, self._c
        r, dr, _ = radii(phi, p.length, p.L)
        ts = np.array([np.pi / 2 + phi, np.pi / 2 - phi])
        tg = np.array([p.sheaves[0].tan_gamma(r[0]), p.sheaves[1].tan_gamma(r[1])])
        z0 = np.array([p.sheaves[0].z0(r[0]), p.sheaves[1].z0(r[1])])
        th = ts[:, None] * c["xi"]
        fr = c["mdF"] / ts[:, None, None]  # (2, n, g)
        geo = dict(r=r, dr=dr, ts=ts, tg=tg, z0=z0, th=th, fr=fr, ds=(r * ts)[:, None] * c["wq"])
        rows = [c["ones"], tg[:, None, None] * fr]
        if self.shaft_compliance:
            a = np.stack([p.sheaves[k].lever(r[k]) for k in range(2)])
            tabs = th + np.array([0.0, np.pi])[:, None]
            cs, sn = np.cos(tabs), np.sin(tabs)
            lev = (r + tg * a)[:, None]
            rows.append(np.stack([-tg[:, None] * cs, -tg[:, None] * sn, lev * sn, -lev * cs], axis=1))
            geo.update(a=a, cs=cs, sn=sn)
        geo["E"] = np.concatenate(rows, axis=1)  # (2, nx, g): d eps / d x_k at the nodes
        return geo

    def face_systems(self, geo) -> np.ndarray:
        """``A = I + c' K_f D`` of each arc (flexible sheaves), ``(2, g, g)``, from the geometry :meth:`arcs`."""
        g = len(self._c["xi"])
        return np.stack([np.eye(g) + self._c["c_edge"] * self.faces[k].matrix(geo["r"][k], geo["th"][k]) * geo["ds"][k]
                         for k in range(2)])

    def face_terms(self, phi: float) -> tuple[np.ndarray, np.ndarray]:
        """``[dG; dK]`` of each arc and its phi-derivative, each ``(2, g + nx, nx)``
        (:mod:`~cvtfem.elements.band.face_table`): from the table where it covers phi, else exactly (``A``
        solved, complex step in phi)."""
        table = self._c.get("table")
        return table.at(phi) if table is not None and table.covers(phi) else self.exact_face_terms(phi)

    def exact_face_terms(self, phi: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`face_terms` from the face systems ``A`` at ``phi + i h``."""
        g = self.arcs(phi + 1j * H)
        Et = np.swapaxes(g["E"], 1, 2)                                  # (2, g, nx)
        dG = np.linalg.solve(self.face_systems(g), Et) - Et
        dK = np.einsum("kxg,kg,kgy->kxy", g["E"], g["ds"], dG)
        block = np.concatenate([dG, 0.5 * (dK + np.swapaxes(dK, 1, 2))], axis=1)
        return block.real, block.imag / H

    def _x_tilde(self, q, geo):
        """``x~ = x - z0 e_0`` per arc, ``(2, nx)`` (complex with a complex geometry): ``eps_r = E^T x~``."""
        X = q[self._c["xidx"]] + 0 * geo["z0"][:, None]
        X[:, 0] -= geo["z0"]
        return X

    def band_mass(self, phi, geo=None):
        """Band block of the mass matrix over ``[phi, sigma, h1, h2]`` (may be complex), kg-based units."""
        p, c = self.p, self._c
        g = self.arcs(phi) if geo is None else geo
        n, rho = p.n_ritz, p.rho
        M = np.zeros((2 + 2 * n, 2 + 2 * n), dtype=np.result_type(phi, float))
        M[0, 0] = band_inertia(phi, p.length, p.L, p.mass, r=g["r"])
        M[1, 1] = p.mass
        for k in range(2):
            sl = slice(2 + k * n, 2 + (k + 1) * n)
            fr, ds = g["fr"][k], g["ds"][k]
            M[sl, sl] = rho * ((fr * ds) @ fr.T + (c["F"] * ds) @ c["F"].T)
            M[1, sl] = M[sl, 1] = rho * (c["F"] * ds).sum(axis=1)
            M[0, sl] = M[sl, 0] = rho * g["dr"][k] * ((fr - g["th"][k] * c["F"]) * ds).sum(axis=1)
        return M

    def strain(self, q, geo):
        """Band-edge strain ``eps`` at the nodes on rigid faces, ``(2, g)`` (1.55) / (1.63)."""
        X = q[self._c["xidx"]]  # (2, nx)
        return np.einsum("kx,kxg->kg", X, geo["E"]) - geo["z0"][:, None]

    def face_opening(self, q, geo=None):
        """Axial opening ``w = eps - eps_r`` (m, ``(2, g)``) of each sheave face at the arc's Gauss nodes (zero on
        rigid faces); ``> 0`` where the face gives way under the band."""
        if self.faces is None:
            return np.zeros((2, len(self._c["xi"])))
        g = self.arcs(q[0]) if geo is None else geo
        gn = len(self._c["xi"])
        return np.einsum("kgx,kx->kg", self.face_terms(q[0])[0][:, :gn], self._x_tilde(q, g))

    def accel(self, q, v, F, M):
        """Accelerations and diagnostics (``N`` (2, g) N/m, ``dissipation``, ``clamp_power`` W, slips)."""
        if self.backend == "numpy":
            return self.accel_numpy(q, v, F, M)
        c = np.ascontiguousarray  # one compiled signature (C-contiguous float64) whatever the caller passes
        a, N, eps, slip, slip_max, dissipation, clamp_power = ker.accel_kernel(
            c(q, float), c(v, float), c(F, float), c(M, float), *self._c["packed"])
        return a, {"N": N, "eps": eps, "slip": slip, "slip_max": slip_max,
                   "dissipation": dissipation, "clamp_power": clamp_power}

    def jacobian(self, q, v, F, M):
        """Forward-difference Jacobian of ``[a, dissipation, clamp_power]`` (n2 + 2 rows) with respect to
        ``[q, v, F, M]`` (2 n2 + 4 columns), see ``compressible_kernel.jacobian_kernel``."""
        c = np.ascontiguousarray
        args = (c(q, float), c(v, float), c(F, float), c(M, float))
        if self.backend == "numba":
            return ker.jacobian_kernel(*args, *self._c["packed"])
        return self.jacobian_numpy(*args)

    def jacobian_numpy(self, q, v, F, M):
        """Numpy twin of :meth:`jacobian` (same columns and increments, :meth:`accel_numpy`)."""
        n2 = self.n2
        x0 = np.concatenate([q, v, F, M])

        def y(x):
            a, info = self.accel_numpy(x[:n2], x[n2:2 * n2], x[2 * n2:2 * n2 + 2], x[2 * n2 + 2:])
            return np.concatenate([a, [info["dissipation"], info["clamp_power"]]])

        y0, Jm = y(x0), np.zeros((n2 + 2, x0.size))
        for j in [0] + list(range(4, x0.size)):
            h = (1e-8 * max(1e-3, abs(x0[j])) if j < n2 else 1e-7 * max(1.0, abs(x0[j])) if j < 2 * n2
                 else 1e-6 * max(1.0, abs(x0[j])))
            xp = x0.copy()
            xp[j] += h
            Jm[:, j] = (y(xp) - y0) / h
        return Jm

    def accel_numpy(self, q, v, F, M):
        """Numpy reference of :meth:`accel` (same results; ~20x slower per call)."""
        p, c = self.p, self._c
        n, n2 = p.n_ritz, self.n2
        phi = q[0]
        gc = self.arcs(phi + 1j * H)
        g = {k: (val.real if val.dtype.kind == "c" else val) for k, val in gc.items()}
        if self.faces is None:
            eps_c = self.strain(q, gc)
        else:  # eps_r = E^T x~ (z - z0 rounded once, as the compiled kernel)
            xt_c = self._x_tilde(q, gc)
            eps_c = np.einsum("kx,kxg->kg", xt_c, gc["E"])
        Pi_c = c["c_edge"] * np.sum(eps_c ** 2 * gc["ds"])
        eps, deps = eps_c.real, eps_c.imag / H
        E_eps = g["E"]  # d eps / d x at the nodes
        Q = np.zeros(n2)
        # elastic band energy and its generalized forces
        Q[0] -= Pi_c.imag / H
        xidx = c["xidx"]
        Q[xidx] -= 2 * c["c_edge"] * np.einsum("kxg,kg->kx", g["E"], eps * g["ds"])
        if self.faces is not None:  # flexible faces: eps = eps_r + dG x~, V = c' int eps_r^2 ds + c' x~^T dK x~
            gn = len(c["xi"])
            (dG, dK), (dG_d, dK_d) = ((T[:, :gn], T[:, gn:]) for T in self.face_terms(phi))
            xt, dxt = xt_c.real, xt_c.imag / H
            eps = eps + np.einsum("kgx,kx->kg", dG, xt)
            deps = deps + np.einsum("kgx,kx->kg", dG_d, xt) + np.einsum("kgx,kx->kg", dG, dxt)
            E_eps = E_eps + np.swapaxes(dG, 1, 2)
            Q[xidx] -= 2 * c["c_edge"] * np.einsum("kxy,ky->kx", dK, xt)
            Q[0] -= c["c_edge"] * (np.einsum("kx,kxy,ky->", xt, dK_d, xt) + 2 * np.einsum("kx,kxy,ky->", dxt, dK, xt))
        Q[4:6] -= p.kappa * np.asarray(F)
        dissipation = 0.0
        if self.shaft_compliance:
            for k in range(2):
                b = 6 + 2 * n + 4 * k
                Q[b:b + 2] -= p.c_U[k] * q[b:b + 2]
                Q[b + 2:b + 4] -= p.c_psi[k] * q[b + 2:b + 4]
                if p.damping:  # shaft damping at ratio nu of each spring-mass pair
                    d = 2 * p.damping_ratio * np.array([np.sqrt(p.c_U[k] * p.m_sheave[k])] * 2
                                                       + [np.sqrt(p.c_psi[k] * p.Theta[k])] * 2)
                    Q[b:b + 4] -= d * v[b:b + 4]
                    dissipation += float(np.sum(d * v[b:b + 4] ** 2))
        if c["beta"] > 0:
            deps_dt = deps * v[0] + np.einsum("kx,kxg->kg", v[xidx], E_eps)
            Qd = np.zeros(n2)
            Qd[0] = -2 * c["beta"] * c["c_edge"] * np.sum(deps_dt * deps * g["ds"])
            Qd[xidx] = -2 * c["beta"] * c["c_edge"] * np.einsum("kxg,kg->kx", E_eps, deps_dt * g["ds"])
            dissipation -= float(Qd @ v)
            Q += Qd
        info = {"N": np.zeros_like(eps), "eps": eps}
        if p.friction:
            Qf, N, vr = self._friction(q, v, g, eps)
            dissipation -= float(Qf @ v)
            Q += Qf
            info.update(N=N, slip=vr[1][:, p.n_gauss // 2], slip_max=np.sqrt((vr ** 2).sum(axis=0)).max(axis=1))
        else:
            vt = v[1] - g["r"] * v[2:4]
            info.update(slip=vt, slip_max=np.abs(vt))
        Q[2:4] += M
        a = self._solve(q, v, Q, phi, gc)
        info.update(dissipation=dissipation, clamp_power=float(-p.kappa * np.dot(F, v[4:6])))
        return a, info

    def _friction(self, q, v, g, eps):
        p, c = self.p, self._c
        n = p.n_ritz
        tg, th, ds = g["tg"][:, None], g["th"], g["ds"]
        hd = np.stack([v[6:6 + n], v[6 + n:6 + 2 * n]])
        vr_r = (g["dr"] * v[0])[:, None] + np.einsum("kng,kn->kg", g["fr"], hd)
        vr_t = v[1] - th * (g["dr"] * v[0])[:, None] - (g["r"] * v[2:4])[:, None] + hd @ c["F"]
        if self.shaft_compliance:
            b = 6 + 2 * n
            U = np.stack([v[b:b + 2], v[b + 4:b + 6]])
            P = np.stack([v[b + 2:b + 4], v[b + 6:b + 8]])
            cs, sn, a = g["cs"], g["sn"], g["a"][:, None]
            vr_r = vr_r - (U[:, :1] * cs + U[:, 1:] * sn) - a * (-P[:, :1] * sn + P[:, 1:] * cs)
            vr_t = vr_t - (-U[:, :1] * sn + U[:, 1:] * cs) + a * (P[:, :1] * cs + P[:, 1:] * sn)
        vr = np.stack([vr_r, vr_t, tg * vr_r])
        ft = friction_vector(vr, p.f0, p.v0, p.law, axis=0)
        cosg = 1.0 / np.sqrt(1.0 + tg ** 2)
        N = np.maximum(0.0, -p.c * eps / (cosg + ft[2]))
        T = ft * N * ds  # (3, 2, g): f N t ds
        Tn = T[0] + tg * T[2]
        Q = np.zeros(self.n2)
        Q[0] = -2 * np.sum(g["dr"][:, None] * (Tn - th * T[1]))
        Q[1] = -2 * np.sum(T[1])
        Q[2:4] = 2 * g["r"] * T[1].sum(axis=1)
        Q[6:6 + 2 * n] = (-2 * (np.einsum("kng,kg->kn", g["fr"], Tn) + T[1] @ c["F"].T)).ravel()
        if self.shaft_compliance:
            b = 6 + 2 * n
            cs, sn, a = g["cs"], g["sn"], g["a"][:, None]
            QU1 = 2 * np.sum(cs * Tn - sn * T[1], axis=1)
            QU2 = 2 * np.sum(sn * Tn + cs * T[1], axis=1)
            Qp1 = -2 * np.sum(a * (sn * Tn + cs * T[1]), axis=1)
            Qp2 = 2 * np.sum(a * (cs * Tn - sn * T[1]), axis=1)
            for k in range(2):
                Q[b + 4 * k:b + 4 * k + 4] = [QU1[k], QU2[k], Qp1[k], Qp2[k]]
        return Q, N, vr

    def _solve(self, q, v, Q, phi, gc=None):
        p, n = self.p, self.p.n_ritz
        a = np.empty(self.n2)
        bi = self._band_index()
        Mc = self.band_mass(phi + 1j * H, gc)  # gc: the geometry accel already built at phi + iH
        Mb, dMb = Mc.real, Mc.imag / H
        vb = v[bi]
        rhs = Q[bi] - v[0] * (dMb @ vb)
        rhs[0] += 0.5 * vb @ dMb @ vb
        a[bi] = np.linalg.solve(Mb, rhs)
        a[4:6] = Q[4:6] / np.asarray(p.m_sheave)
        if not self.shaft_compliance:
            a[2:4] = Q[2:4] / np.asarray(p.J)
            return a
        b = 6 + 2 * n
        for k in range(2):
            j = b + 4 * k
            a[j:j + 2] = Q[j:j + 2] / p.m_sheave[k]
            J, Th = p.J[k], p.Theta[k]
            p1, p2 = q[j + 2], q[j + 3]
            d1, d2 = v[j + 2], v[j + 3]
            if p.gyroscopic:
                w_ax = v[2 + k] + 0.5 * (d1 * p2 - d2 * p1)
                wdot = Q[2 + k] / J
                a[j + 2] = (Q[j + 2] - 0.5 * J * wdot * p2 - J * w_ax * d2) / Th
                a[j + 3] = (Q[j + 3] + 0.5 * J * wdot * p1 + J * w_ax * d1) / Th
                a[2 + k] = wdot - 0.5 * (a[j + 2] * p2 - a[j + 3] * p1)
            else:
                a[j + 2:j + 4] = Q[j + 2:j + 4] / Th
                a[2 + k] = Q[2 + k] / J
        return a

    # --- energies and states -------------------------------------------------------------------
    def energies(self, q, v) -> tuple[float, float]:
        """Kinetic and elastic energy ``(T, V)``, J; compiled when :attr:`backend` is numba (twin:
        :meth:`kinetic_energy`, :meth:`elastic_energy`)."""
        if self.backend == "numpy":
            return self.kinetic_energy(q, v), self.elastic_energy(q)
        c = np.ascontiguousarray
        T, V = ker.energy_kernel(c(q, float), c(v, float), *self._c["packed"])
        return float(T), float(V)

    def kinetic_energy(self, q, v) -> float:
        """Kinetic energy ``q'^T M(phi) q' / 2`` plus the shafts', J; numpy reference of :meth:`energies`."""
        p, n = self.p, self.p.n_ritz
        bi = self._band_index()
        vb = v[bi]
        T = 0.5 * vb @ self.band_mass(q[0]) @ vb + 0.5 * np.sum(np.asarray(p.m_sheave) * v[4:6] ** 2)
        if not self.shaft_compliance:
            return float(T + 0.5 * np.sum(np.asarray(p.J) * v[2:4] ** 2))
        b = 6 + 2 * n
        for k in range(2):
            j = b + 4 * k
            w_ax = v[2 + k] + (0.5 * (v[j + 2] * q[j + 3] - v[j + 3] * q[j + 2]) if p.gyroscopic else 0.0)
            T += 0.5 * (p.m_sheave[k] * np.sum(v[j:j + 2] ** 2) + p.J[k] * w_ax ** 2
                        + p.Theta[k] * np.sum(v[j + 2:j + 4] ** 2))
        return float(T)

    def elastic_energy(self, q) -> float:
        """Band compression plus shaft springs, J (the clamping potential is not included); numpy reference
        of :meth:`energies`."""
        p, n = self.p, self.p.n_ritz
        g = self.arcs(q[0])
        if self.faces is None:
            E = self._c["c_edge"] * np.sum(self.strain(q, g) ** 2 * g["ds"])
        else:  # the band's strain energy and the sheaves', c' x~^T dK x~ (together c' int eps eps_r ds)
            xt = self._x_tilde(q, g)
            dK = self.face_terms(q[0])[0][:, len(g["ds"][0]):]
            E = self._c["c_edge"] * (np.sum(np.einsum("kx,kxg->kg", xt, g["E"]) ** 2 * g["ds"])
                                     + np.einsum("kx,kxy,ky->", xt, dK, xt))
        if self.shaft_compliance:
            b = 6 + 2 * n
            for k in range(2):
                j = b + 4 * k
                E += 0.5 * (p.c_U[k] * np.sum(q[j:j + 2] ** 2) + p.c_psi[k] * np.sum(q[j + 2:j + 4] ** 2))
        return float(E)

    def clamp_positions(self, q):
        """Axial sheave coordinates ``z_k`` (2,), m."""
        return q[4:6]

    def static_state(self, phi: float, F) -> np.ndarray:
        """Coordinates in static equilibrium of the elastic coordinates at span angle phi and forces F.

        Solves ``(2 c' (int E E^T ds + dK) + D) x = 2 c' (int E E^T ds + dK) z0 e_0 - kappa F e_z`` per arc (Pi is
        quadratic in x; ``dK`` the flexible faces' condensed stiffness, :meth:`face_terms`, else 0).
        """
        p, c, n = self.p, self._c, self.p.n_ritz
        g = self.arcs(phi)
        q = np.zeros(self.n2)
        q[0] = phi
        dK = self.face_terms(phi)[0][:, len(c["xi"]):] if self.faces is not None else np.zeros((2, 1, 1))
        for k in range(2):
            E, ds = g["E"][k], g["ds"][k]
            K = 2 * c["c_edge"] * ((E * ds) @ E.T + dK[k])
            rhs = K[:, 0] * g["z0"][k]
            rhs[0] -= p.kappa * F[k]
            if self.shaft_compliance:
                K[1 + n:, 1 + n:] += np.diag([p.c_U[k]] * 2 + [p.c_psi[k]] * 2)
            self._scatter_x(q, k, np.linalg.solve(K, rhs))
        return q

    def steady_state(self, phi: float, omega1: float, F, M1: float):
        """Steady running at fixed span angle: elastic coordinates, band speed, driven speed and torque in balance.

        Unknowns: the elastic coordinates ``x_k``, the band speed ``sigma'``, the driven speed ``omega2`` and the
        driven torque ``M2`` that hold every acceleration but the span angle's at zero under the driving torque
        ``M1`` (N m; ``M2`` is also what keeps the sheaves' tilts of 6+2n+8 in balance through the gyroscopic
        coupling).  Returns ``(q, v, M2, info)``; ``info["residual"]`` is the relative Newton correction at the
        solution (:func:`newton_correction`), at most :data:`STEADY_TOL`.

        scipy's ``hybr`` finds the solution; whether it is one is judged by the Newton correction, not by
        hybr's own stopping test: its residual (accelerations of ~1e4 m/s^2 balanced to round-off, ~1e-7)
        stops improving before ``xtol`` is met, which hybr reported as "not making good progress" at random
        regimes of a converged state (38 of 5,016 on the grid of ``studies/band/steady_start_grid.py``).
        A few Newton steps polish a hybr end point that is near but not at the solution.  Raises
        :class:`NumericalError` where no steady state is found (e.g. a torque beyond what the clamping
        forces transmit: the slip grows without bound).
        """
        from scipy.optimize import root

        from cvtfem.errors import NumericalError

        el = self._elastic_index()
        q0, v0 = self.initial_state(phi, omega1, omega1, F)
        r = radii(phi, self.p.length, self.p.L)[0]
        m_scale = max(abs(M1) * r[1] / r[0], 1.0)  # N m: the driven torque without losses (band balance)

        def unpack(y):
            q, v = q0.copy(), v0.copy()
            q[el] = y[:-3] * 1e-6 + q0[el]
            v[1], v[3] = y[-3], y[-2]
            return q, v, np.array([M1, y[-1] * m_scale])

        def residual(y):
            q, v, M = unpack(y)
            a, _ = self.accel(q, v, F, M)
            return np.concatenate([a[el] * 1e-3, a[1:4]])

        y = np.concatenate([np.zeros(len(el)), [r[0] * omega1, r[0] * omega1 / r[1], -abs(M1) * r[1] / r[0] / m_scale]])
        with np.errstate(all="ignore"):
            y = root(residual, y, method="hybr", options={"xtol": 1e-12}).x
            for _ in range(POLISH_STEPS + 1):
                dy, rel = newton_correction(residual, y)
                if rel <= STEADY_TOL:
                    break
                y = y + dy
        if not rel <= STEADY_TOL:
            raise NumericalError(f"steady state not found: relative Newton correction {rel:.3g} after hybr and "
                                 f"{POLISH_STEPS} Newton steps (tolerance {STEADY_TOL:g})",
                                 component=f"band-6+2n{'+8' if self.shaft_compliance else ''} (n = {self.p.n_ritz})")
        q, v, M = unpack(y)
        a, info = self.accel(q, v, F, M)
        info["residual"] = rel
        return q, v, float(M[1]), info

    def _elastic_index(self) -> np.ndarray:
        n = self.p.n_ritz
        return np.r_[4:6 + 2 * n, 6 + 2 * n:self.n2]

    def initial_state(self, phi0: float, omega1: float, omega2: float, F) -> tuple[np.ndarray, np.ndarray]:
        """Static elastic equilibrium at phi0, shafts at omega1, omega2 (rad/s), no slip on pulley 1."""
        q = self.static_state(phi0, F)
        v = np.zeros(self.n2)
        r = radii(phi0, self.p.length, self.p.L)[0]
        v[1:4] = r[0] * omega1, omega1, omega2
        return q, v


def newton_correction(residual, y) -> tuple[np.ndarray, float]:
    """Newton step ``dy = -J^-1 residual(y)`` (forward-difference Jacobian) of :meth:`CompressibleBand.steady_state`'s
    unknowns ``y = [x (um), sigma' (m/s), omega2 (rad/s), M2 / M_scale]`` and its size relative to them:
    ``max(|dx| / 1 mm, |d sigma'| / |sigma'|, |d omega2| / |omega2|, |d M2| / M_scale)`` (inf where the Jacobian is
    singular)."""
    f = residual(y)
    J = np.empty((f.size, y.size))
    for j in range(y.size):
        h = 1e-7 * max(1.0, abs(y[j]))
        yp = y.copy()
        yp[j] += h
        J[:, j] = (residual(yp) - f) / h
    try:
        dy = np.linalg.solve(J, -f)
    except np.linalg.LinAlgError:
        return np.zeros_like(y), np.inf
    rel = max(np.max(np.abs(dy[:-3])) * 1e-3, *(np.abs(dy[-3:-1]) / np.abs(y[-3:-1])), abs(dy[-1]))
    return dy, float(rel) if np.isfinite(rel) else np.inf
