"""Asymmetric chain model A1: whole pins with 10 coordinates each, plates as an elastic layer.

Spec chain-models-2.md section 2 (eqs. (1.132)-(1.167)), with the section-9 resolutions; the
frame, cyclic indexing and effective masses (1.68) are those of chain-models-1.md section 1.

Coordinates of pin ``p`` (2.1): the in-plane 2-vectors ``u_i`` (``i = 0..3``: mean position,
tilt x l/2, far and near end slope minus chord slope) and the axial scalars ``w_0`` (mean axial
position) and ``w_1`` (half the deformed axis length, ``l/2`` at rest).  The state vector is
``q = [u_0 (n, 2), u_1, u_2, u_3, w_0 (n), w_1]`` (blocks by kind, pins inside), so
``q[:8n].reshape(4, n, 2)`` and ``q[8n:].reshape(2, n)``.  Link ``e`` joins pins ``e`` and ``e+1``
(cyclic); an open chain (``closed=False``) lacks link ``n-1``.

Energies and forces (all SI): kinetic (1.134)-(1.135), pin axial (1.136) and bending (1.137) with
the section axes (1.103) following the link bisector, link extension (1.140)-(1.141), twist
(1.146), shear (1.153) with ``shear_convention`` ("derived": gamma = (psi_1 + psi_2)/2, spec 2.5;
"printed": twice that), Rayleigh functions (1.154)-(1.159) with the joint damping (1.80) and the
exact gradients of spec 2.8.  The strains are linearised as in the source: they are exactly
invariant under translations and rotations about ``k``; rotations about in-plane axes leave them
unchanged only to first order (pin length and plate stretch change at second order).

Forces come from the compiled kernel ``asymmetric_kernel`` (numba) or from the numpy methods here,
its tested reference twin; the stiffness and damping matrices are exact and sparse.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.elements.base import Block
from cvtfem.elements.chain import asymmetric_kernel as ker
from cvtfem.errors import InputError
from cvtfem.outputs import OutputSpec

#: Unit mass matrices of (1.135) for ``m_p = 1``, ``l = 1``: ``m_perp[i, j] = int h_i h_j dxi / 2``.
_M_PERP = np.array([[1.0, 0.0, 1 / 12, -1 / 12],
                    [0.0, 1 / 3, -1 / 60, -1 / 60],
                    [1 / 12, -1 / 60, 1 / 105, -1 / 140],
                    [-1 / 12, -1 / 60, -1 / 140, 1 / 105]])
_M_PAR = np.diag([1.0, 1 / 3])
_KX = np.array([-1.0, 1.0])


def shape_functions(xi: np.ndarray, l: float) -> np.ndarray:
    """``h_0..h_3`` of (1.132) at ``xi`` (-1 far end, +1 near end), shape ``(4,) + xi.shape``; ``h_2, h_3`` in m."""
    xi = np.asarray(xi, float)
    return np.stack([np.ones_like(xi), xi, l / 8 * (1 - xi) ** 2 * (1 + xi), l / 8 * (xi - 1) * (1 + xi) ** 2])


def shape_slopes(xi: np.ndarray, l: float) -> np.ndarray:
    """``dh_i/dxi`` of (1.132) at ``xi``, shape ``(4,) + xi.shape``; ``h_2'(-1) = h_3'(1) = l/2``."""
    xi = np.asarray(xi, float)
    return np.stack([np.zeros_like(xi), np.ones_like(xi), l / 8 * (-1 - 2 * xi + 3 * xi ** 2),
                     l / 8 * (-1 + 2 * xi + 3 * xi ** 2)])


def _kx(v: np.ndarray) -> np.ndarray:
    """``k x v`` for in-plane vectors ``v (..., 2)``."""
    return v[..., ::-1] * _KX


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``k . (a x b)`` for in-plane vectors."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


class ChainA1:
    """Model A1 of a whole chain (spec chain-models-2 section 2), vectorised over pins and links.

    Parameters (arrays per link have ``n`` rows for a closed chain, ``n - 1`` for an open one;
    per-plate arrays have ``Kmax`` columns, entries beyond ``n_plates`` ignored)
    ----------
    pitch : (n_links,) m
        Link pitches ``L_{p,p+1}``.
    plate_xi : (n_links, Kmax) -
        Plate stations ``xi^k`` on both pins of the link (lacing pattern).
    n_plates : (n_links,) int
        Plates per link.
    plate_stiffness : (n_links, Kmax) N/m
        Plate tension stiffness ``c^k`` (1.141).
    plate_bending_stiffness : (n_links, Kmax) N m^2
        Out-of-plane plate bending stiffness ``a^k`` (shear, (1.152)-(1.153)).
    plate_torsion_stiffness : (n_links, Kmax) N m/rad
        Plate torsion stiffness ``c^{k,tors}`` (1.146).
    pin_length : m
        Pin axis length ``l``.
    pin_mass : (n,) kg
        Effective pin masses (1.68), spread uniformly along the axis.
    pin_axial_stiffness : (n,) or scalar, N/m
        ``c_p = EF/l`` (1.136).
    pin_bending_tau, pin_bending_n : N m^2
        Pin bending stiffness against deflection along the chain direction ``tau_p`` and along
        ``n_p`` (``A_tau``, ``A_n`` of chain-models-1 3.5; ``a_2``, ``a_1`` of (1.103)).
    beta_link_ext, beta_link_tors, beta_link_shear, beta_bend : s
        Stiffness-proportional damping (1.154)-(1.159), rule (1.86).
    pin_axial_damping : (n,) or scalar, N s/m
        ``b_p`` (1.158).
    joint_damping : (n,) or scalar, N m s/rad
        ``b^joint_p`` (1.80); joints exist where a pin has two links.
    closed : bool
        Closed loop (cyclic, n links) or open segment (n - 1 links).
    shear_convention : "derived" | "printed"
        ``gamma = (psi_1 + psi_2)/2`` (spec 2.5, default) or the printed (1.153), twice that.
    joint_damping_form : "exact" | "printed"
        Exact gradient of the joint Rayleigh function (spec 2.8) or the printed (1.165).
    use_numba : bool
        Evaluate forces with the compiled kernel of ``asymmetric_kernel`` (when numba is installed);
        the numpy methods are its tested reference twin.
    """

    def __init__(self, *, pitch, plate_xi, n_plates, plate_stiffness, plate_bending_stiffness,
                 plate_torsion_stiffness, pin_length: float, pin_mass, pin_axial_stiffness,
                 pin_bending_tau: float, pin_bending_n: float, beta_link_ext: float = 0.0,
                 beta_link_tors: float = 0.0, beta_link_shear: float = 0.0, beta_bend: float = 0.0,
                 pin_axial_damping=0.0, joint_damping=0.0, closed: bool = True,
                 shear_convention: str = "derived", joint_damping_form: str = "exact",
                 use_numba: bool = True) -> None:
        m = np.asarray(pin_mass, float)
        n = m.size
        n_links = n if closed else n - 1
        if m.ndim != 1 or n < 3 or np.any(m <= 0):
            raise InputError("pin_mass", pin_mass, "1-d, at least 3 pins, all > 0")
        pitch = np.asarray(pitch, float)
        if pitch.shape != (n_links,) or np.any(pitch <= 0):
            raise InputError("pitch", pitch.shape, f"({n_links},) positive pitches for {n} pins, closed={closed}")
        xi = np.atleast_2d(np.asarray(plate_xi, float))
        kmax = xi.shape[1]
        npl = np.asarray(n_plates, int)
        if xi.shape[0] != n_links or npl.shape != (n_links,) or np.any(npl < 1) or np.any(npl > kmax):
            raise InputError("plate_xi/n_plates", (xi.shape, npl.shape), f"({n_links}, Kmax) and ({n_links},), 1..Kmax")
        mask = np.arange(kmax)[None, :] < npl[:, None]
        if np.any(np.abs(xi[mask]) > 1):
            raise InputError("plate_xi", xi, "stations within [-1, 1]")
        plates = {}
        for name, val in (("plate_stiffness", plate_stiffness), ("plate_bending_stiffness", plate_bending_stiffness),
                          ("plate_torsion_stiffness", plate_torsion_stiffness)):
            a = np.broadcast_to(np.asarray(val, float), xi.shape)
            if np.any(a[mask] < 0):
                raise InputError(name, val, ">= 0")
            plates[name] = np.where(mask, a, 0.0)
        if shear_convention not in ("derived", "printed"):
            raise InputError("shear_convention", shear_convention, '"derived" or "printed"')
        if joint_damping_form not in ("exact", "printed"):
            raise InputError("joint_damping_form", joint_damping_form, '"exact" or "printed"')
        if pin_length <= 0 or pin_bending_tau <= 0 or pin_bending_n <= 0:
            raise InputError("pin_length/pin_bending_tau/pin_bending_n",
                             (pin_length, pin_bending_tau, pin_bending_n), "> 0")

        pad = n - n_links                      # 1 for an open chain: link n-1 is a dummy with weight 0
        self.n_pins, self.n_links, self.closed, self.kmax = n, n_links, closed, kmax
        self._next, self._prev = (np.arange(n) + 1) % n, (np.arange(n) - 1) % n     # pins p+1, p-1 (cyclic)
        self.l = float(pin_length)
        self.m = m
        self.L = np.r_[pitch, np.ones(pad)]
        self.weight = np.r_[np.ones(n_links), np.zeros(pad)]
        self.g = self.weight / self.L          # d x_p / d u_0 weights of the bisector stencil
        self.plate_xi = np.where(mask, xi, 0.0)
        self.plate_mask = mask
        self.plate_c = plates["plate_stiffness"]
        h = shape_functions(self.plate_xi, self.l)                        # (4, n_links, Kmax)
        cij = np.einsum("ek,iek,jek->eij", self.plate_c, h, h)            # (1.141)
        self.cij = np.concatenate([cij, np.zeros((pad, 4, 4))])
        self.c_tors = np.r_[plates["plate_torsion_stiffness"].sum(1), np.zeros(pad)]      # (1.146)
        self.c_shear = np.r_[12 / pitch * plates["plate_bending_stiffness"].sum(1), np.zeros(pad)]  # (1.153)
        self.c_pin = np.broadcast_to(np.asarray(pin_axial_stiffness, float), (n,)).copy()
        self.b_pin = np.broadcast_to(np.asarray(pin_axial_damping, float), (n,)).copy()
        self.b_joint = (np.broadcast_to(np.asarray(joint_damping, float), (n,))
                        * self.weight * self.weight[self._prev])          # joint p needs links p-1 and p
        self.A_tau, self.A_n = float(pin_bending_tau), float(pin_bending_n)
        self.beta_ext, self.beta_tors = float(beta_link_ext), float(beta_link_tors)
        self.beta_shear, self.beta_bend = float(beta_link_shear), float(beta_bend)
        self.s_gamma = 1.0 if shear_convention == "derived" else 2.0
        self.joint_damping_form = joint_damping_form
        self.n2 = 10 * n
        self.dof_index = self._dof_index()
        self.mass_matrix = self._mass_matrix()
        unit = self._unit_block()
        self._minv_perp = np.linalg.inv(unit[:8:2, :8:2])
        self._minv_par = np.linalg.inv(unit[8:, 8:])
        self.jac_sparsity = self._jac_sparsity()
        pat = self.jac_sparsity.tocoo()
        self._pattern_keys = pat.row.astype(np.int64) * self.n2 + pat.col     # sorted: canonical CSR order
        self._positions: dict = {}
        self.backend = "numba" if use_numba and ker.HAVE_NUMBA else "numpy"
        self._packed = ker.pack(self)

    # ------------------------------------------------------------------ layout
    @property
    def blocks(self) -> tuple[Block, ...]:
        """State blocks (section 2.1): ``u_0..u_3`` (n x 2 each) and ``w_0, w_1`` (n each)."""
        n = self.n_pins
        return (Block("chain.u_perp0", 2 * n, "m"), Block("chain.u_perp1", 2 * n, "m"),
                Block("chain.u_perp2", 2 * n, "-"), Block("chain.u_perp3", 2 * n, "-"),
                Block("chain.u_par0", n, "m"), Block("chain.u_par1", n, "m"))

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        n, e = self.n_pins, self.n_links
        return (
            OutputSpec("chain.link_tension", "N", "Elastic link tension sum_k c^k Delta^k (1.141).", e),
            OutputSpec("chain.plate_tension", "N", "Elastic plate tension c^k Delta^k, links x Kmax.", e * self.kmax),
            OutputSpec("chain.pin_axial_force", "N", "Pin axial force c_p Delta_p (1.136).", n),
            OutputSpec("chain.pin_moment_far", "N m",
                       "Pin bending moment at the far end, components along tau_p and n_p (2.4).", 2 * n),
            OutputSpec("chain.pin_moment_near", "N m",
                       "Pin bending moment at the near end, components along tau_p and n_p (2.4).", 2 * n),
            OutputSpec("chain.twist", "rad", "Link twist angle phi (1.146).", e),
            OutputSpec("chain.shear", "rad", "Link shear strain gamma (1.153), derived convention.", e),
            OutputSpec("chain.pin_tilt_shear", "m", "t_n = u_1 . tau_p: pin tilt in the running direction (x l/2).", n),
            OutputSpec("chain.pin_tilt_twist", "m", "t_tau = u_1 . n_p: pin tilt about the running direction (x l/2).", n),
        )

    def _dof_index(self) -> np.ndarray:
        """``(n, 10)`` positions in ``q`` of each pin's ``u_0x, u_0y, .., u_3y, w_0, w_1``."""
        n, p = self.n_pins, np.arange(self.n_pins)
        perp = [i * 2 * n + 2 * p + c for i in range(4) for c in range(2)]
        return np.stack(perp + [8 * n + p, 9 * n + p], 1)

    def split(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(u (4, n, 2), w (2, n))`` views of a state or velocity vector."""
        n = self.n_pins
        return q[:8 * n].reshape(4, n, 2), q[8 * n:].reshape(2, n)

    def join(self, u: np.ndarray, w: np.ndarray) -> np.ndarray:
        return np.concatenate([u.reshape(-1), w.reshape(-1)])

    def rest_state(self, centres: np.ndarray, axial: np.ndarray | None = None) -> np.ndarray:
        """Straight, unbent pins parallel to ``k`` at in-plane ``centres (n, 2)`` m, mid-points at ``axial`` m."""
        n = self.n_pins
        u = np.zeros((4, n, 2))
        u[0] = centres
        w = np.stack([np.zeros(n) if axial is None else np.asarray(axial, float), np.full(n, self.l / 2)])
        return self.join(u, w)

    def from_raw(self, far: np.ndarray, near: np.ndarray, slope_far: np.ndarray, slope_near: np.ndarray) -> np.ndarray:
        """State from the raw end coordinates (2.1): end points ``(n, 3)`` m and end slopes ``dU_perp/ds (n, 2)``."""
        far, near = np.asarray(far, float), np.asarray(near, float)
        u1 = (near[:, :2] - far[:, :2]) / 2
        u = np.stack([(near[:, :2] + far[:, :2]) / 2, u1, slope_far - 2 / self.l * u1, slope_near - 2 / self.l * u1])
        return self.join(u, np.stack([(near[:, 2] + far[:, 2]) / 2, (near[:, 2] - far[:, 2]) / 2]))

    def to_raw(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Inverse of :meth:`from_raw`: ``far, near (n, 3)`` m and ``slope_far, slope_near (n, 2)``."""
        u, w = self.split(q)
        far = np.column_stack([u[0] - u[1], w[0] - w[1]])
        near = np.column_stack([u[0] + u[1], w[0] + w[1]])
        return far, near, u[2] + 2 / self.l * u[1], u[3] + 2 / self.l * u[1]

    # ------------------------------------------------------------------ inertia
    def _unit_block(self) -> np.ndarray:
        """10 x 10 mass block of one pin for ``m_p = 1`` in the order of :attr:`dof_index` (1.135)."""
        l = self.l
        mp = _M_PERP * np.outer([1, 1, l, l], [1, 1, l, l])
        B = np.zeros((10, 10))
        B[:8, :8] = np.kron(mp, np.eye(2))
        B[8:, 8:] = _M_PAR
        return B

    def _mass_matrix(self) -> sp.csr_matrix:
        B = self._unit_block()
        idx = self.dof_index
        rows = np.repeat(idx[:, :, None], 10, 2)
        cols = np.repeat(idx[:, None, :], 10, 1)
        vals = self.m[:, None, None] * B[None]
        keep = vals != 0
        return sp.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(self.n2, self.n2))

    def kinetic_energy(self, v: np.ndarray) -> float:
        """``T = v^T M v / 2`` (J), (1.134)."""
        return 0.5 * float(v @ (self.mass_matrix @ v))

    def momentum(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float]:
        """Linear momentum ``(3,)`` (kg m/s) and angular momentum about the ``k`` axis through O (kg m^2/s).

        Both are conserved by the free chain: the energies are invariant under translations and
        rotations about ``k`` (the axial momentum is ``sum m_p w_0'``).
        """
        u, _ = self.split(q)
        pu, pw = self.split(self.mass_matrix @ v)
        return np.r_[pu[0].sum(0), pw[0].sum()], float(_cross(u, pu).sum())

    def accel(self, q: np.ndarray, v: np.ndarray, q_ext: np.ndarray | None = None) -> np.ndarray:
        """``M^{-1} (Q + Q_d + Q_ext)`` (per-pin block solve, no global factorisation)."""
        Q = self.forces(q, v)
        if q_ext is not None:
            Q = Q + q_ext
        qu, qw = self.split(Q)
        au = np.einsum("ij,jnc->inc", self._minv_perp, qu) / self.m[None, :, None]
        aw = self._minv_par @ qw / self.m[None, :]
        return self.join(au, aw)

    # ------------------------------------------------------------------ strains
    def _link_strains(self, u: np.ndarray, w: np.ndarray) -> dict:
        """Link differences, direction (1.138), stretches (1.140), twist (1.146), shear (1.153)."""
        L, l = self.L, self.l
        du = u[:, self._next] - u
        dw0 = w[0][self._next] - w[0]
        tt = du[0] / L[:, None]
        D = np.empty((4, self.n_pins))
        D[0] = 0.5 * L * (_dot(tt, tt) - 1.0)
        D[1:] = _dot(tt[None], du[1:])
        phi = 2 / l * _cross(du[1], tt)
        s1 = u[1] + u[1][self._next]
        gam = self.s_gamma * (_dot(s1, tt) / l + dw0 / L)
        return dict(du=du, tt=tt, D=D, phi=phi, s1=s1, gam=gam)

    def _link_rates(self, s: dict, vu: np.ndarray, vw: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Strain rates of (1.154)-(1.157): the same gradients applied to the velocities (1.164)."""
        L, l = self.L, self.l
        dv = vu[:, self._next] - vu
        dvw0 = vw[0][self._next] - vw[0]
        ttd = dv[0] / L[:, None]
        Dd = np.empty((4, self.n_pins))
        Dd[0] = _dot(s["tt"], dv[0])
        Dd[1:] = _dot(s["tt"][None], dv[1:]) + _dot(ttd[None], s["du"][1:])
        phid = 2 / l * (_cross(dv[1], s["tt"]) + _cross(s["du"][1], ttd))
        s1d = vu[1] + vu[1][self._next]
        gamd = self.s_gamma * ((_dot(s1d, s["tt"]) + _dot(s["s1"], ttd)) / l + dvw0 / L)
        return Dd, phid, gamd

    def _link_forces(self, s: dict, f: np.ndarray, ft: np.ndarray, fs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Generalized forces of link "stresses" ``f_i = dPi/dDelta_i``, ``ft = dPi/dphi``, ``fs = dPi/dgamma`` (2.8).

        Link gradients ``G_i = dPi/d(Delta u_i)`` are assembled as ``Q_p = G_{p,p+1} - G_{p-1,p}``.
        """
        L, l, tt, du, sg = self.L, self.l, s["tt"], s["du"], self.s_gamma
        G = np.empty((4, self.n_pins, 2))
        G[0] = (f[0][:, None] * tt + (f[1:, :, None] * du[1:]).sum(0) / L[:, None]
                + (2 * ft / (l * L))[:, None] * _kx(du[1]) + (sg * fs / (l * L))[:, None] * s["s1"])
        G[1] = f[1][:, None] * tt - (2 * ft / l)[:, None] * _kx(tt)
        G[2] = f[2][:, None] * tt
        G[3] = f[3][:, None] * tt
        Qu = G - G[:, self._prev]
        sh = (sg * fs / l)[:, None] * tt                 # shear acts on the sum u_{p,1} + u_{p+1,1}
        Qu[1] -= sh + sh[self._prev]
        gw = sg * fs / L
        Qw = np.zeros((2, self.n_pins))
        Qw[0] = gw - gw[self._prev]
        return Qu, Qw

    def _bisector(self, tt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pin section axes (1.103): ``|x_p|``, ``tau_p``, ``n_p`` from the weighted link directions."""
        wt = self.weight[:, None] * tt
        x = wt + wt[self._prev]
        r = np.sqrt(_dot(x, x))
        tau = x / r[:, None]
        return r, tau, _kx(tau)

    def _ahat(self, tau: np.ndarray, nv: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``a^ . y = A_tau (tau.y) tau + A_n (n.y) n`` (1.104), deflection form."""
        return (self.A_tau * _dot(tau, y))[..., None] * tau + (self.A_n * _dot(nv, y))[..., None] * nv

    def _scatter_axes(self, v: np.ndarray) -> np.ndarray:
        """Force on ``u_{p,0}`` of a per-pin ``dPi/dx_p`` vector: stencil of (1.162)/(1.167), sign as a force."""
        g, gm = self.g, self.g[self._prev]
        return g[:, None] * v[self._next] + (g - gm)[:, None] * v - gm[:, None] * v[self._prev]

    # ------------------------------------------------------------------ energies
    def potential_energy(self, q: np.ndarray) -> float:
        """``Pi = Pi^pins + Pi^links`` (J): (1.136), (1.137), (1.141), (1.146), (1.153)."""
        return float(sum(self.potential_parts(q).values()))

    def potential_parts(self, q: np.ndarray) -> dict[str, float]:
        """The terms of :meth:`potential_energy` (J): pin axial, pin bending, link extension, twist, shear."""
        u, w = self.split(q)
        s = self._link_strains(u, w)
        _, tau, nv = self._bisector(s["tt"])
        m2, m3 = (4 * u[2] + 2 * u[3]) / self.l, (2 * u[2] + 4 * u[3]) / self.l
        return {
            "pin_axial": 0.5 * float(self.c_pin @ (2 * w[1] - self.l) ** 2),
            "pin_bending": 0.5 * float((_dot(u[2], self._ahat(tau, nv, m2)) + _dot(u[3], self._ahat(tau, nv, m3))).sum()),
            "link_extension": 0.5 * float(np.einsum("ie,eij,je->", s["D"], self.cij, s["D"])),
            "link_twist": 0.5 * float(self.c_tors @ s["phi"] ** 2),
            "link_shear": 0.5 * float(self.c_shear @ s["gam"] ** 2),
        }

    def rayleigh(self, q: np.ndarray, v: np.ndarray) -> float:
        """Rayleigh function ``Phi`` (W), (1.154)-(1.159) and the joint damping (1.80)."""
        u, w = self.split(q)
        vu, vw = self.split(v)
        s = self._link_strains(u, w)
        Dd, phid, gamd = self._link_rates(s, vu, vw)
        r, tau, nv = self._bisector(s["tt"])
        nab = self._corotated_rates(u, vu, s, r, nv)
        m2, m3 = (4 * nab[0] + 2 * nab[1]) / self.l, (2 * nab[0] + 4 * nab[1]) / self.l
        oj = self._joint_rates(s, vu)[1]
        return float(0.5 * self.beta_ext * np.einsum("ie,eij,je->", Dd, self.cij, Dd)
                     + 0.5 * self.beta_tors * self.c_tors @ phid ** 2
                     + 0.5 * self.beta_shear * self.c_shear @ gamd ** 2
                     + 0.5 * self.b_pin @ (2 * vw[1]) ** 2
                     + 0.5 * self.beta_bend * (_dot(nab[0], self._ahat(tau, nv, m2))
                                               + _dot(nab[1], self._ahat(tau, nv, m3))).sum()
                     + 0.5 * self.b_joint @ oj ** 2)

    def _corotated_rates(self, u, vu, s, r, nv) -> np.ndarray:
        """``u_i^nabla = u_i' - omega_p k x u_i`` (i = 2, 3) with the spin rate (1.116)."""
        wt = self.weight[:, None] * (vu[0][self._next] - vu[0]) / self.L[:, None]
        omega = _dot(nv, wt + wt[self._prev]) / r
        return vu[2:] - omega[None, :, None] * _kx(u[2:])

    def _joint_rates(self, s: dict, vu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``W_e = d omega_e / d u'_{e+1,0}`` and joint rates ``omega^joint_p = omega_{p,p+1} - omega_{p-1,p}`` (1.82)-(1.83)."""
        tt = s["tt"]
        W = _kx(tt) / (self.L * _dot(tt, tt))[:, None]
        om = _dot(W, vu[0][self._next] - vu[0])
        return W, om - om[self._prev]

    # ------------------------------------------------------------------ forces
    def elastic_forces(self, q: np.ndarray) -> np.ndarray:
        """``Q = -dPi/dq`` (N; N m for the slope coordinates), spec 2.8."""
        return self._forces(q, None, elastic=True)

    def dissipative_forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``Q_d = -dPhi/dv``, spec 2.8 (exact joint gradient unless ``joint_damping_form="printed"``)."""
        return self._forces(q, v, elastic=False)

    def forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``Q + Q_d`` in one pass (the link strain gradients are shared, (1.164))."""
        return self._forces(q, v, elastic=True)

    def _forces(self, q: np.ndarray, v: np.ndarray | None, elastic: bool) -> np.ndarray:
        if self.backend == "numba":
            u, w = self.split(np.ascontiguousarray(q, dtype=float))
            vu, vw = (u, w) if v is None else self.split(np.ascontiguousarray(v, dtype=float))
            return self.join(*ker.forces(u, w, vu, vw, v is not None, elastic, *self._packed))
        return self._forces_numpy(q, v, elastic)

    def _forces_numpy(self, q: np.ndarray, v: np.ndarray | None, elastic: bool) -> np.ndarray:
        """Reference twin of the compiled kernel."""
        l = self.l
        u, w = self.split(q)
        s = self._link_strains(u, w)
        n = self.n_pins
        f, ft, fs = np.zeros((4, n)), np.zeros(n), np.zeros(n)
        if elastic:
            f += np.einsum("eij,je->ie", self.cij, s["D"])
            ft += self.c_tors * s["phi"]
            fs += self.c_shear * s["gam"]
        r, tau, nv = self._bisector(s["tt"])
        Qw_pin = np.zeros((2, n))
        Qu_pin = np.zeros((4, n, 2))
        daxes = np.zeros((n, 2))
        if elastic:
            m2, m3 = (4 * u[2] + 2 * u[3]) / l, (2 * u[2] + 4 * u[3]) / l
            Qu_pin[2] -= self._ahat(tau, nv, m2)
            Qu_pin[3] -= self._ahat(tau, nv, m3)
            daxes += ((self.A_tau - self.A_n) / r * (_dot(nv, u[2]) * _dot(tau, m2)
                                                     + _dot(nv, u[3]) * _dot(tau, m3)))[:, None] * nv   # v_p (1.163)
            Qw_pin[1] -= 2 * self.c_pin * (2 * w[1] - l)
        if v is not None:
            vu, vw = self.split(v)
            Dd, phid, gamd = self._link_rates(s, vu, vw)
            f += self.beta_ext * np.einsum("eij,je->ie", self.cij, Dd)
            ft += self.beta_tors * self.c_tors * phid
            fs += self.beta_shear * self.c_shear * gamd
            Qw_pin[1] -= 4 * self.b_pin * vw[1]
            if self.beta_bend:
                nab = self._corotated_rates(u, vu, s, r, nv)
                b2 = self._ahat(tau, nv, (4 * nab[0] + 2 * nab[1]) / l)
                b3 = self._ahat(tau, nv, (2 * nab[0] + 4 * nab[1]) / l)
                Qu_pin[2] -= self.beta_bend * b2
                Qu_pin[3] -= self.beta_bend * b3
                daxes += (self.beta_bend / r * (_dot(_kx(u[2]), b2) + _dot(_kx(u[3]), b3)))[:, None] * -nv  # w_p (1.167)
            if np.any(self.b_joint):
                W, oj = self._joint_rates(s, vu)
                tq = self.b_joint * oj
                if self.joint_damping_form == "exact":
                    G = (tq - tq[self._next])[:, None] * W
                    Qu_pin[0] += G - G[self._prev]
                else:
                    Qu_pin[0] += tq[:, None] * (W + W[self._prev])
        Qu, Qw = self._link_forces(s, f, ft, fs)
        Qu += Qu_pin
        Qu[0] += self._scatter_axes(daxes)
        return self.join(Qu, Qw + Qw_pin)

    # ------------------------------------------------------------------ loads
    def axis_points(self, q: np.ndarray, pins: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """Positions ``U_p(xi) (m, 3)`` (m) of points on the pin axes (1.133)."""
        u, w = self.split(q)
        pins, xi = np.asarray(pins), np.asarray(xi, float)
        h = shape_functions(xi, self.l)
        perp = np.einsum("im,imc->mc", h, u[:, pins])
        return np.column_stack([perp, w[0, pins] + xi * w[1, pins]])

    def point_loads(self, pins: np.ndarray, xi: np.ndarray, force: np.ndarray,
                    moment: np.ndarray | None = None) -> np.ndarray:
        """Generalized forces of forces ``(m, 3)`` N at axis points ``(pins, xi)`` and in-plane moments ``(m, 2)`` N m.

        Virtual work ``F . dU(xi) + M . d theta(xi)`` with ``theta = k x t_perp``, ``t_perp = (2/l) dU_perp/dxi``
        (1.143); at the ends this is the table of spec 2.7 (with the ``x k`` of erratum 4).
        """
        pins, xi = np.asarray(pins), np.asarray(xi, float)
        force = np.asarray(force, float).reshape(-1, 3)
        n = self.n_pins
        Qu, Qw = np.zeros((4, n, 2)), np.zeros((2, n))
        h = shape_functions(xi, self.l)
        for i in range(4):
            np.add.at(Qu[i], pins, h[i][:, None] * force[:, :2])
        np.add.at(Qw[0], pins, force[:, 2])
        np.add.at(Qw[1], pins, xi * force[:, 2])
        if moment is not None:
            mk = -_kx(np.asarray(moment, float).reshape(-1, 2))          # M x k
            dh = shape_slopes(xi, self.l)
            for i in range(1, 4):
                np.add.at(Qu[i], pins, (2 / self.l * dh[i])[:, None] * mk)
        return self.join(Qu, Qw)

    # ------------------------------------------------------------------ Jacobian blocks
    def stiffness_matrix(self, q: np.ndarray) -> sp.csr_matrix:
        """``K = dQ/dq`` of the elastic forces (N/m etc.), exact: ``-(J^T c J + sum sigma H)`` per term.

        With :meth:`damping_matrix` this is the exact linearisation at any state with ``v = 0`` (the
        dissipative forces are linear in ``v``); at ``v != 0`` it omits ``dQ_d/dq``.
        """
        n, l, sg = self.n_pins, self.l, self.s_gamma
        u, w = self.split(q)
        s = self._link_strains(u, w)
        gD, gphi, ggam = self._link_gradients(s)
        f = np.einsum("eij,je->ie", self.cij, s["D"])
        ft, fs = self.c_tors * s["phi"], self.c_shear * s["gam"]
        K = (np.einsum("eij,ien,jem->enm", self.cij, gD, gD, optimize=True) + self.c_tors[:, None, None] * gphi[:, :, None] * gphi[:, None]
             + self.c_shear[:, None, None] * ggam[:, :, None] * ggam[:, None])
        I2, E = np.eye(2), np.array([[0.0, 1.0], [-1.0, 0.0]])
        for a, sa in ((0, -1.0), (1, 1.0)):
            for b, sb in ((0, -1.0), (1, 1.0)):
                oa, ob = 10 * a, 10 * b
                K[:, oa:oa + 2, ob:ob + 2] += (sa * sb * f[0] / self.L)[:, None, None] * I2          # H of Delta_0
                for i in range(1, 4):                                                               # H of Delta_i
                    blk = (sa * sb * f[i] / self.L)[:, None, None] * I2
                    K[:, oa:oa + 2, ob + 2 * i:ob + 2 * i + 2] += blk
                    K[:, ob + 2 * i:ob + 2 * i + 2, oa:oa + 2] += blk
                blk = (sa * sb * ft * 2 / (l * self.L))[:, None, None] * E                           # H of phi
                K[:, oa + 2:oa + 4, ob:ob + 2] += blk
                K[:, ob:ob + 2, oa + 2:oa + 4] += np.swapaxes(blk, 1, 2)
                blk = (sb * sg * fs / (l * self.L))[:, None, None] * I2                              # H of gamma
                K[:, ob:ob + 2, oa + 2:oa + 4] += blk
                K[:, oa + 2:oa + 4, ob:ob + 2] += blk
        parts = [("link", self._link_index(), -K)]
        # pin axial (1.136) and pin bending (1.137) with the bisector axes (1.103)
        parts.append(("axial", self.dof_index[:, 9:10], np.full((n, 1, 1), -4.0) * self.c_pin[:, None, None]))
        parts.append(("bend", self._bend_index(), -self._bending_hessian(u, s)))
        return self._assemble(parts)

    def damping_matrix(self, q: np.ndarray) -> sp.csr_matrix:
        """``C = dQ/dv`` (N s/m etc.), exact: the dissipative forces are linear in ``v`` (1.154)-(1.159), (1.80)."""
        n, l = self.n_pins, self.l
        u, w = self.split(q)
        s = self._link_strains(u, w)
        gD, gphi, ggam = self._link_gradients(s)
        C = (self.beta_ext * np.einsum("eij,ien,jem->enm", self.cij, gD, gD, optimize=True)
             + (self.beta_tors * self.c_tors)[:, None, None] * gphi[:, :, None] * gphi[:, None]
             + (self.beta_shear * self.c_shear)[:, None, None] * ggam[:, :, None] * ggam[:, None])
        parts = [("link", self._link_index(), -C),
                 ("axial", self.dof_index[:, 9:10], np.full((n, 1, 1), -4.0) * self.b_pin[:, None, None])]
        # co-rotated bending rates u_i^nabla = B_i v_loc over (u_0 of p-1, p, p+1; u_2, u_3 of p)
        r, tau, nv = self._bisector(s["tt"])
        lam = np.stack([-self.g[self._prev], self.g[self._prev] - self.g, self.g], 1)        # dx_p/du_0
        B = np.zeros((2, n, 2, 10))
        for i in range(2):
            kxu = _kx(u[2 + i])
            for m in range(3):
                B[i, :, :, 2 * m:2 * m + 2] = -(lam[:, m] / r)[:, None, None] * kxu[:, :, None] * nv[:, None, :]
            B[i, :, :, 6 + 2 * i:8 + 2 * i] = np.eye(2)
        ahat = self.A_tau * tau[:, :, None] * tau[:, None] + self.A_n * nv[:, :, None] * nv[:, None]
        cb = np.array([[4.0, 2.0], [2.0, 4.0]]) / l
        Cb = np.einsum("ij,ienx,enm,jemy->exy", cb, B, ahat, B, optimize=True)
        parts.append(("bend", self._bend_index(), -self.beta_bend * Cb))
        # joints: omega^joint_p = g_p . (v_0 of p-1, p, p+1), g = (W_{p-1}, -W_{p-1} - W_p, W_p)
        W, _ = self._joint_rates(s, np.zeros_like(u))
        Wm = W[self._prev]
        gj = np.concatenate([Wm, -Wm - W, W], 1)
        jidx = self._bend_index()[:, :6]
        if self.joint_damping_form == "exact":
            parts.append(("joint", jidx, -self.b_joint[:, None, None] * gj[:, :, None] * gj[:, None]))
        else:                                      # printed (1.165): rows of pin p only
            rows = np.zeros((n, 6, 6))
            rows[:, 2:4] = self.b_joint[:, None, None] * (W + Wm)[:, :, None] * gj[:, None]
            parts.append(("joint", jidx, rows))
        return self._assemble(parts)

    def _link_gradients(self, s: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Gradients of ``Delta_i`` (4, n, 20), ``phi`` and ``gamma`` (n, 20) over the 20 coordinates of a link's pins."""
        n, l, L, sg, tt, du = self.n_pins, self.l, self.L, self.s_gamma, s["tt"], s["du"]
        gD, gphi, ggam = np.zeros((4, n, 20)), np.zeros((n, 20)), np.zeros((n, 20))
        for a, sa in ((0, -1.0), (1, 1.0)):
            o = 10 * a
            gD[0, :, o:o + 2] = sa * tt
            for i in range(1, 4):
                gD[i, :, o:o + 2] = sa * du[i] / L[:, None]
                gD[i, :, o + 2 * i:o + 2 * i + 2] = sa * tt
            gphi[:, o:o + 2] = sa * (2 / (l * L))[:, None] * _kx(du[1])
            gphi[:, o + 2:o + 4] = -sa * 2 / l * _kx(tt)
            ggam[:, o:o + 2] = sa * sg * s["s1"] / (l * L)[:, None]
            ggam[:, o + 2:o + 4] = sg * tt / l
            ggam[:, o + 8] = sa * sg / L
        return gD, gphi, ggam

    def _bending_hessian(self, u: np.ndarray, s: dict) -> np.ndarray:
        """Hessian (n, 10, 10) of ``Pi^pin,bend_p`` over (u_0 of p-1, p, p+1; u_2, u_3 of p)."""
        n, l = self.n_pins, self.l
        r, tau, nv = self._bisector(s["tt"])
        dA = self.A_tau - self.A_n
        cb = np.array([[4.0, 2.0], [2.0, 4.0]]) / l
        U = u[2:]                                                    # (2, n, 2)
        a = _dot(tau[None], U)                                       # tau . u_i
        b = _dot(nv[None], U)                                        # n . u_i
        g = b[:, :, None] * nv[None] / r[None, :, None]              # d a_i / dx
        ca = cb @ a                                                   # sum_j c_ij a_j
        tn = tau[:, :, None] * nv[:, None] + nv[:, :, None] * tau[:, None]
        nn = nv[:, :, None] * nv[:, None]
        Hxx = dA * (np.einsum("ij,inx,jny->nxy", cb, g, g)
                    - np.einsum("in,in,nxy->nxy", ca, b, tn) / r[:, None, None] ** 2
                    - np.einsum("in,in,nxy->nxy", ca, a, nn) / r[:, None, None] ** 2)
        H = np.zeros((n, 10, 10))
        lam = np.stack([-self.g[self._prev], self.g[self._prev] - self.g, self.g], 1)
        ahat = self.A_tau * tau[:, :, None] * tau[:, None] + self.A_n * nn
        cg = np.einsum("ij,inx->jnx", cb, g)                          # sum_i c_ik g_i
        for k in range(2):
            Hxu = dA * ((ca[k] / r)[:, None, None] * nn + cg[k][:, :, None] * tau[:, None])   # d2/dx du_k
            for m in range(3):
                H[:, 2 * m:2 * m + 2, 6 + 2 * k:8 + 2 * k] = lam[:, m, None, None] * Hxu
                H[:, 6 + 2 * k:8 + 2 * k, 2 * m:2 * m + 2] = lam[:, m, None, None] * np.swapaxes(Hxu, 1, 2)
            for j in range(2):
                H[:, 6 + 2 * k:8 + 2 * k, 6 + 2 * j:8 + 2 * j] = cb[k, j] * ahat
        for m in range(3):
            for mm in range(3):
                H[:, 2 * m:2 * m + 2, 2 * mm:2 * mm + 2] = (lam[:, m] * lam[:, mm])[:, None, None] * Hxx
        return H

    def _link_index(self) -> np.ndarray:
        return np.concatenate([self.dof_index, self.dof_index[self._next]], 1)

    def _bend_index(self) -> np.ndarray:
        d = self.dof_index
        return np.concatenate([d[self._prev, :2], d[:, :2], d[self._next, :2], d[:, 4:8]], 1)

    def _assemble(self, parts) -> sp.csr_matrix:
        """Sum named local blocks ``(name, index (n, k), values (n, k, k))`` on the structure of :attr:`jac_sparsity`.

        The positions of each index set in the pattern's CSR data are computed once; a call is then
        one ``bincount`` (explicit zeros of the pattern are kept).
        """
        pat = self.jac_sparsity
        pos = []
        for key, idx, _ in parts:
            if key not in self._positions:
                rows = np.broadcast_to(idx[:, :, None], idx.shape + idx.shape[1:]).ravel()
                cols = np.broadcast_to(idx[:, None, :], idx.shape + idx.shape[1:]).ravel()
                self._positions[key] = np.searchsorted(self._pattern_keys, rows.astype(np.int64) * self.n2 + cols)
            pos.append(self._positions[key])
        data = np.bincount(np.concatenate(pos), weights=np.concatenate([v.ravel() for _, _, v in parts]),
                           minlength=pat.nnz)
        return sp.csr_matrix((data, pat.indices, pat.indptr), shape=pat.shape)

    # ------------------------------------------------------------------ Jacobian pattern
    def _jac_sparsity(self) -> sp.csr_matrix:
        """Pattern of ``dQ/dq`` and ``dQ/dv``: pin ``p`` couples to pins ``p-2..p+2`` (bisector axes and joints, spec 8)."""
        n = self.n_pins
        P = np.arange(n)
        pairs = []
        for d in range(-2, 3):
            r = P + d
            ok = np.ones(n, bool) if self.closed else (r >= 0) & (r < n)
            pairs.append(np.column_stack([P[ok], r[ok] % n]))
        pairs = np.unique(np.concatenate(pairs), axis=0)
        idx = self.dof_index
        rows = np.repeat(idx[pairs[:, 0]][:, :, None], 10, 2).ravel()
        cols = np.repeat(idx[pairs[:, 1]][:, None, :], 10, 1).ravel()
        pattern = sp.csr_matrix((np.ones(rows.size, bool), (rows, cols)), shape=(self.n2, self.n2))
        pattern.sort_indices()
        return pattern

    # ------------------------------------------------------------------ outputs
    def outputs(self, q: np.ndarray, v: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Values of :attr:`output_specs` (elastic parts; ``v`` unused, kept for the model interface)."""
        u, w = self.split(q)
        s = self._link_strains(u, w)
        e = self.n_links
        h = shape_functions(self.plate_xi, self.l)
        _, tau, nv = self._bisector(s["tt"])
        out = {"chain.link_tension": np.einsum("ej,je->e", self.cij[:, 0], s["D"])[:e],
               "chain.plate_tension": (self.plate_c * np.einsum("iek,ie->ek", h, s["D"][:, :e])).ravel(),
               "chain.pin_axial_force": self.c_pin * (2 * w[1] - self.l)}
        for name, k2, k3 in (("far", -4.0, -2.0), ("near", 2.0, 4.0)):
            kappa = _kx(k2 * u[2] + k3 * u[3]) / self.l                 # curvature (2.4) at xi = -1 / +1
            M = np.column_stack([self.A_n * _dot(tau, kappa), self.A_tau * _dot(nv, kappa)])
            out[f"chain.pin_moment_{name}"] = M.ravel()
        out["chain.twist"] = s["phi"][:e]
        out["chain.shear"] = s["gam"][:e] / self.s_gamma
        out["chain.pin_tilt_shear"] = _dot(u[1], tau)
        out["chain.pin_tilt_twist"] = _dot(u[1], nv)
        return out
