"""Pin halves: model A5 (independent halves, 21 coordinates per pin) and the A2 contact layer over A1.

Spec chain-models-2.md section 5 (eqs. (1.211)-(1.221)) and section 3 (eq. (1.210)), with the
errata of section 9 (items 12, 13, 16) and the digest's energy-consistent proposal for the contacts
the source does not give (half-half rolling, half against the other half's plates; a project-defined
extension).  SI units throughout.

**A5 coordinates.** Each half ``p-`` / ``p+`` of pin ``p`` carries the ten coordinates of A1 (section
2.1): in-plane ``u_0..u_3`` and axial ``w_0, w_1``; the plate pack around pin ``p`` adds ``q_p`` (its
axial position, m).  ``q = [half - (A1 layout, 10 n), half + (10 n), q_pack (n)]``.  The plates of link
``e = (p, p+1)`` are attached to ``p-`` and ``(p+1)+``; ``p-`` is the rear half (``-h_pin tau``),
``p+`` the front one, so the pitch ``L`` of link ``e`` (the distance of the attached half axes) is the
pin pitch plus ``2 h_pin``.  Half ``p-`` takes its section axes from link ``(p, p+1)`` turned by
``+gamma_0``, half ``p+`` from link ``(p-1, p)`` turned by ``-gamma_0`` (1.215); the end pins of an
open segment take those of their only link.

**Potential energy.** Half axial (1.214) and bending (1.216) with half stiffnesses; per-plate
strains between the halves at the variable stations (1.211)-(1.212) (factor ``2/l``, erratum 12)
with the A3/A4 plate law of :mod:`plates` (``plate_model``), their gradients including the station
terms; link twist (1.146) over the cross-half differences (1.217); stoppers ``k_*`` with free play
(erratum 13); three contacts per pin, each between two circular arcs fixed in the frames of two
halves, evaluated at two Gauss stations along the pin: the rolling faces of ``p-`` and ``p+``
(convex-convex) and the hole contour of each link's plates around the foreign half's back face
(concave-convex), with penalty energy ``(l/2) w_s k [-g_s]_+^2 / 2`` and its full gradient (link
angles included).  An optional tangential tie ``k_t g_t^2 / 2`` on the holonomic rolling slip locks
the halves (conservative; a bilateral glue, for the locked-halves limit only).

**Dissipation.** Rayleigh functions: half axial ``b (2 w_1')^2 / 2``, co-rotational half bending
(section 5.4 with the corrected spin rates, erratum 16), plate extension/shear (1.192)-(1.193),
twist, joint damping (1.80) with the exact gradient, contact normal damping while closed.  Friction
(not a gradient, forces by virtual work): the axial law (1.221) half/half and half/pack with the link
tension proxies, and regularised Coulomb on the rolling slip of every contact (digest proposal), all
through :mod:`cvtfem.elements.contact.friction`.

**Backends.** With ``use_numba`` :meth:`ChainA5.forces` runs the whole pass in the compiled
:mod:`halves_kernel` (plate ends as virtual whole pins, the per-plate law of ``plates_kernel``); the numpy
pass here is its tested twin.  The Jacobian is assembled element by element in the kernel (exact velocity
blocks of the links, differences of single links and pins), or coloured central differences of the forces on
the 5-pin stencil.

**A2** (:class:`CoupledHalvesA2`): the whole pins of :class:`ChainA1` with two half-pin end points
per pin end, ``U(xi_e) +- h_pin tau_p`` (1.210), and the exact virtual work of a force there.
"""
from __future__ import annotations

import copy
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from cvtfem.elements.chain import halves_kernel as HK
from cvtfem.elements.chain import halves_slips_kernel as HSK
from cvtfem.elements.chain import plates as P
from cvtfem.elements.chain import plates_kernel as PK
from cvtfem.elements.chain.asymmetric import (_M_PAR, _M_PERP, ChainA1, _cross, _dot, _kx, shape_functions,
                                              shape_slopes)
from cvtfem.elements.chain.implicit_friction import FrictionSet, friction_step
from cvtfem.elements.contact.friction import LAWS, friction_gain
from cvtfem.errors import InputError
from cvtfem.outputs import OutputSpec

#: Gauss stations and weights of the half-half and half-plate contacts along the pin (sum of weights 2).
GAUSS_XI = np.array([-1.0, 1.0]) / np.sqrt(3.0)
GAUSS_W = np.array([1.0, 1.0])
PLATE_MODELS = ("A4", "A3", "A3-keep")
#: Contacts per pin: (name, carrier half A, other half B, sigma): sigma +1 convex-convex, -1 B inside A's hole.
CONTACTS = (("roll", 0, 1, 1.0), ("hole_next", 0, 1, -1.0), ("hole_prev", 1, 0, -1.0))
TERMS = ("half_axial", "half_bending", "plates", "twist", "contacts", "stoppers")


def shape_curvatures(xi: np.ndarray, l: float) -> np.ndarray:
    """``d^2 h_i / dxi^2`` of (1.132) at ``xi``, shape ``(4,) + xi.shape`` (m for i = 2, 3)."""
    xi = np.asarray(xi, float)
    z = np.zeros_like(xi)
    return np.stack([z, z, l / 8 * (6 * xi - 2), l / 8 * (6 * xi + 2)])


def _rot(v: np.ndarray, c: float, s: float) -> np.ndarray:
    """In-plane vectors ``v (..., 2)`` turned by the angle with cosine ``c``, sine ``s`` about ``k``."""
    return c * v + s * _kx(v)


