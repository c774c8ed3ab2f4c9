"""A band (or any) model closed by the stabilisation systems and driven by a regime.

State ``x = [q, v, z, W]``: coordinates and velocities of the model, the controller state
``z`` (section 5.5; absent when stabilisation is off) and four work integrals
``W = [input, output, dissipated, clamping]`` (J) used for the efficiency and the power balance
``d(T + V)/dt = M1 w1 + M2 w2 + P_clamp - D``.

The model must offer ``n2``, ``speed_indices()``, ``accel(q, v, F, M) -> (a, info)`` with
``info["dissipation"]`` and ``info["clamp_power"]``, ``kinetic_energy(q, v)`` and
``elastic_energy(q)``; nothing else is assumed, so discrete-chain models can plug in later.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cvtfem.control.regimes import Regime
from cvtfem.control.stabilisation import Stabilisation
from cvtfem.elements.band.estimates import min_clamping_force
from cvtfem.elements.band.equilibrium import forces_for_angle
from cvtfem.elements.band.geometry import phi_for_ratio, phi_for_ratios, radii
from cvtfem.elements.band.params import BandParams
from cvtfem.errors import InputError

SPLITS = ("equilibrium", "per-shaft")
#: Smallest prescribed clamping force per pulley, N (assumed: a preload, as the spring of a real driven
#: pulley, ~3 % of the 30-35 kN at 200 N m, i.e. the estimate (1.13) x 1.1 at ~7 N m).  Without it the
#: forces vanish with the torque and a torque ramp towards 0 N m ends in gross slip under ~0.4 N, where
#: the implicit solvers' steps collapse to ~1e-13 s.  It changes nothing above ~7 N m.  Scenes set it
#: with ``cvt.regime.min_clamping_force`` (same default); this is the default of :class:`Clamping`.
MIN_CLAMPING_FORCE = 1000.0


@dataclass(frozen=True)
class Clamping:
    """Prescribed clamping forces ``F_appl(M1, i)`` from the estimate (1.13) times a safety factor.

    ``split = "per-shaft"`` applies (1.13) to each pulley separately (spec section 3.1).
    ``split = "equilibrium"`` keeps the force ratio ``F1/F2`` of the equilibrium span angle of the
    target ratio (section 4.2) and scales the pair until each pulley has at least ``safety`` times
    its estimate: the band models hold a ratio only at that force ratio (friction has no steady
    phi-component), so this starts the ratio loop at its working point.
    Neither pulley gets less than ``f_min`` (N; the equilibrium split scales the pair, keeping its ratio).
    """

    p: BandParams
    safety: float
    split: str = "equilibrium"
    f_min: float = MIN_CLAMPING_FORCE
    _table: tuple[np.ndarray, np.ndarray] = field(init=False, repr=False)
    _last: dict = field(init=False, repr=False, default_factory=dict)  # memo of the last (M1, ratio)

    def __post_init__(self) -> None:
        if self.split not in SPLITS:
            raise InputError("regime.clamping_split", self.split, "must be one of " + ", ".join(SPLITS))
        ratios = np.geomspace(0.3, 3.5, 400)
        phis = phi_for_ratios(ratios, self.p.length, self.p.L)
        object.__setattr__(self, "_table", (np.log(ratios), phis))

    def span_angle(self, ratio: float) -> float:
        """Span angle of the geometric ratio (tabulated for speed; exact solve outside 0.3..3.5)."""
        x, y = self._table
        lr = np.log(ratio)
        if x[0] <= lr <= x[-1]:
            return float(np.interp(lr, x, y))
        return phi_for_ratio(ratio, self.p.length, self.p.L)

    def estimates(self, M1: float, ratio: float) -> np.ndarray:
        """Per-pulley estimates (1.13) at the target ratio, N (``|M2| = M1 i``)."""
        phi = self.span_angle(ratio)
        r, _, _ = radii(phi, self.p.length, self.p.L)
        g = [self.p.sheaves[k].gamma_at(r[k]) for k in range(2)]
        return np.array([min_clamping_force(M1, r[0], self.p.f0, g[0]),
                         min_clamping_force(M1 * ratio, r[1], self.p.f0, g[1])])

    def forces(self, M1: float, ratio: float) -> np.ndarray:
        """``F_appl = (F1, F2)``, N (a pure function of its arguments; the last result is memoised)."""
        key = (float(M1), float(ratio))
        if self._last.get("key") != key:
            self._last.update(key=key, value=self._forces(M1, ratio))
        return self._last["value"].copy()

    def _forces(self, M1: float, ratio: float) -> np.ndarray:
        est = self.estimates(M1, ratio)
        if self.split == "per-shaft":
            return np.maximum(self.safety * est, self.f_min)
        rho = forces_for_angle(self.span_angle(ratio), self.p.sheaves, self.p.length, self.p.L)
        F2 = max(self.safety * max(est[1], est[0] / rho), self.f_min / min(rho, 1.0))
        return np.array([rho * F2, F2])


@dataclass(frozen=True)
class ClosedLoop:
    """Model + clamping + regime (+ stabilisation) as one first-order ODE ``x' = rhs(t, x)``."""

    model: Any
    clamping: Clamping
    regime: Regime
    control: Stabilisation | None = None

    @property
    def n_ctrl(self) -> int:
        return 0 if self.control is None else 4

    @property
    def size(self) -> int:
        return 2 * self.model.n2 + self.n_ctrl + 4

    def split(self, x):
        """Views ``q, v, z, W`` of a state vector."""
        n = self.model.n2
        return x[:n], x[n:2 * n], x[2 * n:2 * n + self.n_ctrl], x[2 * n + self.n_ctrl:]

    def initial_state(self, ratio: float | None = None, speed_factor: float = 1.0) -> np.ndarray:
        """Band at the span angle of the target ratio, driving shaft at the target speed.

        Models with ``steady_state`` start in steady running (elastic coordinates and slips in balance);
        others start without slip on pulley 1.  ``ratio`` and ``speed_factor`` start the run away from the
        targets (geometric ratio, driving speed as a multiple of its target).
        """
        w1, M1, i = self.regime.targets(0.0)
        F = self.clamping.forces(M1, i)
        if ratio is not None:  # start away from the target (tests of the loops)
            i = ratio
        w1 *= speed_factor
        phi = self.clamping.span_angle(i)
        if hasattr(self.model, "steady_state"):  # start in steady running: no start-up transient
            q, v, _, _ = self.model.steady_state(phi, w1, F, M1)
        else:
            q, v = self.model.initial_state(phi, w1, w1 / i, F)
        z = self.control.initial_state(w1, w1 / i) if self.control else np.zeros(0)
        return np.concatenate([q, v, z, np.zeros(4)])

    def _controls(self, t: float, w, z):
        """Clamping forces, shaft torques and controller derivative at shaft speeds ``w`` (rad/s), state z."""
        w1d, M1, i_d = self.regime.targets(t)
        w2d = w1d / i_d
        F_appl = self.clamping.forces(M1, i_d)
        if self.control is not None:
            F, M2, dz, diag = self.control.outputs(w, z, i_d, w2d, M1, F_appl)
        else:
            b20 = M1 * i_d / w2d
            F, M2, dz, diag = F_appl, -b20 * w[1], np.zeros(0), {"ratio_estimate": w[0] / w[1], "resistance": b20}
        return F, np.array([M1, M2]), dz, diag, (w1d, M1, i_d)

    def evaluate(self, t: float, x):
        """Right-hand side and everything an output needs: ``(dx, loads, info)``."""
        q, v, z, _ = self.split(x)
        k1, k2 = self.model.speed_indices()
        w = np.array([v[k1], v[k2]])
        F, M, dz, diag, targets = self._controls(t, w, z)
        a, info = self.model.accel(q, v, F, M)
        dW = np.array([M[0] * w[0], -M[1] * w[1], info["dissipation"], info["clamp_power"]])
        info.update(diag, F=F, M=M, w=w, targets=targets)
        return np.concatenate([v, a, dz, dW]), info

    def rhs(self, t: float, x):
        """``dx/dt``."""
        return self.evaluate(t, x)[0]

    def jac(self, t: float, x):
        """Jacobian ``d rhs / dx``: chain rule through the model's own Jacobian when it has one
        (``model.jacobian(q, v, F, M)``, rows ``[a, dissipation, clamp_power]``, columns ``[q, v, F, M]``)
        and a difference quotient of the loops' outputs in the shaft speeds and the controller state;
        otherwise :meth:`jac_fd`.
        """
        if not hasattr(self.model, "jacobian"):
            return self.jac_fd(t, x)
        n, nc = self.model.n2, self.n_ctrl
        q, v, z, _ = self.split(x)
        k1, k2 = self.model.speed_indices()
        w = np.array([v[k1], v[k2]])
        F, M, dz, _, _ = self._controls(t, w, z)
        # d(F1, F2, M1, M2, dz) / d(w1, w2, z) by forward differences (the loops are cheap and piecewise smooth)
        u0 = np.concatenate([F, M, dz])
        G = np.zeros((4 + nc, 2 + nc))
        for j in range(2 + nc):
            wp, zp = w.copy(), z.copy()
            if j < 2:
                h = 1e-7 * max(1.0, abs(w[j]))
                wp[j] += h
            else:
                h = 1e-7 * max(1.0, abs(z[j - 2]))
                zp[j - 2] += h
            Fp, Mp, dzp, _, _ = self._controls(t, wp, zp)
            G[:, j] = (np.concatenate([Fp, Mp, dzp]) - u0) / h
        Ja = self.model.jacobian(q, v, F, M)  # (n + 2, 2 n + 4)
        AU = Ja[:, 2 * n:] @ G[:4]  # model rows through the loops' outputs, (n + 2, 2 + nc)
        Jm = np.zeros((x.size, x.size))
        Jm[:n, n:2 * n] = np.eye(n)
        rows = slice(n, 2 * n)
        Jm[rows, :2 * n] = Ja[:n, :2 * n]
        Jm[rows, [n + k1, n + k2]] += AU[:n, :2]
        Jm[rows, 2 * n:2 * n + nc] = AU[:n, 2:]
        Jm[2 * n:2 * n + nc, [n + k1, n + k2]] = G[4:, :2]
        Jm[2 * n:2 * n + nc, 2 * n:2 * n + nc] = G[4:, 2:]
        iw = 2 * n + nc  # work integrals: [M1 w1, -M2 w2, dissipation, clamping power]
        dM = G[2:4]  # d(M1, M2) / d(w, z)
        Jm[iw, [n + k1, n + k2]] = M[0] * np.array([1.0, 0.0]) + w[0] * dM[0, :2]
        Jm[iw, 2 * n:iw] = w[0] * dM[0, 2:]
        Jm[iw + 1, [n + k1, n + k2]] = -M[1] * np.array([0.0, 1.0]) - w[1] * dM[1, :2]
        Jm[iw + 1, 2 * n:iw] = -w[1] * dM[1, 2:]
        Jm[iw + 2:iw + 4, :2 * n] = Ja[n:, :2 * n]
        Jm[iw + 2:iw + 4, [n + k1, n + k2]] += AU[n:, :2]
        Jm[iw + 2:iw + 4, 2 * n:iw] = AU[n:, 2:]
        return Jm

    def jac_fd(self, t: float, x):
        """Finite-difference Jacobian ``d rhs / dx`` over the states the right-hand side depends on.

        Rotation angles (sigma, phi1, phi2: indices 1..3 of q) and the work integrals never enter the
        right-hand side, so their columns are zero and are not differenced (this also keeps scipy's
        adaptive num_jac from inflating its increments on them).
        """
        n = self.model.n2
        f0 = self.rhs(t, x)
        cols = [0] + list(range(4, 2 * n + self.n_ctrl))
        Jm = np.zeros((x.size, x.size))
        for j in cols:
            h = 1e-7 * max(1.0, abs(x[j])) if j >= n else 1e-8 * max(1e-3, abs(x[j]))
            xp = x.copy()
            xp[j] += h
            Jm[:, j] = (self.rhs(t, xp) - f0) / h
        return Jm

    def energy(self, x) -> float:
        """Kinetic plus elastic energy of the model, J (one compiled call where the model has ``energies``)."""
        q, v, _, _ = self.split(x)
        if hasattr(self.model, "energies"):
            T, V = self.model.energies(q, v)
            return float(T + V)
        return float(self.model.kinetic_energy(q, v) + self.model.elastic_energy(q))
