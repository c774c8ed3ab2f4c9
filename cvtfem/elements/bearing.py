"""Shaft supports (bearings) to ground or between two nodes: linear coefficients and the nonlinear radial law.

Linear bearing (per node, DOF ``(u1, u2, u3, theta1, theta2, phi)``): lateral
stiffness/damping ``[[kxx, kxy], [kyx, kyy]]``, axial ``kzz``, tilt ``ktt``
(isotropic), torsional ``kphi``, and a lumped rigid body ``(m, Id, Ip)`` at the
attachment point (spec §5.4 with ``eta* = 0``).  A bearing linked to a second
node ``j`` (ROSS ``n_link``: a pedestal) acts on the relative motion
``u_i - u_j``: its 6x6 block ``B`` enters as ``[[B, -B], [-B, B]]``; its lumped
mass stays on node ``i``.

Nonlinear isotropic radial law (spec §5.3, (1.274)-(1.277)): the radial force
magnitude ``f_r(u)`` of the radial deflection ``u = |u_perp|``, given as a
table (monotone cubic interpolation) or a polynomial ``sum c_n u^n``.  Modal
analysis uses its tangent stiffness at the operating deflection (spec §12.4):
``K_t = f_r'(u) e e^T + f_r(u)/u (I - e e^T)``, with ``K_t = f_r'(0) I`` at
``u = 0``; the damping ``beta C^perp e e^T`` is radial only.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.errors import InputError

#: Names of the per-bearing coefficient arrays of :class:`BearingFamily`.
COEFFICIENTS = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy", "kzz", "czz",
                "ktt", "ctt", "kphi", "cphi", "m", "Id", "Ip")


@dataclass(frozen=True)
class RadialLaw:
    """Isotropic radial force characteristic ``f_r(u)`` (N) of a bearing.

    Parameters
    ----------
    u, f : arrays, optional
        Table of deflections (m, increasing, starting at 0) and forces (N, f(0) = 0);
        interpolated by a monotone cubic (PCHIP).
    coeffs : array, optional
        Polynomial coefficients ``c_1 .. c_n`` of ``f_r = sum c_n u^n`` (N/m^n).
    """

    u: tuple[float, ...] = ()
    f: tuple[float, ...] = ()
    coeffs: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if bool(self.coeffs) == bool(self.u):
            raise InputError("radial law", self, "needs either a table (u, f) or polynomial coefficients")
        if self.u:
            u, f = np.asarray(self.u, float), np.asarray(self.f, float)
            if u.shape != f.shape or len(u) < 2 or u[0] != 0 or f[0] != 0 or np.any(np.diff(u) <= 0):
                raise InputError("radial law table", (self.u, self.f),
                                 "must be >= 2 increasing deflections from 0 with forces from 0, same length")

    def force(self, u: np.ndarray) -> np.ndarray:
        """f_r(u), N (u >= 0, m)."""
        if self.coeffs:
            return np.polynomial.polynomial.polyval(u, (0.0, *self.coeffs))
        return self._spline()(u)

    def slope(self, u: np.ndarray) -> np.ndarray:
        """f_r'(u), N/m."""
        if self.coeffs:
            return np.polynomial.polynomial.polyval(u, np.polynomial.polynomial.polyder((0.0, *self.coeffs)))
        return self._spline().derivative()(u)

    def _spline(self):  # noqa: ANN202 - scipy interpolator
        from scipy.interpolate import PchipInterpolator

        return PchipInterpolator(self.u, self.f, extrapolate=True)

    def tangent(self, u_perp: np.ndarray) -> np.ndarray:
        """2x2 tangent stiffness at the lateral deflection ``u_perp = (u1, u2)``, N/m (spec §12.4)."""
        u_perp = np.asarray(u_perp, dtype=float)
        u = float(np.hypot(*u_perp))
        if u == 0.0:
            return float(self.slope(0.0)) * np.eye(2)
        e = u_perp / u
        ee = np.outer(e, e)
        return float(self.slope(u)) * ee + float(self.force(u)) / u * (np.eye(2) - ee)

    def damping(self, u_perp: np.ndarray, beta: float) -> np.ndarray:
        """2x2 damping ``beta f_r'(0) e e^T`` (radial rate only, spec (1.275), §12.4), N s/m.

        At ``u = 0`` the direction is undefined; ``beta f_r'(0) I`` is used there
        (the isotropic choice the spec allows).
        """
        u_perp = np.asarray(u_perp, dtype=float)
        u = float(np.hypot(*u_perp))
        c = beta * float(self.slope(0.0))
        if u == 0.0:
            return c * np.eye(2)
        e = u_perp / u
        return c * np.outer(e, e)

    def reaction(self, u_perp: np.ndarray) -> np.ndarray:
        """Elastic reaction on the shaft ``-f_r(u) e_u`` (spec (1.277)), N."""
        u_perp = np.asarray(u_perp, dtype=float)
        u = float(np.hypot(*u_perp))
        return np.zeros(2) if u == 0 else -float(self.force(u)) * u_perp / u


