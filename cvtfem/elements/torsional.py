"""Torsional networks: disks, shafts, gear meshes, backlash and one-sided gaps.

Every quantity is written in circumferential coordinates at the radius ``r``
of the (single) gear on each shaft, as in the source (spec
numerics-and-periodic.md, section 8.1): ``x = r phi``, ``m = I / r^2``,
``b = b_phi / r^2``, shaft stiffness ``c = k_phi / r^2``, force ``q = M / r``.
A gear mesh is then a plain spring between the two gears' ``x`` (the sign of
the second gear's rotation is absorbed into its coordinate), so the whole
drivetrain is a spring network without ratios.

Links are one vectorised family: link ``e`` joins node ``i[e]`` to node
``j[e]`` (``-1`` = ground), deflection ``l = x_j - x_i`` and force ``f(l)``
(+ viscous ``d l'``) acting ``+f`` on node ``i`` and ``-f`` on node ``j``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: Link law codes.
LINEAR, BACKLASH, GAP = 0, 1, 2
LAW_NAMES = ("linear", "backlash", "gap")


def smooth_ramp(u: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """C1 ramp ``max(u, 0)`` rounded over ``|u| <= w`` and its derivative.

    ``R = 0`` for ``u < -w``, ``(u + w)^2 / (4 w)`` for ``|u| <= w``, ``u`` for
    ``u > w``; ``R' = 0, (u + w) / (2 w), 1``.  ``w = 0`` gives the sharp ramp.

    >>> smooth_ramp(np.array([-1.0, 0.0, 1.0]), np.array(0.5))[0].tolist()
    [0.0, 0.125, 1.0]
    """
    ws = np.where(w > 0, w, 1.0)
    inside = np.abs(u) <= w
    R = np.where(u > w, u, np.where(inside, (u + w) ** 2 / (4 * ws), 0.0))
    dR = np.where(u > w, 1.0, np.where(inside, (u + w) / (2 * ws), 0.0))
    return R, dR


def ramp_integral(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``P(u) = int_{-inf}^{u} R``, R of :func:`smooth_ramp`: ``0``, ``(u + w)^3 / (12 w)``, ``u^2 / 2 + w^2 / 6``.

    >>> ramp_integral(np.array([-1.0, 0.0, 1.0]), np.array(0.5)).tolist()
    [0.0, 0.020833333333333332, 0.5416666666666666]
    """
    ws = np.where(w > 0, w, 1.0)
    return np.where(u > w, u ** 2 / 2 + w ** 2 / 6, np.where(np.abs(u) <= w, (u + w) ** 3 / (12 * ws), 0.0))


def link_energy(l: np.ndarray, law: np.ndarray, k_in: np.ndarray, k_out: np.ndarray,
                h: np.ndarray, zone: np.ndarray) -> np.ndarray:
    """Elastic energy ``V(l)`` (J) of every link, ``V' = f`` of :func:`link_force` (same arguments), ``V(0) = 0``."""
    k0, dk, centre, w, two_sided = _law_terms(np.ndim(l), law, k_in, k_out, h, zone)
    return k0 * l ** 2 / 2 + dk * (ramp_integral(l - centre, w) - ramp_integral(-centre, w)
                                   + np.where(two_sided, ramp_integral(-l - centre, w) - ramp_integral(-centre, w),
                                              0.0))


def _law_terms(ndim: int, law, k_in, k_out, h, zone):
    """Per-link ``k0``, ``dk = k_out - k_in`` (0 for linear links), contact centre, half zone width ``w`` and the
    two-sided flag, shaped ``(E, 1, ...)`` to broadcast against deflections of ``ndim`` dimensions."""
    shape = (-1,) + (1,) * (ndim - 1)
    law, k_in, k_out = law.reshape(shape), k_in.reshape(shape), k_out.reshape(shape)
    h = h.reshape(shape)
    dk = np.where(law == LINEAR, 0.0, k_out - k_in)
    k0 = np.where(law == LINEAR, k_out, k_in)
    centre = np.where(law == GAP, h, h / 2)
    return k0, dk, centre, (zone.reshape(shape) * h / 2), law == BACKLASH