class ChainA5:
    """Model A5 of a whole chain with independent pin halves (spec section 5), vectorised over pins and plates.

    Parameters (per-link arrays have ``n`` rows, the last ignored for an open segment; per-plate
    arrays ``(n, Kmax)``, entries beyond ``n_plates`` ignored)
    ----------
    pitch : (n,) m
        Plate pitch ``L``: distance of the attached half axes (``p-`` to ``(p+1)+``).
    plate_offset : (n, Kmax) m
        Axial offsets ``d^k`` of the plates from the pack coordinate (1.211).
    n_plates : (n,) int
        Plates per link.
    plate_stiffness, plate_bending_stiffness : (n, Kmax) N/m, N m^2
        ``c^k`` and the out-of-plane bending stiffness ``a^k`` (``c_1 = 4a/L``, ``c_2 = 2a/L``).
    plate_thickness : m
        ``h`` of the A4 moment bound ``|M| <= T h/2``.
    plate_torsion_stiffness : (n, Kmax) N m/rad
        Torsion stiffness of each plate; a link twists with their sum (1.146).
    plate_mass : (n,) kg
        Plate mass of each link (1.213).
    pin_length : m
        ``l``.
    pin_mass : (n,) kg
        Pin mass (both halves) ``m^pin``.
    pin_axial_stiffness : N/m
        ``c_p`` of the whole pin; each half ``c_p / 2`` (1.214).
    half_bending_tau, half_bending_n : N m^2
        Bending stiffness of one half against deflection along its ``tau`` and its ``n`` (1.216).
    gamma0 : rad
        Turn of each half's section axes against its link (1.215).
    h_pin : m
        Half the distance of the half axes.
    roll_radius : (R-, R+) m
        Radii of the rolling faces.
    roll_stiffness, roll_damping, roll_tie : N/m^2, N s/m^2, N/m^2
        Normal penalty per unit length, its damping while closed, tangential tie (0: none).
    hole_radius, back_radius, back_extent, hole_clearance : m
        Plate hole contour ``R_h``, foreign half's back face ``r``, its extent ``s_f`` from the pin
        centre and the clearance ``c_0`` of the straight chain (``R_h - r - c_0 > 0``).
    hole_stiffness : N/m^2
        Normal penalty of the half-plate contact.
    stopper_stiffness, stopper_play : N/m, m
        ``k_* = 3 a_* / l_*^3`` and ``d_p`` of the stoppers (erratum 13).
    friction_coefficient, friction_speed, friction_law
        ``f_0``, ``v_0`` (m/s) and the law of :mod:`friction` for (1.221) and the contacts.
    plate_model : "A4" | "A3" | "A3-keep"
        Plate law: bounded moment, clamped dropping compressed plates, clamped keeping them.
    half_axial_damping : N s/m; beta_plate_ext, beta_plate_shear, beta_twist, beta_bend : s;
    joint_damping : N m s/rad
        Rayleigh damping (section 5.4).
    closed : bool
        Closed loop or open segment (link ``n-1`` absent).
    use_numba : bool
        :meth:`forces` runs in the compiled :mod:`halves_kernel` (each plate end mapped to a virtual whole
        pin at ``xi = 0``); the numpy pass is its tested reference twin.
    """

    def __init__(self, *, pitch, plate_offset, n_plates, plate_stiffness, plate_bending_stiffness,
                 plate_thickness: float, plate_torsion_stiffness, plate_mass, pin_length: float, pin_mass,
                 pin_axial_stiffness: float, half_bending_tau: float, half_bending_n: float,
                 gamma0: float = np.radians(5.0), h_pin: float, roll_radius=(0.004, 0.004),
                 roll_stiffness: float, roll_damping: float = 0.0, roll_tie: float = 0.0,
                 hole_radius: float, back_radius: float, back_extent: float, hole_clearance: float,
                 hole_stiffness: float, stopper_stiffness: float, stopper_play: float,
                 friction_coefficient: float = 0.0, friction_speed: float = 1e-3,
                 friction_law: str = "linear-saturated", plate_model: str = "A4",
                 half_axial_damping: float = 0.0, beta_plate_ext: float = 0.0, beta_plate_shear: float = 0.0,
                 beta_twist: float = 0.0, beta_bend: float = 0.0, joint_damping: float = 0.0,
                 closed: bool = True, use_numba: bool = True) -> None:
        m = np.asarray(pin_mass, float)
        n = m.size
        if m.ndim != 1 or n < 3 or np.any(m <= 0):
            raise InputError("pin_mass", pin_mass, "1-d, at least 3 pins, all > 0")
        L = np.asarray(pitch, float)
        if L.shape != (n,) or np.any(L <= 0):
            raise InputError("pitch", L.shape, f"({n},) positive pitches")
        d = np.atleast_2d(np.asarray(plate_offset, float))
        npl = np.asarray(n_plates, int)
        kmax = d.shape[1]
        if d.shape[0] != n or npl.shape != (n,) or np.any(npl < 1) or np.any(npl > kmax):
            raise InputError("plate_offset/n_plates", (d.shape, npl.shape), f"({n}, Kmax) and ({n},), 1..Kmax")
        if plate_model not in PLATE_MODELS:
            raise InputError("plate_model", plate_model, f"one of {PLATE_MODELS}")
        if friction_law not in LAWS:
            raise InputError("friction_law", friction_law, f"one of {LAWS}")
        for key, val in (("pin_length", pin_length), ("half_bending_tau", half_bending_tau),
                         ("half_bending_n", half_bending_n), ("h_pin", h_pin), ("plate_thickness", plate_thickness),
                         ("friction_speed", friction_speed)):
            if not val > 0:
                raise InputError(key, val, "> 0")
        R = np.broadcast_to(np.asarray(roll_radius, float), (2,))
        if np.any(R <= 0) or not 0 < back_radius < hole_radius - hole_clearance or hole_clearance < 0:
            raise InputError("roll_radius/back_radius/hole_radius/hole_clearance",
                             (tuple(R), back_radius, hole_radius, hole_clearance),
                             "radii > 0 and 0 < back_radius < hole_radius - hole_clearance, clearance >= 0")
        mask = (np.arange(kmax)[None, :] < npl[:, None])
        link_w = np.ones(n) if closed else np.r_[np.ones(n - 1), 0.0]
        self.n_pins, self.kmax, self.closed, self.l = n, kmax, closed, float(pin_length)
        self.L, self.link_w = L, link_w
        p = np.arange(n)
        self._next, self._prev = (p + 1) % n, (p - 1) % n
        lm, lp = p.copy(), (p - 1) % n                      # links giving the axes of halves - and + (1.215)
        if not closed:
            lm[n - 1], lp[0] = n - 2, 0
        self.axis_link = np.stack([lm, lp])
        self.plate_w = mask * link_w[:, None]

        def fill(a):
            """Padded plates copy plate 0 (weight 0; keeps the plate law free of 0/0)."""
            return np.where(mask, a, a[:, :1])

        self.plate_d = fill(d)
        self.plate_c = fill(np.broadcast_to(np.asarray(plate_stiffness, float), d.shape))
        a = fill(np.broadcast_to(np.asarray(plate_bending_stiffness, float), d.shape))
        self.plate_c1, self.plate_c2 = P.bending_stiffnesses(a, L[:, None])
        self.plate_h = float(plate_thickness)
        self.plate_model = plate_model
        self.c_twist = np.sum(np.broadcast_to(np.asarray(plate_torsion_stiffness, float), d.shape) * mask, 1) * link_w
        mpl = np.broadcast_to(np.asarray(plate_mass, float), (n,)) * link_w
        self.m_half = np.stack([0.5 * m + 0.5 * mpl, 0.5 * m + 0.5 * mpl[self._prev]])     # m-, m+ (1.213)
        self.m_axial = 0.5 * m
        self.m_pack = 0.5 * (mpl + mpl[self._prev])
        if np.any(self.m_pack <= 0):
            raise InputError("plate_mass", plate_mass, "> 0 (the pack needs a mass)")
        self.c_half = 0.5 * float(pin_axial_stiffness)
        self.b_half = float(half_axial_damping)
        self.A_tau, self.A_n = float(half_bending_tau), float(half_bending_n)
        self.gamma0 = float(gamma0)
        self._cs = np.array([[np.cos(gamma0), np.sin(gamma0)], [np.cos(gamma0), -np.sin(gamma0)]])  # turn of -, +
        h, cg, sg = float(h_pin), np.cos(gamma0), np.sin(gamma0)
        sf, c0, Rh, r = float(back_extent), float(hole_clearance), float(hole_radius), float(back_radius)
        self.h_pin, self.roll_radius = h, R
        # contact arcs: centre offsets (along tau, n of the half), radius, rest distance rho_0, stiffness
        self._arcs = {
            "roll": ((h - R[0]) * np.array([cg, -sg]), R[0], (R[1] - h) * np.array([cg, sg]), R[1],
                     R[0] + R[1], float(roll_stiffness)),
            "hole_next": ((sf + c0 - Rh + h) * np.array([cg, -sg]), Rh, (sf - r - h) * np.array([cg, sg]), r,
                          Rh - r, float(hole_stiffness)),
            "hole_prev": ((sf + c0 - Rh + h) * np.array([-cg, -sg]), Rh, (sf - r - h) * np.array([-cg, sg]), r,
                          Rh - r, float(hole_stiffness)),
        }
        self._contact_w = {"roll": np.ones(n), "hole_next": link_w.copy(), "hole_prev": link_w[self._prev].copy()}
        self.roll_stiffness, self.b_roll, self.k_tie = float(roll_stiffness), float(roll_damping), float(roll_tie)
        self.k_stop, self.d_stop = float(stopper_stiffness), float(stopper_play)
        self.f0, self.v0, self.law = float(friction_coefficient), float(friction_speed), friction_law
        self.beta_ext, self.beta_shear = float(beta_plate_ext), float(beta_plate_shear)
        self.beta_twist, self.beta_bend = float(beta_twist), float(beta_bend)
        self.b_joint = float(joint_damping) * (lm != lp)
        self.n2 = 21 * n
        self.dof_index = self._dof_index()
        self.mass_matrix = self._mass_matrix()
        self.inverse_mass = self._mass_matrix(inverse=True)
        self.jac_sparsity = self._jac_sparsity()
        self.backend = "numba" if use_numba and HK.HAVE_NUMBA else "numpy"
        self._kmodel = {"A4": PK.A4, "A3": PK.A3_DROP, "A3-keep": PK.A3_KEEP}[plate_model]
        self._kernel_args = HK.pack(self, CONTACTS)
        self._positions = None                  # CSR positions of the compiled Jacobian's blocks, at first use

    # ------------------------------------------------------------------ layout
    def _dof_index(self) -> np.ndarray:
        """``(n, 21)`` positions of each pin's coordinates: half - (A1 order), half + (A1 order), ``q_p``."""
        n, p = self.n_pins, np.arange(self.n_pins)
        one = [i * 2 * n + 2 * p + c for i in range(4) for c in range(2)] + [8 * n + p, 9 * n + p]
        return np.stack(one + [10 * n + j for j in one] + [20 * n + p], 1)

    def split(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Views ``u (2, 4, n, 2)``, ``w (2, 2, n)`` (half -, half +) and ``q_pack (n,)``."""
        n = self.n_pins
        y = q[:20 * n].reshape(2, 10 * n)
        return y[:, :8 * n].reshape(2, 4, n, 2), y[:, 8 * n:].reshape(2, 2, n), q[20 * n:]

    def join(self, u: np.ndarray, w: np.ndarray, qp: np.ndarray) -> np.ndarray:
        n = self.n_pins
        return np.concatenate([np.concatenate([u.reshape(2, 8 * n), w.reshape(2, 2 * n)], 1).ravel(), qp])

    def rest_state(self, centres: np.ndarray, tau: np.ndarray, axial=None) -> np.ndarray:
        """Straight unbent halves at ``centres -+ h_pin tau`` (``(n, 2)`` m, unit ``tau (n, 2)``), pack at ``axial``."""
        n, h = self.n_pins, self.h_pin
        u = np.zeros((2, 4, n, 2))
        u[0, 0], u[1, 0] = centres - h * tau, centres + h * tau
        z = np.zeros(n) if axial is None else np.asarray(axial, float)
        w = np.stack([np.stack([z, np.full(n, self.l / 2)])] * 2)
        return self.join(u, w, z.copy())

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        n, k = self.n_pins, self.kmax
        return (OutputSpec("chain.link_tension", "N", "Sum of the plate tensions of each link.", n),
                OutputSpec("chain.plate_tension", "N", "Plate tension T = c Delta~, links x Kmax.", n * k),
                OutputSpec("chain.plate_state", "1", "Plate contact state 1..10 (10 slack), links x Kmax.", n * k),
                OutputSpec("chain.pin_half_axial_force", "N", "Half axial force c_p/2 Delta (1.214), half -, half +.",
                           2 * n),
                OutputSpec("chain.roll_force", "N", "Normal force of the half-half rolling contact of each pin.", n),
                OutputSpec("chain.half_slip", "m/s", "Axial slip w_0+' - w_0-' of the halves (1.221).", n),
                OutputSpec("chain.half_pack_slip", "m/s", "Axial slip w_0' - q' of half -, half + on the pack.", 2 * n),
                OutputSpec("chain.friction_power", "W", "Power of all friction forces at each pin (<= 0).", n),
                OutputSpec("chain.twist", "rad", "Link twist angle phi (1.146).", n))

    # ------------------------------------------------------------------ inertia
    def _mass_matrix(self, inverse: bool = False) -> sp.csr_matrix:
        """Constant block-diagonal mass (1.213): per half ``m_perp (x) I_2`` and ``m^pin/2 diag(1, 1/3)``, pack ``m^q``;
        with ``inverse`` its inverse (block by block, the same pattern)."""
        l, n = self.l, self.n_pins
        mp = np.kron(_M_PERP * np.outer([1, 1, l, l], [1, 1, l, l]), np.eye(2))
        mpar, p = _M_PAR, 1.0
        if inverse:
            mp, mpar, p = np.linalg.inv(mp), np.linalg.inv(_M_PAR), -1.0
        rows, cols, vals = [], [], []
        for hf in range(2):
            idx = self.dof_index[:, 10 * hf:10 * hf + 10]
            blk = np.zeros((n, 10, 10))
            blk[:, :8, :8] = self.m_half[hf][:, None, None] ** p * mp
            blk[:, 8:, 8:] = self.m_axial[:, None, None] ** p * mpar
            rows.append(np.repeat(idx[:, :, None], 10, 2).ravel())
            cols.append(np.repeat(idx[:, None, :], 10, 1).ravel())
            vals.append(blk.ravel())
        rows.append(self.dof_index[:, 20])
        cols.append(self.dof_index[:, 20])
        vals.append(self.m_pack ** p)
        M = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(self.n2,) * 2)
        M.eliminate_zeros()
        return M

    def kinetic_energy(self, v: np.ndarray) -> float:
        """``T = v^T M v / 2`` (J), (1.213)."""
        return 0.5 * float(v @ (self.mass_matrix @ v))

    def momentum(self, v: np.ndarray) -> np.ndarray:
        """Linear momentum (kg m/s): in-plane (sum over ``u_0`` rows of ``M v``) and axial (``w_0`` and pack rows)."""
        pu, pw, pq = self.split(self.mass_matrix @ v)
        return np.r_[pu[:, 0].sum((0, 1)), pw[:, 0].sum() + pq.sum()]

    def accel(self, q: np.ndarray, v: np.ndarray, q_ext: np.ndarray | None = None) -> np.ndarray:
        """``M^{-1} (Q + Q_ext)`` with the block-diagonal inverse :attr:`inverse_mass`."""
        Q = self.forces(q, v)
        return self.inverse_mass @ (Q if q_ext is None else Q + q_ext)

    # ------------------------------------------------------------------ geometry
    def _frames(self, u: np.ndarray) -> dict:
        """Link vectors ``x_e = u+_{e+1,0} - u-_{e,0}``, ``rho_e``, ``tau_e``, ``n_e`` and the half axes (2, n, 2)."""
        x = u[1, 0][self._next] - u[0, 0]
        rho = np.sqrt(_dot(x, x))
        tau = x / rho[:, None]
        th = np.stack([_rot(tau[self.axis_link[hf]], *self._cs[hf]) for hf in range(2)])
        return dict(x=x, rho=rho, tau=tau, nl=_kx(tau), th=th, nh=_kx(th))

    def _link_rates(self, fr: dict, vu: np.ndarray) -> np.ndarray:
        """``theta_e' = n_e . x_e' / rho_e`` (rad/s), the spin rate of every link."""
        return _dot(fr["nl"], vu[1, 0][self._next] - vu[0, 0]) / fr["rho"]

    def _scatter_angles(self, gth: np.ndarray, fr: dict, gu: np.ndarray) -> None:
        """Add a gradient over the link angles ``(n,)`` to the ``u_0`` gradients (``d theta_e = n_e . dx_e / rho_e``)."""
        gx = (gth / fr["rho"])[:, None] * fr["nl"]
        gu[1, 0][self._next] += gx
        gu[0, 0] -= gx

    def _half_to_links(self, gh: np.ndarray) -> np.ndarray:
        """Gradient over half angles ``(2, n)`` -> over link angles ``(n,)`` (1.215)."""
        n = self.n_pins
        return np.bincount(self.axis_link[0], gh[0], n) + np.bincount(self.axis_link[1], gh[1], n)

    # ------------------------------------------------------------------ evaluation
    def _evaluate(self, q: np.ndarray, v: np.ndarray | None, terms=TERMS) -> dict:
        """Energies ``Pi`` (J) and ``Phi`` (W) per term, ``dPi/dq``, ``dPhi/dv`` and the friction forces (vectors)."""
        n, l = self.n_pins, self.l
        u, w, qp = self.split(np.asarray(q, float))
        have_v = v is not None
        vu, vw, vq = self.split(np.asarray(v, float)) if have_v else (0 * u, 0 * w, 0 * qp)
        fr = self._frames(u)
        thd = self._link_rates(fr, vu)
        thd_h = thd[self.axis_link]                                       # half spin rates (2, n)
        gu, gw, gq, gth_h = np.zeros_like(u), np.zeros_like(w), np.zeros(n), np.zeros((2, n))
        du, dw, dq, dth_h = np.zeros_like(u), np.zeros_like(w), np.zeros(n), np.zeros((2, n))
        fu, fw, fq, fth_h = np.zeros_like(u), np.zeros_like(w), np.zeros(n), np.zeros((2, n))
        Pi, Phi, out = {}, {}, {}
        fpow = np.zeros(n)
        if "half_axial" in terms:                                         # (1.214), section 5.4
            s = 2 * w[:, 1] - l
            Pi["half_axial"] = 0.5 * self.c_half * float(np.sum(s * s))
            gw[:, 1] += 2 * self.c_half * s
            Phi["half_axial"] = 0.5 * self.b_half * float(np.sum((2 * vw[:, 1]) ** 2))
            dw[:, 1] += 4 * self.b_half * vw[:, 1]
            out["chain.pin_half_axial_force"] = (self.c_half * s).ravel()
        if "half_bending" in terms:                                       # (1.216), section 5.4
            self._half_bending(u, vu, fr, thd_h, Pi, Phi, gu, gth_h, du, dth_h)
        T_link = np.zeros(n)
        if "plates" in terms or "twist" in terms:
            gl, dl = self._links(u, w, qp, vu, vw, vq, terms, Pi, Phi, out)
            T_link = out.get("chain.link_tension", T_link)
            self._scatter_links(gl, gu, gw, gq)
            self._scatter_links(dl, du, dw, dq)
        if "contacts" in terms:
            self._contacts(u, vu, fr, thd_h, Pi, Phi, out, gu, gth_h, du, dth_h, fu, fth_h, fpow)
        if "stoppers" in terms:
            s = w[:, 0] - qp
            g = np.maximum(np.abs(s) - self.d_stop, 0.0)
            Pi["stoppers"] = 0.5 * self.k_stop * float(np.sum(g * g))
            f = self.k_stop * g * np.sign(s)
            gw[:, 0] += f
            gq -= f.sum(0)
        # axial friction (1.221) with the link tension proxies, and the joint damping (1.80)
        v_hh = vw[1, 0] - vw[0, 0]
        v_hp = vw[:, 0] - vq
        out["chain.half_slip"], out["chain.half_pack_slip"] = v_hh, v_hp.ravel()
        if self.f0 and have_v and "plates" in terms:
            Tp = np.maximum(T_link, 0.0)
            N_hh, N_hp = 0.5 * (Tp + Tp[self._prev]), np.stack([Tp, Tp[self._prev]])
            R_hh = -N_hh * friction_gain(np.abs(v_hh), self.f0, self.v0, self.law) * v_hh
            R_hp = -N_hp * friction_gain(np.abs(v_hp), self.f0, self.v0, self.law) * v_hp
            fw[1, 0] += R_hh
            fw[0, 0] -= R_hh
            fw[:, 0] += R_hp
            fq -= R_hp.sum(0)
            fpow += R_hh * v_hh + (R_hp * v_hp).sum(0)
        if np.any(self.b_joint):
            oj = thd[self.axis_link[0]] - thd[self.axis_link[1]]
            Phi["joint"] = 0.5 * float(self.b_joint @ (oj * oj))
            tq = self.b_joint * oj
            dth_h += np.stack([tq, -tq])
        out["chain.friction_power"] = fpow
        dth = self._half_to_links(dth_h)
        self._scatter_angles(self._half_to_links(gth_h), fr, gu)
        self._scatter_angles(dth, fr, du)
        self._scatter_angles(self._half_to_links(fth_h), fr, fu)
        return dict(Pi=Pi, Phi=Phi, grad=self.join(gu, gw, gq), gradv=self.join(du, dw, dq),
                    friction=self.join(fu, fw, fq), out=out)

    def _half_bending(self, u, vu, fr, thd_h, Pi, Phi, gu, gth_h, du, dth_h) -> None:
        """Half bending (1.216) with axes turning with the links, and its co-rotational damping (section 5.4)."""
        l, tau, nv = self.l, fr["th"], fr["nh"]

        def ahat(y):
            return (self.A_tau * _dot(tau, y))[..., None] * tau + (self.A_n * _dot(nv, y))[..., None] * nv

        U = u[:, 2:].transpose(1, 0, 2, 3)                                  # (2 kinds, 2 halves, n, 2)
        m = np.stack([4 * U[0] + 2 * U[1], 2 * U[0] + 4 * U[1]]) / l
        am = ahat(m)
        Pi["half_bending"] = 0.5 * float(np.sum(U * am))
        gu[:, 2:] += am.transpose(1, 0, 2, 3)
        gth_h += (self.A_tau - self.A_n) * np.sum(_dot(nv, U) * _dot(tau, m), 0)
        if self.beta_bend:
            nab = vu[:, 2:].transpose(1, 0, 2, 3) - thd_h[None, :, :, None] * _kx(U)
            mb = ahat(np.stack([4 * nab[0] + 2 * nab[1], 2 * nab[0] + 4 * nab[1]]) / l)
            Phi["half_bending"] = 0.5 * self.beta_bend * float(np.sum(nab * mb))
            du[:, 2:] += self.beta_bend * mb.transpose(1, 0, 2, 3)
            dth_h -= self.beta_bend * np.sum(_dot(_kx(U), mb), 0)

    def _links(self, u, w, qp, vu, vw, vq, terms, Pi, Phi, out):
        """Per-plate strains at the variable stations (1.211)-(1.212), (1.219)-(1.220), the plate law, twist.

        Returns the link-local gradients ``dPi/dy``, ``dPhi/dy'`` ``(n, 22)`` over (half - of ``e``, half + of
        ``e+1``, ``q_e``, ``q_{e+1}``).
        """
        l, L, nx = self.l, self.L, self._next
        um, up, wm, wp = u[0], u[1][:, nx], w[0], w[1][:, nx]
        y = np.concatenate([um.transpose(1, 0, 2).reshape(-1, 8), wm.T, up.transpose(1, 0, 2).reshape(-1, 8), wp.T,
                            qp[:, None], qp[nx][:, None]], 1)
        yd = np.concatenate([vu[0].transpose(1, 0, 2).reshape(-1, 8), vw[0].T,
                             vu[1][:, nx].transpose(1, 0, 2).reshape(-1, 8), vw[1][:, nx].T,
                             vq[:, None], vq[nx][:, None]], 1)
        g_loc, d_loc = np.zeros((self.n_pins, 22)), np.zeros((self.n_pins, 22))
        if "plates" in terms:
            eps, J = self._plate_strains(um, up, wm, wp, qp, qp[nx])
            c, c1, c2, wgt = self.plate_c, self.plate_c1, self.plate_c2, self.plate_w
            if self.plate_model == "A4":
                st = P.plate_state(eps, c, c1, c2, self.plate_h)
            else:
                st = P.clamped_plate_state(eps, c, c1, c2, drop_compressed=self.plate_model == "A3")
            epsd = np.einsum("ekij,ej->eki", J, yd)
            f_el = P.strain_forces(st, 0 * epsd, c, c1, c2, 0.0, 0.0)
            f_all = P.strain_forces(st, epsd, c, c1, c2, self.beta_ext, self.beta_shear)
            g_loc -= np.einsum("ekji,ekj,ek->ei", J, f_el, wgt)
            d_loc -= np.einsum("ekji,ekj,ek->ei", J, f_all - f_el, wgt)
            Pi["plates"] = float(np.sum(wgt * st.energy))
            Phi["plates"] = float(np.sum(wgt * P.rayleigh(st, epsd, c, c1, c2, self.beta_ext, self.beta_shear)))
            T = st.tension * wgt
            out["chain.plate_tension"] = T.ravel()
            out["chain.plate_state"] = np.where(wgt > 0, st.state, P.SLACK).ravel().astype(float)
            out["chain.link_tension"] = T.sum(1)
        if "twist" in terms:                                              # (1.146) with (1.217)
            d0, d1 = y[:, 10:12] - y[:, 0:2], y[:, 12:14] - y[:, 2:4]
            k = 2 / (l * L)
            phi = k * _cross(d1, d0)
            Jp = np.zeros((self.n_pins, 22))
            Jp[:, 10:12], Jp[:, 12:14] = k[:, None] * _kx(d1), -k[:, None] * _kx(d0)
            Jp[:, 0:4] = -Jp[:, 10:14]
            phid = np.sum(Jp * yd, 1)
            Pi["twist"] = 0.5 * float(self.c_twist @ phi ** 2)
            Phi["twist"] = 0.5 * self.beta_twist * float(self.c_twist @ phid ** 2)
            g_loc += (self.c_twist * phi)[:, None] * Jp
            d_loc += (self.beta_twist * self.c_twist * phid)[:, None] * Jp
            out["chain.twist"] = phi * self.link_w
        return g_loc, d_loc

    def _plate_strains(self, um, up, wm, wp, qa, qb):
        """``eps = (psi_1, psi_2, Delta)`` (n, K, 3) of every plate and ``d eps / dy`` (n, K, 3, 22)."""
        l, L = self.l, self.L[:, None]
        xi = [2 / l * (qa[:, None] - wm[0][:, None] + self.plate_d), 2 / l * (qb[:, None] - wp[0][:, None] + self.plate_d)]
        U, dU, tp, dtp, Hs, Hps = [], [], [], [], [], []
        for uu, ww, x in ((um, wm, xi[0]), (up, wp, xi[1])):
            H, Hp, Hpp = shape_functions(x, l), shape_slopes(x, l), shape_curvatures(x, l)
            Up = np.einsum("iek,iec->ekc", H, uu)
            Upr = np.einsum("iek,iec->ekc", Hp, uu)                       # dU_perp / dxi
            U.append(np.concatenate([Up, (ww[0][:, None] + ww[1][:, None] * x)[..., None]], -1))
            dU.append(np.concatenate([Upr, np.broadcast_to(ww[1][:, None, None], Upr.shape[:2] + (1,))], -1))
            tp.append(2 / l * Upr)
            dtp.append(2 / l * np.einsum("iek,iec->ekc", Hpp, uu))
            Hs.append(H)
            Hps.append(Hp)
        V = U[1] - U[0]
        Lt = np.sqrt(np.sum(V * V, -1))
        tau = V / Lt[..., None]
        t = [np.concatenate([tp[a], np.ones(Lt.shape + (1,))], -1) for a in range(2)]
        psi = [np.sum(tau * t[a], -1) for a in range(2)]
        e = [(t[a] - tau * psi[a][..., None]) / Lt[..., None] for a in range(2)]
        eps = np.stack([psi[0], psi[1], Lt - L], -1)
        J = np.zeros(Lt.shape + (3, 22))
        for b, sgn in ((0, -1.0), (1, 1.0)):                             # half - (cols 0..9), half + (10..19)
            o, H, Hp, x = 10 * b, Hs[b], Hps[b], xi[b]
            for i in range(4):
                for c in range(2):
                    col = o + 2 * i + c
                    for a in range(2):
                        J[..., a, col] = sgn * H[i] * e[a][..., c] + (2 / l * Hp[i] * tau[..., c] if a == b else 0.0)
                    J[..., 2, col] = sgn * H[i] * tau[..., c]
            for a in range(2):
                J[..., a, o + 8], J[..., a, o + 9] = sgn * e[a][..., 2], sgn * x * e[a][..., 2]
            J[..., 2, o + 8], J[..., 2, o + 9] = sgn * tau[..., 2], sgn * x * tau[..., 2]
            dV = sgn * dU[b]                                              # d V / d xi_b
            dx = np.stack([np.sum(e[0] * dV, -1), np.sum(e[1] * dV, -1), np.sum(tau * dV, -1)], -1)
            dx[..., b] += np.sum(tau[..., :2] * dtp[b], -1)
            J[..., 20 + b] += 2 / l * dx                                  # xi_b grows with q (1.212)
            J[..., o + 8] -= 2 / l * dx                                   # and falls with w_0 of the half
        return eps, J

    def _scatter_links(self, g: np.ndarray, gu: np.ndarray, gw: np.ndarray, gq: np.ndarray) -> None:
        """Add link-local ``(n, 22)`` gradients to the half and pack arrays."""
        nx = self._next
        gu[0] += g[:, 0:8].reshape(-1, 4, 2).transpose(1, 0, 2)
        gw[0] += g[:, 8:10].T
        gu[1][:, nx] += g[:, 10:18].reshape(-1, 4, 2).transpose(1, 0, 2)
        gw[1][:, nx] += g[:, 18:20].T
        gq += g[:, 20]
        gq[nx] += g[:, 21]

    def _contacts(self, u, vu, fr, thd_h, Pi, Phi, out, gu, gth_h, du, dth_h, fu, fth_h, fpow) -> None:
        """The three arc contacts of every pin (digest proposal, section 5.3): penalty, damping, tie, friction."""
        l = self.l
        H = shape_functions(GAUSS_XI, l)                                  # (4, S)
        Ux = np.einsum("is,hinc->hsnc", H, u)                             # half axes at the stations
        Vx = np.einsum("is,hinc->hsnc", H, vu)
        ws = (l / 2 * GAUSS_W)[:, None]                                   # (S, 1) lengths
        Pi["contacts"], Phi["contacts"] = 0.0, 0.0
        for name, A, B, sig in CONTACTS:
            offA, RA, offB, RB, rho0, k = self._arcs[name]
            wgt = ws * self._contact_w[name][None]                        # (S, n)
            rA = offA[0] * fr["th"][A] + offA[1] * fr["nh"][A]            # lever C - U (n, 2)
            rB = offB[0] * fr["th"][B] + offB[1] * fr["nh"][B]
            d = Ux[B] + rB - Ux[A] - rA                                   # (S, n, 2)
            rho = np.sqrt(_dot(d, d))
            nn = d / rho[..., None]
            tt = _kx(nn)
            g = sig * (rho - rho0)
            pen = np.maximum(-g, 0.0)
            N = wgt * k * pen                                             # normal force per station, N
            Pi["contacts"] += 0.5 * float(np.sum(wgt * k * pen * pen))
            # dg = sig n . (dU_B - dU_A + (k x r_B) dth_B - (k x r_A) dth_A)
            kA, kB = _kx(rA), _kx(rB)
            self._add_pair(gu, gth_h, -N * sig, nn, kA, kB, A, B, H)
            gdot = sig * (_dot(nn, Vx[B] - Vx[A]) + _dot(nn, kB) * thd_h[B] - _dot(nn, kA) * thd_h[A])
            if self.b_roll and name == "roll":
                cl = wgt * self.b_roll * (g < 0)
                Phi["contacts"] += 0.5 * float(np.sum(cl * gdot * gdot))
                self._add_pair(du, dth_h, cl * gdot * sig, nn, kA, kB, A, B, H)
            if self.k_tie and name == "roll":                            # g_t = R_A ang(n, tau_A) + R_B ang(n, tau_B)
                ta, tb = fr["tau"][self.axis_link[A]], fr["tau"][self.axis_link[B]]
                gt = RA * np.arctan2(_cross(nn, ta), _dot(nn, ta)) + RB * np.arctan2(_cross(nn, tb), _dot(nn, tb))
                Pi["contacts"] += 0.5 * self.k_tie * float(np.sum(wgt * gt * gt))
                s = wgt * self.k_tie * gt                                 # dPi/dg_t
                # d g_t = R_A dth_A + R_B dth_B - (R_A + R_B) t . dd / rho
                cf = -(RA + RB) / rho * s
                self._add_pair(gu, gth_h, cf, tt, kA, kB, A, B, H)
                gth_h[A] += np.sum(s * RA, 0)
                gth_h[B] += np.sum(s * RB, 0)
            if name == "roll":
                out["chain.roll_force"] = N.sum(0)
            if self.f0 and np.any(N):                                     # regularised Coulomb on the rolling slip
                vs = _dot(tt, Vx[B] - Vx[A]) + (_dot(tt, kB) - sig * RB) * thd_h[B] - (_dot(tt, kA) + RA) * thd_h[A]
                Ft = -N * friction_gain(np.abs(vs), self.f0, self.v0, self.law) * vs
                self._add_pair(fu, fth_h, Ft, tt, kA, kB, A, B, H)
                fth_h[B] -= np.sum(Ft * sig * RB, 0)
                fth_h[A] -= np.sum(Ft * RA, 0)
                fpow += np.sum(Ft * vs, 0)

    @staticmethod
    def _add_pair(gu, gth_h, s, vec, kA, kB, A, B, H) -> None:
        """Add ``s vec . (dU_B - dU_A + kB dth_B - kA dth_A)`` summed over stations (``s (S, n)``, ``vec (S, n, 2)``)."""
        sv = s[..., None] * vec
        gu[B] += np.einsum("is,snc->inc", H, sv)
        gu[A] -= np.einsum("is,snc->inc", H, sv)
        gth_h[B] += np.sum(_dot(sv, kB), 0)
        gth_h[A] -= np.sum(_dot(sv, kA), 0)

    # ------------------------------------------------------------------ public energies and forces
    def potential_parts(self, q: np.ndarray, terms=TERMS) -> dict[str, float]:
        """Terms of the potential energy (J): half axial, half bending, plates, twist, contacts, stoppers."""
        return self._evaluate(q, None, terms)["Pi"]

    def potential_energy(self, q: np.ndarray, terms=TERMS) -> float:
        """``Pi`` (J) of the named :data:`TERMS` (all by default)."""
        return float(sum(self.potential_parts(q, terms).values()))

    def rayleigh(self, q: np.ndarray, v: np.ndarray) -> float:
        """Rayleigh function ``Phi`` (W); the dissipative forces dissipate ``2 Phi``."""
        return float(sum(self._evaluate(q, v)["Phi"].values()))

    def elastic_forces(self, q: np.ndarray, terms=TERMS) -> np.ndarray:
        """``-dPi/dq`` of the named :data:`TERMS` (all by default)."""
        return -self._evaluate(q, None, terms)["grad"]

    def dissipative_forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``-dPhi/dv``."""
        return -self._evaluate(q, v)["gradv"]

    def friction_forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Friction forces by virtual work: axial (1.221) and on the rolling slip of the contacts."""
        return self._evaluate(q, v)["friction"]

    def with_roll_tie(self, roll_tie: float) -> "ChainA5":
        """The same chain with the rolling tie ``k_t`` (N/m^2) instead of its own (the quasi-static start of the chain
        on the sheaves releases it in steps)."""
        tied = copy.copy(self)
        tied.k_tie = float(roll_tie)
        tied._kernel_args = HK.pack(tied, CONTACTS)
        return tied

    def without_friction(self) -> "ChainA5":
        """The same chain with ``f_0 = 0``: the forces less the halves' internal friction (the explicit part of the
        split of :meth:`friction_slips`)."""
        free = copy.copy(self)
        free.f0 = 0.0
        free._kernel_args = HK.pack(free, CONTACTS)
        return free

    def link_tensions(self, q: np.ndarray) -> np.ndarray:
        """Link tensions (N) of the plates at ``q``: the normal-force proxies of the axial friction (1.221)."""
        if self.backend == "numba":
            a = self._kernel_args
            return HK.link_tensions(np.asarray(q, float), a[0], *a[2:4], *a[6:11], a[15], a[16])
        return self.outputs(q)["chain.link_tension"]

    def friction_slips(self, q: np.ndarray, groups: bool = False) -> tuple:
        """``(B, c)``: with the positions ``q`` frozen every slip of the halves' internal friction is linear in the
        velocities, ``s = B v`` (m/s; rows: the half-half axial slip of each pin, the half-pack slips of half -, half +,
        then the rolling slip of each contact and Gauss station where it is closed), and the friction forces are
        ``F = -B^T (c psi(|s|) s)`` with the normal forces ``c`` (N) and the law's gain ``psi`` (:meth:`friction_forces`
        exactly, to round-off).  With ``groups`` also each row's group: 0 axial half-half, 1 axial half-pack, then
        ``2 + k`` for contact ``k`` of :data:`CONTACTS` (rolling, hole of the next link, of the previous one)."""
        n, di, l = self.n_pins, self.dof_index, self.l
        u = self.split(np.asarray(q, float))[0]
        p = np.arange(n)
        Tp = np.maximum(self.link_tensions(q), 0.0)
        pattern = getattr(self, "_slip_pattern", None)                  # rows and columns: the same at every q
        rows, cols, vals, c = [], [], [], []

        def add(block_rows, block_cols, block_vals):
            if pattern is None:
                rows.append(np.broadcast_to(block_rows, block_vals.shape).ravel())
                cols.append(np.broadcast_to(block_cols, block_vals.shape).ravel())
            vals.append(block_vals.ravel())

        one = np.ones(n)
        add(p, di[:, 18], one)                                            # v_hh = w_0+' - w_0-'
        add(p, di[:, 8], -one)
        c.append(0.5 * (Tp + Tp[self._prev]))
        for hf, Tn in ((0, Tp), (1, Tp[self._prev])):                    # v_hp = w_0' - q'
            add(n * (1 + hf) + p, di[:, 10 * hf + 8], one)
            add(n * (1 + hf) + p, di[:, 20], -one)
            c.append(Tn)
        if pattern is not None and self.backend == "numba":                # the compiled twin of the loop below
            roll = np.empty(len(CONTACTS) * len(GAUSS_XI) * 24 * n)
            N = np.empty((len(CONTACTS), len(GAUSS_XI), n))
            HSK.rolling_slip_values(u, self._next, self.axis_link, self._cs, *self._slip_constants, roll, N)
            vals.append(roll)
            c.append(N.ravel())
            return self._slips_out(pattern, vals, c, groups)
        fr = self._frames(u)
        H = shape_functions(GAUSS_XI, l)                                  # (4, S)
        Ux = np.einsum("is,hinc->hsnc", H, u)
        ws = (l / 2 * GAUSS_W)[:, None]
        m = 3 * n
        al, ic = self.axis_link, np.arange(2)
        for name, A, Bh, sig in CONTACTS:
            offA, RA, offB, RB, rho0, k = self._arcs[name]
            rA = offA[0] * fr["th"][A] + offA[1] * fr["nh"][A]
            rB = offB[0] * fr["th"][Bh] + offB[1] * fr["nh"][Bh]
            d = Ux[Bh] + rB - Ux[A] - rA
            rho = np.sqrt(_dot(d, d))
            tt = _kx(d / rho[..., None])
            N = ws * self._contact_w[name][None] * k * np.maximum(-sig * (rho - rho0), 0.0)    # (S, n)
            coef = {Bh: _dot(tt, _kx(rB)) - sig * RB, A: -(_dot(tt, _kx(rA)) + RA)}          # on thd of each half
            for s_ in range(len(GAUSS_XI)):
                r = m + p
                for h_, sgn in ((Bh, 1.0), (A, -1.0)):
                    cu = di[:, 10 * h_ + 2 * np.arange(4)[:, None] + ic[None, :]]           # (n, 4, 2)
                    add(r[:, None, None], cu, sgn * H[:, s_][None, :, None] * tt[s_][:, None, :])
                    e = al[h_]                                            # thd_e = nl_e . (U+_{e+1} - U-_e)' / rho_e
                    g = (coef[h_][s_] / fr["rho"][e])[:, None] * fr["nl"][e]
                    add(r[:, None], di[self._next[e]][:, 10 + ic], g)
                    add(r[:, None], di[e][:, ic], -g)
                c.append(N[s_])
                m += n
        if pattern is None:                         # the CSR pattern and where each value adds in it, built once
            key = np.concatenate(rows) * self.n2 + np.concatenate(cols)
            unique, where = np.unique(key, return_inverse=True)
            indptr = np.searchsorted(unique // self.n2, np.arange(m + 1))
            pattern = self._slip_pattern = (where, unique % self.n2, indptr)
        return self._slips_out(pattern, vals, c, groups)

    def _slips_out(self, pattern, vals, c, groups) -> tuple:
        """:meth:`friction_slips`' rows from the values ``vals`` on the CSR ``pattern``, those with ``c > 0``."""
        n = self.n_pins
        where, indices, indptr = pattern
        c = np.concatenate(c)
        keep = np.flatnonzero(c > 0)
        B = sp.csr_matrix(HSK.kept_rows(where, np.concatenate(vals), indices, indptr, keep), shape=(len(keep), self.n2))
        if not groups:
            return B, c[keep]
        label = np.concatenate([np.zeros(n, int), np.ones(2 * n, int), np.repeat(2 + np.arange(len(CONTACTS)),
                                                                                 len(GAUSS_XI) * n)])
        return B, c[keep], label[keep]

    @property
    def _slip_constants(self) -> tuple:
        """The constant arguments of :func:`~.halves_slips_kernel.rolling_slip_values` after ``cs``."""
        if getattr(self, "_slip_consts", None) is None:
            arcs = [self._arcs[name] for name, *_ in CONTACTS]
            self._slip_consts = (
                shape_functions(GAUSS_XI, self.l), self.l / 2 * GAUSS_W,
                np.array([[A, B, sig] for _, A, B, sig in CONTACTS], float),
                np.array([[a[0], a[2]] for a in arcs], float), np.array([[a[1], a[3]] for a in arcs], float),
                np.array([a[4] for a in arcs], float), np.array([a[5] for a in arcs], float),
                np.array([self._contact_w[name] for name, *_ in CONTACTS], float))
        return self._slip_consts

    def friction_step(self, B: sp.csr_matrix, c: np.ndarray, v_star: np.ndarray, h: float, v_start=None,
                      tol: float = 1e-6, max_lu: int = 100) -> tuple[np.ndarray, float, int]:
        """Backward Euler of the halves' friction alone with the positions frozen: ``v`` with
        ``M (v - v_star) = h F(v)``, ``F = -B^T (c psi(|Bv|) Bv)`` (:meth:`friction_slips`), by
        :func:`~cvtfem.elements.chain.implicit_friction.friction_step` from ``v_start`` (default ``v_star``) to
        ``tol v_0``.  Returns ``(v, W, LUs)`` with the work the step dissipates ``W = -h F(v) . (v + v_star) / 2`` (J):
        the kinetic energy it removes."""
        fs = FrictionSet(B, c, 1, self.f0, self.v0, self.law)
        return friction_step(self.mass_matrix, self.inverse_mass, [fs], v_star, h, v_start, tol=tol, max_lu=max_lu)

    def forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``Q = -dPi/dq - dPhi/dv + Q_friction`` in one pass (:func:`halves_kernel.forces` with ``use_numba``)."""
        if self.backend == "numba":
            return HK.forces(np.asarray(q, float), np.asarray(v, float), *self._kernel_args)
        r = self._evaluate(q, v)
        return r["friction"] - r["grad"] - r["gradv"]

    def forces_and_dissipation(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float]:
        """``(Q, D)``: :meth:`forces` and the power dissipated by its damping and friction parts, ``D = 2 Phi - P_fr``
        (W, >= 0) in the same pass (:func:`halves_kernel.forces_power` with ``use_numba``)."""
        if self.backend == "numba":
            Q, D = HK.forces_power(np.asarray(q, float), np.asarray(v, float), *self._kernel_args)
            return Q, float(D)
        r = self._evaluate(q, v)
        return (r["friction"] - r["grad"] - r["gradv"],
                2 * float(sum(r["Phi"].values())) - float(np.sum(r["out"]["chain.friction_power"])))

    def outputs(self, q: np.ndarray, v: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Values of :attr:`output_specs` (slips and friction power need ``v``; zero without)."""
        return self._evaluate(q, np.zeros(self.n2) if v is None else v)["out"]

    # ------------------------------------------------------------------ loads at the half ends
    def _half_view(self) -> SimpleNamespace:
        """An A1-shaped view of one half's coordinates for :meth:`ChainA1.axis_points` / ``point_loads``."""
        n = self.n_pins
        return SimpleNamespace(n_pins=n, l=self.l, split=lambda y: (y[:8 * n].reshape(4, n, 2), y[8 * n:].reshape(2, n)),
                               join=lambda u, w: np.concatenate([u.reshape(-1), w.reshape(-1)]))

    def axis_points(self, q: np.ndarray, pins: np.ndarray, half: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """Points ``U^{half}_p(xi) (m, 3)`` m on the half axes (``half`` 0 = ``p-``, 1 = ``p+``)."""
        n, view = self.n_pins, self._half_view()
        pins, half, xi = np.asarray(pins), np.asarray(half), np.asarray(xi, float)
        out = np.zeros((pins.size, 3))
        for hf in range(2):
            sel = half == hf
            out[sel] = ChainA1.axis_points(view, q[10 * n * hf:10 * n * (hf + 1)], pins[sel], xi[sel])
        return out

    def point_loads(self, pins: np.ndarray, half: np.ndarray, xi: np.ndarray, force: np.ndarray,
                    moment: np.ndarray | None = None) -> np.ndarray:
        """Generalized forces of forces ``(m, 3)`` N and in-plane moments ``(m, 2)`` N m at half-axis points
        (spec 2.7 per half)."""
        n, view = self.n_pins, self._half_view()
        pins, half, xi = np.asarray(pins), np.asarray(half), np.asarray(xi, float)
        force = np.asarray(force, float).reshape(-1, 3)
        Q = np.zeros(self.n2)
        for hf in range(2):
            sel = half == hf
            mom = None if moment is None else np.asarray(moment, float).reshape(-1, 2)[sel]
            Q[10 * n * hf:10 * n * (hf + 1)] = ChainA1.point_loads(view, pins[sel], xi[sel], force[sel], mom)
        return Q

    # ------------------------------------------------------------------ Jacobian
    def _jac_sparsity(self) -> sp.csr_matrix:
        """Pin ``p`` couples to pins ``p-2..p+2`` (contacts and joints reach the neighbours' links)."""
        n = self.n_pins
        p = np.arange(n)
        pairs = []
        for dd in range(-2, 3):
            r = p + dd
            ok = np.ones(n, bool) if self.closed else (r >= 0) & (r < n)
            pairs.append(np.column_stack([p[ok], r[ok] % n]))
        pairs = np.unique(np.concatenate(pairs), axis=0)
        idx = self.dof_index
        rows = np.repeat(idx[pairs[:, 0]][:, :, None], 21, 2).ravel()
        cols = np.repeat(idx[pairs[:, 1]][:, None, :], 21, 1).ravel()
        pat = sp.csr_matrix((np.ones(rows.size, bool), (rows, cols)), shape=(self.n2, self.n2))
        pat.sort_indices()
        return pat

    def jacobian(self, q: np.ndarray, v: np.ndarray, damping: bool = True,
                 scheme: str = "analytic") -> tuple[sp.csr_matrix, sp.csr_matrix | None]:
        """``(dQ/dq, dQ/dv)`` of :meth:`forces` on :attr:`jac_sparsity`; ``damping=False`` returns None for ``dQ/dv``.

        Compiled backend: element by element (:func:`halves_kernel.jacobian`): each link's velocity block exact,
        its coordinate block by ``scheme``: "analytic" (default; exact within the plates' states: the strain
        Hessians, the state law's Jacobian and the curvature of the moving plate stations,
        :func:`halves_kernel._link_jacobian`), or "central" (step ``1e-7``) or "forward" (step ``sqrt(eps)``, relative
        to ``max(|x|, l)``) differences of that link alone, kept as its cross-check; each pin's coordinate block
        (bending, contacts, friction) central differences of the pin alone (step ``1e-7 max(|x|, l)``), its velocity
        block exact in one pass (dampers and the friction laws' slopes, :func:`halves_kernel._pin_velocity_block`);
        the axial friction's tension dependence by the chain rule.  Forward differences are one-sided at the kinks
        of the plate law and the contacts: Newton from the exact straight chain diverged with them.
        numpy backend: :meth:`coloured_jacobian`.
        """
        if scheme not in ("analytic", "forward", "central"):
            raise InputError("scheme", scheme, 'must be "analytic", "forward" or "central"')
        if self.backend != "numba":
            return self.coloured_jacobian(q, v, damping=damping)
        Jq, Jv, _, _ = self.jacobian_and_power_gradient(q, v, scheme)
        return Jq, Jv if damping else None

    def jacobian_and_power_gradient(self, q: np.ndarray, v: np.ndarray, scheme: str = "analytic") -> tuple:
        """``(dQ/dq, dQ/dv, dD/dq, dD/dv)`` of the compiled backend: :meth:`jacobian`'s matrices and the gradient
        (W/m, W s/m; arrays (21 n,)) of the dissipated power ``D`` of :meth:`forces_and_dissipation` from the same
        element passes (:func:`halves_kernel.jacobian`)."""
        pat = self.jac_sparsity
        Jq, Jv, dDq, dDv = self.jacobian_data(q, v, scheme)
        out = [sp.csr_matrix((d[:-1], pat.indices, pat.indptr), shape=pat.shape) for d in (Jq, Jv)]
        return out[0], out[1], dDq, dDv

    def jacobian_data(self, q: np.ndarray, v: np.ndarray, scheme: str = "analytic") -> tuple:
        """:meth:`jacobian_and_power_gradient` with the matrices as their CSR data on :attr:`jac_sparsity` (each
        ``nnz + 1`` long: the last a spare slot of the kernel), for a caller that assembles them itself."""
        if self.backend != "numba":
            raise InputError("backend", self.backend, 'must be "numba" for the power gradient of the element passes')
        if scheme not in ("analytic", "forward", "central"):
            raise InputError("scheme", scheme, 'must be "analytic", "forward" or "central"')
        pat = self.jac_sparsity
        if self._positions is None:
            self._positions = HK.positions(self._kernel_args, self.dof_index, pat)
        Jq, Jv = np.zeros(pat.nnz + 1), np.zeros(pat.nnz + 1)
        dDq, dDv = np.zeros(self.n2), np.zeros(self.n2)
        steps = np.array([np.sqrt(np.finfo(float).eps) if scheme == "forward" else 1e-7, 1e-7])
        link = {"forward": HK.FORWARD, "central": HK.CENTRAL, "analytic": HK.ANALYTIC}[scheme]
        HK.jacobian(np.asarray(q, float), np.asarray(v, float), *self._kernel_args, *self._positions, steps, link,
                    Jq, Jv, dDq, dDv)
        return Jq, Jv, dDq, dDv

    def coloured_jacobian(self, q: np.ndarray, v: np.ndarray, step: float = 1e-7,
                          damping: bool = True) -> tuple[sp.csr_matrix, sp.csr_matrix | None]:
        """``(dQ/dq, dQ/dv)`` of :meth:`forces` by central differences over pin colours, on :attr:`jac_sparsity`.

        Pins five or more apart share a colour (the stencil is ``p-2..p+2``), so ``2 x 21 x colours``
        force evaluations per matrix (6 colours for 84 pins).  ``step`` is relative to ``max(|x|, 1e-2 l)``;
        ``damping=False`` skips ``dQ/dv`` (returned as None).
        """
        n = self.n_pins
        k = 5 if not self.closed else next((k for k in range(5, n + 1) if n % k == 0 or n % k >= 5), n)
        colour = np.arange(n) % k
        pat = self.jac_sparsity.tocoo()
        group = np.empty(self.n2, int)                    # (colour, slot) of every coordinate
        group[self.dof_index] = colour[:, None] * 21 + np.arange(21)[None, :]
        order = np.argsort(group[pat.col], kind="stable")
        bounds = np.searchsorted(group[pat.col][order], np.arange(21 * k + 1))
        out = [None, None]
        for wrt in (0, 1) if damping else (0,):
            x0 = (q, v)[wrt]
            data = np.zeros(pat.nnz)
            for c in range(min(k, n)):
                for j in range(21):
                    cols = self.dof_index[colour == c, j]
                    e = np.zeros(self.n2)
                    e[cols] = step * np.maximum(np.abs(x0[cols]), 1e-2 * self.l)
                    args_p = (q + e, v) if wrt == 0 else (q, v + e)
                    args_m = (q - e, v) if wrt == 0 else (q, v - e)
                    dQ = self.forces(*args_p) - self.forces(*args_m)
                    g = 21 * c + j
                    sel = order[bounds[g]:bounds[g + 1]]  # a row sees at most one perturbed pin of the colour
                    data[sel] = dQ[pat.row[sel]] / (2 * e[pat.col[sel]])
            out[wrt] = sp.csr_matrix((data, (pat.row, pat.col)), shape=(self.n2, self.n2))
        return out[0], out[1]


class CoupledHalvesA2:
    """Model A2 (spec section 3, (1.210)): A1's whole pins with two half-pin contact points per pin end.

    Half ``s = -1`` / ``+1`` of pin ``p`` has its axis at ``U_p(xi) + s h_pin tau_p``, ``tau_p`` the
    section axis (1.103) of :class:`ChainA1` (unit bisector of the link directions); the offset stays
    in-plane (the halves slide axially, case (a) of section 1.5.1.2).  ``transfer = "exact"`` maps a
    force at a half end by its exact virtual work (spec 3, the turning of ``tau_p`` loads pins
    ``p-1, p, p+1``); ``"end"`` applies it at the pin end as in spec 2.7 and drops that spin term.
    """

    def __init__(self, chain: ChainA1, h_pin: float, transfer: str = "exact") -> None:
        if not h_pin > 0:
            raise InputError("h_pin", h_pin, "> 0")
        if transfer not in ("exact", "end"):
            raise InputError("transfer", transfer, '"exact" or "end"')
        self.chain, self.h_pin, self.transfer = chain, float(h_pin), transfer

    def _axes(self, q: np.ndarray):
        u, w = self.chain.split(q)
        s = self.chain._link_strains(u, w)
        return self.chain._bisector(s["tt"])

    def contact_points(self, q: np.ndarray, pins: np.ndarray, half: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """Points ``(m, 3)`` m on the axes of half ``half`` (-1 or +1) of ``pins`` at ``xi`` (the ends: -1, +1)."""
        _, tau, _ = self._axes(q)
        pins = np.asarray(pins)
        P0 = self.chain.axis_points(q, pins, xi)
        P0[:, :2] += (self.h_pin * np.asarray(half, float))[:, None] * tau[pins]
        return P0

    def point_loads(self, q: np.ndarray, pins: np.ndarray, half: np.ndarray, xi: np.ndarray, force: np.ndarray,
                    moment: np.ndarray | None = None) -> np.ndarray:
        """Generalized forces of forces ``(m, 3)`` N (and in-plane moments ``(m, 2)`` N m) at half points.

        ``F . dP`` with ``dP = dU(xi) + s h_pin (n_p n_p / |x_p|) . dx_p`` (spec 3), ``x_p`` the bisector (1.103).
        """
        ch = self.chain
        pins = np.asarray(pins)
        force = np.asarray(force, float).reshape(-1, 3)
        Q = ch.point_loads(pins, xi, force, moment)
        if self.transfer == "end":
            return Q
        r, _, nv = self._axes(q)
        a = np.zeros((ch.n_pins, 2))
        coef = self.h_pin * np.asarray(half, float) * _dot(force[:, :2], nv[pins]) / r[pins]
        np.add.at(a, pins, coef[:, None] * nv[pins])
        Qu, Qw = ch.split(Q)
        Qu[0] -= ch._scatter_axes(a)                                      # dx_p/du_0 stencil (1.162), as a force
        return ch.join(Qu, Qw)


def ring_state(chain: ChainA5, stretch: float = 0.0, overlap: float = 0.0) -> np.ndarray:
    """A closed regular ring of straight halves (uniform pitch): plates stretched by ``stretch`` (m), rolling
    faces overlapping by ``overlap`` (m; 0: touching), pack and halves centred axially."""
    n, h, (Rm, Rp) = chain.n_pins, chain.h_pin, chain.roll_radius
    L = float(chain.L[0]) + stretch
    alpha = 2 * np.pi * np.arange(n) / n
    tau = np.column_stack([np.cos(alpha), np.sin(alpha)])
    beta = alpha - np.pi / n
    bis = np.column_stack([np.cos(beta), np.sin(beta)])
    step = (L + Rp - h) * tau[chain._prev] - (Rm + Rp - overlap) * bis - (h - Rm) * tau    # O_p - O_{p-1}
    O = np.cumsum(step, 0)
    u = np.zeros((2, 4, n, 2))
    u[0, 0] = O
    u[1, 0] = (O + L * tau)[chain._prev]
    z = np.zeros(n)
    w = np.stack([np.stack([z, np.full(n, chain.l / 2)])] * 2)
    return chain.join(u, w, z)