@dataclass(frozen=True)
class BearingFamily:
    """Linear bearings (tangent matrices of nonlinear ones) on nodes, to ground or to a second node.

    Parameters
    ----------
    nodes : int array (n,)
    kxx ... Ip : arrays (n,)
        See :data:`COEFFICIENTS` (N/m, N s/m, N m/rad, N m s/rad, kg, kg m^2).
    links : int array (n,), optional
        Second node of each bearing, -1 for ground (default: all to ground).
    """

    nodes: np.ndarray
    kxx: np.ndarray
    kxy: np.ndarray
    kyx: np.ndarray
    kyy: np.ndarray
    cxx: np.ndarray
    cxy: np.ndarray
    cyx: np.ndarray
    cyy: np.ndarray
    kzz: np.ndarray
    czz: np.ndarray
    ktt: np.ndarray
    ctt: np.ndarray
    kphi: np.ndarray
    cphi: np.ndarray
    m: np.ndarray
    Id: np.ndarray
    Ip: np.ndarray
    links: np.ndarray | None = None

    @classmethod
    def from_dicts(cls, nodes: np.ndarray, entries: list[dict[str, float]],
                   links: np.ndarray | None = None) -> BearingFamily:
        """Family from per-bearing dicts; absent coefficients are 0."""
        cols = {k: np.array([float(e.get(k, 0.0)) for e in entries]) for k in COEFFICIENTS}
        return cls(np.asarray(nodes, dtype=np.int64), **cols,
                   links=None if links is None else np.asarray(links, dtype=np.int64))

    @property
    def dofs(self) -> np.ndarray:
        """Global DOF map, shape (n, 6)."""
        return np.asarray(self.nodes, dtype=np.int64)[:, None] * 6 + np.arange(6)

    @property
    def linked(self) -> np.ndarray:
        """Boolean (n,): bearings acting between two nodes."""
        return np.zeros(len(self.nodes), bool) if self.links is None else np.asarray(self.links) >= 0

    def relative(self, blocks: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """``(blocks, dofs)`` pairs to assemble (n, 6, 6) stiffness or damping blocks acting on ``u_i - u_j``.

        Bearings to ground give their 6x6 block on node ``i``; linked ones ``[[B, -B], [-B, B]]`` on ``(i, j)``.
        """
        ln = self.linked
        pairs = [(blocks[~ln], self.dofs[~ln])]
        if np.any(ln):
            B = blocks[ln]
            pairs.append((np.block([[B, -B], [-B, B]]),
                          np.concatenate([self.dofs[ln], self.links[ln, None] * 6 + np.arange(6)], axis=1)))
        return pairs

    def _blocks(self, xx: str, xy: str, yx: str, yy: str, zz: str, tt: str, ph: str) -> np.ndarray:
        n = len(self.nodes)
        B = np.zeros((n, 6, 6))
        B[:, 0, 0], B[:, 0, 1] = getattr(self, xx), getattr(self, xy)
        B[:, 1, 0], B[:, 1, 1] = getattr(self, yx), getattr(self, yy)
        B[:, 2, 2] = getattr(self, zz)
        B[:, 3, 3] = B[:, 4, 4] = getattr(self, tt)
        B[:, 5, 5] = getattr(self, ph)
        return B

    def stiffness(self) -> np.ndarray:
        """(n, 6, 6) stiffness blocks to ground."""
        return self._blocks("kxx", "kxy", "kyx", "kyy", "kzz", "ktt", "kphi")

    def damping(self) -> np.ndarray:
        """(n, 6, 6) damping blocks to ground."""
        return self._blocks("cxx", "cxy", "cyx", "cyy", "czz", "ctt", "cphi")

    def mass(self) -> np.ndarray:
        """(n, 6, 6) lumped rigid-body mass at the attachment point (spec §5.4)."""
        d = np.stack([self.m, self.m, self.m, self.Id, self.Id, self.Ip], axis=1)
        return d[:, :, None] * np.eye(6)

    def gyroscopic(self) -> np.ndarray:
        """(n, 6, 6) gyroscopic blocks of the lumped mass per unit spin speed."""
        G = np.zeros((len(self.nodes), 6, 6))
        G[:, 3, 4], G[:, 4, 3] = self.Ip, -self.Ip
        return G


#: Lateral coefficients a bearing may tabulate over the spin speed, in the column order of :class:`SpeedTables`.
SPEED_COEFFICIENTS = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")


def interpolate_over_speed(speeds: np.ndarray, values: np.ndarray, speed: float) -> np.ndarray:
    """Coefficient table ``values (s, ...)`` over ``speeds (s,)`` (rad/s) at ``speed``, as ROSS 3.1 does.

    One point: constant; two: linear; more: PCHIP (shape-preserving, no overshoot between points). Outside the
    table the coefficients continue linearly with the end slopes (ROSS 3.1 ``BearingCoefficient``).
    """
    from scipy.interpolate import PchipInterpolator, interp1d

    speeds, values = np.asarray(speeds, float), np.asarray(values, float)
    if len(speeds) == 1:
        return values[0].copy()
    if len(speeds) == 2:
        return interp1d(speeds, values, axis=0, fill_value="extrapolate")(speed)
    p = PchipInterpolator(speeds, values, axis=0, extrapolate=True)
    clipped = float(np.clip(speed, speeds[0], speeds[-1]))
    slope = p.derivative()(clipped)
    return p(clipped) + (speed - clipped) * slope


@dataclass(frozen=True)
class SpeedTables:
    """Lateral bearing (or seal) coefficients tabulated over the spin speed.

    Parameters
    ----------
    nodes : int array (b,)
        Node of each tabulated bearing.
    speeds : tuple of arrays
        Per bearing its strictly increasing table speeds, rad/s.
    values : tuple of arrays
        Per bearing ``(s, 8)``: the columns :data:`SPEED_COEFFICIENTS` (N/m, N s/m) at its speeds.
    """

    nodes: np.ndarray
    speeds: tuple
    values: tuple

    def coefficients(self, speed: float) -> np.ndarray:
        """``(b, 8)`` coefficients at ``speed`` (rad/s), interpolated per bearing."""
        return np.array([interpolate_over_speed(s, v, speed) for s, v in zip(self.speeds, self.values)])

    def blocks(self, speed: float) -> tuple[np.ndarray, np.ndarray]:
        """``(b, 2, 2)`` lateral stiffness and damping blocks at ``speed`` (rad/s)."""
        c = self.coefficients(speed).reshape(-1, 2, 2, 2)
        return c[:, 0], c[:, 1]