def link_force(l: np.ndarray, law: np.ndarray, k_in: np.ndarray, k_out: np.ndarray,
               h: np.ndarray, zone: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Elastic force ``f(l)`` and stiffness ``f'(l)`` of every link.

    Parameters
    ----------
    l : ndarray (E, ...) m
        Deflections ``x_j - x_i``; trailing axes (time samples) broadcast.
    law : ndarray (E,) int
        LINEAR, BACKLASH (symmetric dead zone of total width ``h``) or GAP
        (one-sided: contact for ``l > h``).
    k_in, k_out : ndarray (E,) N/m
        Gap (weak, residual) and contact stiffness.  Spec erratum 10 #15: the
        printed law B:(18) swaps them; here the weak one is inside the gap.
    h : ndarray (E,) m
        Clearance.
    zone : ndarray (E,) -
        Width of the transition zone as a fraction of ``h``, centred on the
        contact point (0.2 reproduces B:(18): ``0.4 h <= |l| <= 0.6 h``).

    Returns
    -------
    f : ndarray, N ; df : ndarray, N/m
        ``f`` and ``f'`` are continuous; ``f''`` is piecewise constant with
        ``|f''| <= (k_out - k_in) / (zone h)`` (bound K of B:(21)).

    Examples
    --------
    The source's law at the ends of the transition zone (``h = 1``, ``k_in = 1``,
    ``k_out = 11``): ``f(0.6) = 11 * 0.6 - 10 * 0.5 = 1.6``.

    >>> one = np.ones(1)
    >>> f, df = link_force(np.array([[0.4, 0.6]]), np.array([1]), one, 11 * one, one, 0.2 * one)
    >>> np.round(f, 12).tolist(), np.round(df, 12).tolist()
    ([[0.4, 1.6]], [[1.0, 11.0]])
    """
    k0, dk, centre, w, two_sided = _law_terms(np.ndim(l), law, k_in, k_out, h, zone)
    Rp, dRp = smooth_ramp(l - centre, w)
    Rm, dRm = smooth_ramp(-l - centre, w)
    f = k0 * l + dk * (Rp - np.where(two_sided, Rm, 0.0))
    df = k0 + dk * (dRp + np.where(two_sided, dRm, 0.0))
    return f, df


@dataclass(frozen=True)
class TorsionalNetwork:
    """A torsional network in circumferential coordinates (all arrays read-only).

    Attributes
    ----------
    names : tuple of str
        Node (disk) names, S of them.
    m : ndarray (S,) kg
        Reduced masses ``I / r^2``.
    b : ndarray (S,) N s/m
        External (to ground) damping ``b_phi / r^2``.
    radius : ndarray (S,) m
        Gear radius of each node's shaft (torque = force x radius).
    link_names : tuple of str
        E link names.
    i, j : ndarray (E,) int
        End nodes; ``j = -1`` ties the link to ground.
    law : ndarray (E,) int
        LINEAR, BACKLASH or GAP.
    k_out, k_in : ndarray (E,) N/m
        Contact (linear) and gap stiffness.
    h, zone : ndarray (E,)
        Clearance (m) and transition-zone fraction (-).
    d : ndarray (E,) N s/m
        Viscous damping of the link.
    orders : ndarray (H,) int
        Harmonic orders of the loads (of the base frequency ``omega``).
    Q : ndarray (S, H) complex, N
        Load of node s: ``q_s(t) = sum_k Re(Q[s, k] exp(i orders[k] omega t))``.
    """

    names: tuple[str, ...]
    m: np.ndarray
    b: np.ndarray
    radius: np.ndarray
    link_names: tuple[str, ...]
    i: np.ndarray
    j: np.ndarray
    law: np.ndarray
    k_out: np.ndarray
    k_in: np.ndarray
    h: np.ndarray
    zone: np.ndarray
    d: np.ndarray
    orders: np.ndarray
    Q: np.ndarray

    def __post_init__(self) -> None:
        for name in ("m", "b", "radius", "i", "j", "law", "k_out", "k_in", "h", "zone", "d", "orders", "Q"):
            getattr(self, name).flags.writeable = False

    @property
    def n_nodes(self) -> int:
        return len(self.m)

    @property
    def n_links(self) -> int:
        return len(self.i)

    def incidence(self) -> sp.csr_matrix:
        """``D`` (E x S): ``(D x)_e = x_j - x_i`` (ground columns dropped), spec B:(2)."""
        E = self.n_links
        rows = np.concatenate([np.arange(E), np.arange(E)])
        cols = np.concatenate([self.j, self.i])
        vals = np.concatenate([np.ones(E), -np.ones(E)])
        keep = cols >= 0
        return sp.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(E, self.n_nodes))

    def linearized(self, stiffness: str = "contact") -> TorsionalNetwork:
        """The same network with every nonlinear link made linear.

        ``stiffness="contact"`` uses ``k_out`` (no backlash), ``"gap"`` uses ``k_in``.
        """
        from dataclasses import replace

        k = self.k_out if stiffness == "contact" else np.where(self.law == LINEAR, self.k_out, self.k_in)
        return replace(self, law=np.zeros_like(self.law), k_out=k.copy(), k_in=k.copy(),
                       h=np.zeros_like(self.h))

    def load(self, t: np.ndarray, omega: float) -> np.ndarray:
        """External forces ``q(t)`` (S, len(t)), N."""
        phase = np.exp(1j * np.outer(self.orders, np.atleast_1d(t)) * omega)
        return (self.Q @ phase).real

    def forces(self, l: np.ndarray, ldot: np.ndarray) -> np.ndarray:
        """Link forces ``f(l) + d l'`` (E, ...), N."""
        f, _ = link_force(l, self.law, self.k_in, self.k_out, self.h, self.zone)
        return f + self.d.reshape((-1,) + (1,) * (np.ndim(l) - 1)) * ldot

    def first_order_rhs(self, omega: float):
        """``F(t, y)`` of ``y = [x, v]`` for time integration (solve_ivp signature)."""
        D = self.incidence()
        DT = D.T.tocsr()
        S = self.n_nodes

        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            x, v = y[:S], y[S:]
            f = self.forces(D @ x, D @ v)
            a = (self.load(t, omega)[:, 0] - self.b * v - DT @ f) / self.m
            return np.concatenate([v, a])

        return rhs


