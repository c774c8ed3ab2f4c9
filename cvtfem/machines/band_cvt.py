"""The band CVT model: a band element family closed by a control family and driven by a regime.

State ``x = [q, v, z, W]``: coordinates and velocities of the band family, the states ``z`` of the
control family (:class:`~cvtfem.control.stabilisation.Stabilisation`: 4;
:class:`~cvtfem.control.stabilisation.OpenLoop`: none) and four work integrals
``W = [input, output, dissipated, clamping]`` (J) used for the efficiency and the power balance
``d(T + V)/dt = M1 w1 + M2 w2 + P_clamp - D``.

The band family must offer ``n2``, ``names``, ``speed_indices()``, ``accel(q, v, F, M) -> (a, info)``
with ``info["dissipation"]`` and ``info["clamp_power"]``, ``kinetic_energy(q, v)`` and
``elastic_energy(q)``, optionally ``jacobian(q, v, F, M)`` and ``steady_state``.
"""
from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly.model import Linearization, ModelBase, StateLayout
from cvtfem.control.clamping import Clamping
from cvtfem.control.regimes import Regime
from cvtfem.elements.base import Block, Layout
from cvtfem.errors import NumericalError
from cvtfem.outputs import OutputSpec

log = logging.getLogger(__name__)

#: SI unit of a band-family coordinate by its name without the arc digits.
COORDINATE_UNITS = {"phi": "rad", "sigma": "m", "z": "m", "h": "m", "U": "m", "psi": "rad"}
#: Rotation angles sigma, phi1, phi2 (indices 1..3 of q) never enter the right-hand side.
ANGLES = (1, 2, 3)


