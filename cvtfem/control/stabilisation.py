"""Stabilisation systems of section 1.6: smoothed speeds, ratio loop on F1, driven-speed loop on b2.

Spec: low-order digest sections 5.2-5.5, eqs. (1.353)-(1.356).  The controller state is
``z = [w1s, w2s, F11, b21]`` (smoothed speeds, integral parts); modes (normal/saturation)
are recomputed at every call, without events (section 5.5).

A control family adds its first-order states (:attr:`blocks`), the clamping forces and the
driven-shaft torque to a model that exposes its two shaft speeds: :class:`Stabilisation` (both
loops) or :class:`OpenLoop` (prescribed forces and a fixed resistance, no states).  Both offer
``blocks``, ``size``, ``output_specs``, ``initial_state(w1, w2)`` and
``outputs(w, z, i_d, w2d, M1, F_appl) -> (F, M2, dz, diag)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.base import Block
from cvtfem.outputs import OutputSpec

#: Named outputs of the loops (the open loop reports them too, but records none).
LOOP_OUTPUTS = (OutputSpec("control.ratio_estimate", "-", "Smoothed ratio estimate."),
                OutputSpec("control.resistance", "N m s", "Driven-shaft resistance b2."))

def clamp(x, a, b):
    """``max(a, min(b, x))``, eq. (1.354)."""
    return np.maximum(a, np.minimum(b, x))


def ratio_estimate(w1s, w2s, eps: float, i_min: float, i_max: float):
    """Guarded ratio ``clamp(w1s / w2s, i_min, i_max)``, or 1 where ``|w2s| < eps`` (section 5.3)."""
    w2 = np.where(np.abs(w2s) < eps, 1.0, w2s)
    return np.where(np.abs(w2s) < eps, 1.0, clamp(w1s / w2, i_min, i_max))


@dataclass(frozen=True)
class StabilisationParams:
    """Gains and limits of both loops (section 9 reference values in the ``reference_cvt`` preset).

    Attributes
    ----------
    tau_omega : float, s
        Speed filter time constant (1.353).
    eps : float, rad/s; i_min, i_max : float
        Ratio guards.
    k_sat : float
        F1 stays within ``[F1a / k_sat, k_sat F1a]``.
    c_f0 : float, N; c_f1 : float, N/s
        Proportional and integral gains of the ratio loop.
    c_sat : float
        b2 stays within ``[b20 / c_sat, c_sat b20]``.
    tau : float, s; nu : float
        Desired transient time and damping ratio of the driven-speed loop.
    J_sigma : float, kg m^2
        Inertia reduced to the driven shaft ``J1 i^2 + J2 + m_ch r2^2`` at the target ratio.
    F11_start : float, N
        Start value of the ratio loop's integral (0 in the source; :func:`~cvtfem.control.loop_start.integral_start`
        seeds the chain's own clamping ratio).
    """

    tau_omega: float = 0.002
    eps: float = 1e-5
    i_min: float = 0.1
    i_max: float = 10.0
    k_sat: float = 2.5
    c_f0: float = 2e5
    c_f1: float = 1e6
    c_sat: float = 2.5
    tau: float = 0.01
    nu: float = 0.8
    J_sigma: float = 0.1
    F11_start: float = 0.0

    def speed_gains(self, b20: float, w2d: float) -> tuple[float, float]:
        """``c_b0 = (2 J / tau - b20) / w2d`` and ``c_b1 = J / ((tau nu)^2 w2d)`` (section 5.4)."""
        J = self.J_sigma
        return (2 * J / self.tau - b20) / w2d, J / ((self.tau * self.nu) ** 2 * w2d)


@dataclass(frozen=True)
class Stabilisation:
    """Both loops as a control family: states ``z = [w1s, w2s, F11, b21]``, forces F1 and M2."""

    p: StabilisationParams
    blocks = (Block("control.speed", 2, "rad/s", order=1), Block("control.F1_integral", 1, "N", order=1),
              Block("control.b2_integral", 1, "N m s", order=1))
    size = 4
    output_specs = LOOP_OUTPUTS

    def initial_state(self, w1: float, w2: float) -> np.ndarray:
        """``z(0) = [w1, w2, F11_start, 0]`` (filters start at the measured speeds, the b2 integral at zero, the F1
        integral at :attr:`StabilisationParams.F11_start`, zero unless seeded)."""
        return np.array([w1, w2, self.p.F11_start, 0.0])

    def outputs(self, w, z, i_d: float, w2d: float, M1: float, F_appl):
        """Control forces and state derivatives (section 5.5).

        Parameters
        ----------
        w : (2,) rad/s
            Raw shaft speeds.
        z : (4,)
            Controller state ``[w1s, w2s, F11, b21]``.
        i_d, w2d, M1 : float
            Target ratio, target driven speed (rad/s) and driving torque (N m).
        F_appl : (2,) N
            Prescribed clamping forces (estimate (1.13) times the safety factor).

        Returns
        -------
        F : (2,) N; M2 : float, N m; dz : (4,); diag : dict (ratio estimate, b2, saturation flags)
        """
        p = self.p
        w1s, w2s, F11, b21 = np.asarray(z, float).tolist()  # Python floats: this runs at every right-hand-side call
        w0, w1 = np.asarray(w, float).tolist()
        F_appl = np.asarray(F_appl, float).tolist()
        i_t = 1.0 if abs(w2s) < p.eps else min(max(w1s / w2s, p.i_min), p.i_max)  # scalar form of ratio_estimate
        e = i_t - i_d
        FS = p.c_f0 * e + F11
        Fmin, Fmax = (1 / p.k_sat - 1) * F_appl[0], (p.k_sat - 1) * F_appl[0]
        f1 = p.c_f1 * e
        sat1 = (FS < Fmin and f1 < 0) or (FS > Fmax and f1 > 0)
        F = np.array([F_appl[0] + min(max(FS, Fmin), Fmax), F_appl[1]])
        b20 = M1 * i_d / w2d
        cb0, cb1 = p.speed_gains(b20, w2d)
        ew = w2s - w2d
        bS = cb0 * ew + b21
        g1 = cb1 * ew
        lo, hi = (1 / p.c_sat - 1) * b20, (p.c_sat - 1) * b20
        sat2 = (bS < lo and g1 < 0) or (bS > hi and g1 > 0)
        b2 = b20 + min(max(bS, lo), hi)
        M2 = -b2 * w2s
        dz = np.array([(w0 - w1s) / p.tau_omega, (w1 - w2s) / p.tau_omega,
                       0.0 if sat1 else f1, 0.0 if sat2 else g1])
        return F, M2, dz, {"ratio_estimate": i_t, "resistance": b2, "sat1": sat1, "sat2": sat2}


@dataclass(frozen=True)
class OpenLoop:
    """No stabilisation: the prescribed clamping forces and a fixed resistance ``M2 = -b20 w2``,
    ``b20 = M1 i_d / w2d`` (the resistance of the target operating point); no states."""

    blocks = ()
    size = 0
    output_specs = ()

    def initial_state(self, w1: float, w2: float) -> np.ndarray:
        """No states."""
        return np.zeros(0)

    def outputs(self, w, z, i_d: float, w2d: float, M1: float, F_appl):
        """``(F, M2, dz, diag)`` as :meth:`Stabilisation.outputs` (raw ratio estimate, b2 = b20)."""
        b20 = M1 * i_d / w2d
        return F_appl, -b20 * w[1], np.zeros(0), {"ratio_estimate": w[0] / w[1], "resistance": b20}