def build_network(m, b, i, j, k, *, d=None, law=None, k_in=None, h=None, zone=None, orders=(1,),
                  Q=None, radius=None, names=None, link_names=None) -> TorsionalNetwork:
    """A :class:`TorsionalNetwork` from plain arrays; omitted link arrays default to linear links.

    >>> net = build_network([1.0, 2.0], [0.1, 0.1], [0, 1], [1, -1], [10.0, 5.0])
    >>> net.n_nodes, net.n_links, net.law.tolist()
    (2, 2, [0, 0])
    """
    m, b = np.asarray(m, float), np.asarray(b, float)
    S, k = len(m), np.asarray(k, float)
    E = len(k)

    def arr(v, default, dtype=float):
        return np.full(E, default, dtype) if v is None else np.asarray(v, dtype).copy()

    orders = np.asarray(orders, int)
    return TorsionalNetwork(
        names=tuple(names) if names is not None else tuple(f"n{s}" for s in range(S)),
        m=m.copy(), b=b.copy(), radius=arr(radius, 1.0) if radius is not None else np.ones(S),
        link_names=tuple(link_names) if link_names is not None else tuple(f"l{e}" for e in range(E)),
        i=np.asarray(i, int).copy(), j=np.asarray(j, int).copy(), law=arr(law, LINEAR, int),
        k_out=k.copy(), k_in=arr(k_in, 0.0) if k_in is not None else k.copy(), h=arr(h, 0.0),
        zone=arr(zone, 0.2), d=arr(d, 0.0), orders=orders,
        Q=np.zeros((S, len(orders)), complex) if Q is None else np.asarray(Q, complex).reshape(S, -1).copy())