@dataclass(frozen=True)
class BandCVT(ModelBase):
    """Band family + clamping + regime + control family as one first-order ODE ``x' = rhs(t, x)``.

    ``parts``: the components (element families with their named outputs) the model was built from.
    """

    model: Any
    clamping: Clamping
    regime: Regime
    control: Any
    parts: tuple[Layout, ...] = ()

    @property
    def layout(self) -> StateLayout:
        coords = tuple(Block(f"band.{name}", 1, COORDINATE_UNITS[name.rstrip("0123456789")])
                       for name in self.model.names)
        return StateLayout(coords + tuple(self.control.blocks) + (Block("work", 4, "J", order=1),))

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        return tuple(o for part in self.parts for o in part.outputs)

    def split(self, x):
        """Views ``q, v, z, W`` of a state vector."""
        n, nc = self.model.n2, self.control.size
        return x[:n], x[n:2 * n], x[2 * n:2 * n + nc], x[2 * n + nc:]

    def with_regime(self, **changes: Any) -> BandCVT:
        """This loop with the regime's fields ``changes`` (e.g. ``input_speed`` rad/s, ``torque`` N m, ``ratio``)."""
        return dataclasses.replace(self, regime=dataclasses.replace(self.regime, **changes))

    def initial_state(self, ratio: float | None = None, speed_factor: float = 1.0) -> np.ndarray:
        """The start state of :meth:`start` (logs its warning, if any)."""
        return self.start(ratio, speed_factor)[0]

    def start(self, ratio: float | None = None, speed_factor: float = 1.0) -> tuple[np.ndarray, dict[str, Any]]:
        """Band at the span angle of the target ratio, driving shaft at the target speed: ``(x0, report)``.

        Band families with ``steady_state`` start in steady running (elastic coordinates and slips in
        balance; ``report = {"kind": "steady", "residual": ...}``, the relative Newton correction); others,
        and a steady state that is not found, start without slip on pulley 1 from the static elastic
        equilibrium (``{"kind": "no-slip"}``; for a steady state not found also ``"warning"``, one line saying
        why, logged).  ``ratio`` and ``speed_factor`` start the run away from the targets (geometric ratio,
        driving speed as a multiple of its target).
        """
        w1, M1, i = self.regime.targets(0.0)
        F = self.clamping.forces(M1, i)
        if ratio is not None:  # start away from the target (tests of the loops)
            i = ratio
        w1 *= speed_factor
        phi = self.clamping.span_angle(i)
        report: dict[str, Any] = {"kind": "no-slip"}
        if hasattr(self.model, "steady_state"):  # start in steady running: no start-up transient
            try:
                q, v, _, info = self.model.steady_state(phi, w1, F, M1)
                report = {"kind": "steady", "residual": info["residual"]}
            except NumericalError as err:
                report["warning"] = self._no_steady_state(w1, M1, i, F, err)
                log.warning("%s", report["warning"])
        if report["kind"] == "no-slip":
            q, v = self.model.initial_state(phi, w1, w1 / i, F)
        return np.concatenate([q, v, self.control.initial_state(w1, w1 / i), np.zeros(4)]), report

    def _no_steady_state(self, w1: float, M1: float, i: float, F, err: NumericalError) -> str:
        """Why a run starts without slip: the torques the clamping forces carry by (1.13), and the solver's word."""
        safety = min(F / self.clamping.estimates(M1, i)) if M1 > 0 else math.inf
        why = (f"the clamping forces {F[0] / 1e3:.3g} / {F[1] / 1e3:.3g} kN carry {safety:.3g} x the torque by the "
               "estimate (1.13), so friction cannot hold it (the slip grows without bound)" if safety <= 1.0 else
               f"not found ({err})")
        return (f"no steady state at {w1 * 30 / math.pi:.0f} rpm, {M1:g} N m, ratio {i:g}: {why}; "
                "starting without slip on the driving pulley (a start-up transient follows)")

    def _controls(self, t: float, w, z):
        """Clamping forces, shaft torques and control-state derivative at shaft speeds ``w`` (rad/s), state z."""
        w1d, M1, i_d = self.regime.targets(t)
        w2d = w1d / i_d
        F_appl = self.clamping.forces(M1, i_d)
        F, M2, dz, diag = self.control.outputs(w, z, i_d, w2d, M1, F_appl)
        return F, np.array([M1, M2]), dz, diag, (w1d, M1, i_d)

    def evaluate(self, t: float, x):
        """Right-hand side and everything an output needs: ``(dx, info)``."""
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

    @property
    def jac_sparsity(self) -> sp.csr_matrix:
        """``u' = v`` rows, and all other rows on the columns the right-hand side depends on (not the angles, not W)."""
        n, N = self.model.n2, self.size
        cols = self._fd_columns()
        rows = np.concatenate([np.arange(n), np.repeat(np.arange(n, N), len(cols))])
        cols = np.concatenate([np.arange(n, 2 * n), np.tile(cols, N - n)])
        return sp.csr_matrix((np.ones(rows.size, bool), (rows, cols)), shape=(N, N))

    def _fd_columns(self) -> np.ndarray:
        return np.array([j for j in range(2 * self.model.n2 + self.control.size) if j not in ANGLES])

    def jac(self, t: float, x):
        """Jacobian ``d rhs / dx`` (dense): chain rule through the band family's own Jacobian when it has one
        (``model.jacobian(q, v, F, M)``, rows ``[a, dissipation, clamp_power]``, columns ``[q, v, F, M]``)
        and a difference quotient of the control outputs in the shaft speeds and the control states;
        otherwise :meth:`jac_fd`.
        """
        if not hasattr(self.model, "jacobian"):
            return self.jac_fd(t, x)
        n, nc = self.model.n2, self.control.size
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
        """Finite-difference Jacobian ``d rhs / dx`` (dense) over the columns of :attr:`jac_sparsity`.

        The rotation angles and the work integrals never enter the right-hand side, so their columns are
        zero and are not differenced (this also keeps scipy's adaptive num_jac from inflating its
        increments on them).
        """
        n = self.model.n2
        f0 = self.rhs(t, x)
        Jm = np.zeros((x.size, x.size))
        for j in self._fd_columns():
            h = 1e-7 * max(1.0, abs(x[j])) if j >= n else 1e-8 * max(1e-3, abs(x[j]))
            xp = x.copy()
            xp[j] += h
            Jm[:, j] = (self.rhs(t, xp) - f0) / h
        return Jm

    def linearize(self, x0, t: float = 0.0) -> Linearization:
        """First-order ``A = d rhs / dx`` at ``(t, x0)`` (the loops and work integrals are first-order)."""
        return Linearization(A=self.jac(t, x0))

    def power(self, t: float, x) -> np.ndarray:
        """``[M1 w1, -M2 w2, dissipation, clamping power]``, W: the rates of the work integrals W."""
        return self.rhs(t, x)[-4:]

    def energy(self, x) -> float:
        """Kinetic plus elastic energy of the band family, J (one compiled call where the family has ``energies``)."""
        q, v, _, _ = self.split(x)
        if hasattr(self.model, "energies"):
            T, V = self.model.energies(q, v)
            return float(T + V)
        return float(self.model.kinetic_energy(q, v) + self.model.elastic_energy(q))

    def outputs(self, t: float, x) -> dict[str, Any]:
        """The named outputs of :attr:`output_specs` at ``(t, x)``: one evaluation of the loop (its work-integral
        rates are the powers) and one of the energy."""
        dx, info = self.evaluate(t, x)
        q, _, _, W = self.split(x)
        P = dx[-4:]  # [M1 w1, -M2 w2, dissipation, clamping power], W
        N = np.asarray(info["N"])
        w, M, F = info["w"], info["M"], info["F"]
        out = {"band.span_angle": q[0], "band.slip_speed": info["slip"], "band.slip_max": info["slip_max"],
               "band.mean_normal_force": N.sum(axis=-1) / N.shape[-1] if N.ndim == 2 else N,
               "driving.speed": w[0], "driving.torque": M[0], "driving.clamping_force": F[0],
               "driven.speed": w[1], "driven.torque": M[1], "driven.clamping_force": F[1],
               "control.ratio_estimate": info["ratio_estimate"], "control.resistance": info["resistance"],
               "efficiency": P[1] / P[0] if P[0] else 0.0, "ratio": w[0] / w[1] if w[1] else math.nan,
               "power": P, "work": W, "energy": self.energy(x), "band.normal_force": N.ravel()}
        return {s.name: out[s.name] for s in self.output_specs}
