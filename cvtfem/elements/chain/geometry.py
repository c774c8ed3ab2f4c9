"""Chain geometry: pins, links, plates and their stations along the pin (spec chain-models-1 §1, §6).

Pins ``p = 0..n-1`` and links ``p`` = ``(p, p+1)`` are indexed cyclically (§1.2, zero-based here).
Plate ``k`` of link ``p`` sits at the fixed station ``xi[p, k]`` on both pins (§1.4); links hold at
most ``k_max`` plates, unused entries have zero stiffness and mass (``plate_mask``).  An open chain
(``closed=False``) is the same cyclic arrangement with link ``n-1`` (last pin to first) absent.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from cvtfem.elements.link_pattern import link_lengths
from cvtfem.errors import InputError

#: Young's modulus of steel, Pa (chain-models-1 §6, context value).
E_STEEL = 2.1e11
#: Density of steel, kg/m^3.
RHO_STEEL = 7850.0


def h1(xi, l: float):
    """S3 bending shape ``h1(xi) = l/2 (xi^2 - 1)``, m (eq. 1.96b)."""
    return 0.5 * l * (np.asarray(xi) ** 2 - 1.0)


def weave_stations(n_links: int, plates_per_link: int, period: int = 3, pack: float = 0.8) -> np.ndarray:
    """Plate stations ``xi`` of a laced chain, shape ``(n_links, plates_per_link)``.

    The plate pack spans ``|xi| <= pack`` and is cut into ``period * plates_per_link`` equal slots;
    link ``p`` occupies slots ``p mod period + period k`` (its plates interleave with those of the
    ``period - 1`` neighbouring links, so the two links on one pin never share a slot when ``n`` is
    a multiple of ``period``).  Stations are the slot centres.
    """
    if period < 1 or plates_per_link < 1 or not 0.0 < pack <= 1.0:
        raise InputError("weave_stations", (plates_per_link, period, pack),
                         "plates_per_link >= 1, period >= 1 and 0 < pack <= 1")
    n_slots = period * plates_per_link
    centres = -pack + pack * (2 * np.arange(n_slots) + 1) / n_slots
    slot = (np.arange(n_links) % period)[:, None] + period * np.arange(plates_per_link)[None, :]
    return centres[slot]


@dataclass(frozen=True)
class ChainGeometry:
    """A chain of ``n`` pins and ``n`` links with its plates (SI units).

    Attributes
    ----------
    L : (n,) m
        Undeformed pitch ``L_{p,p+1}`` of link ``p`` (eq. 1.73).
    l : float, m
        Undeformed pin-axis length.
    xi : (n, k_max)
        Plate stations (Lagrangian pin coordinate, -1..1).
    c_plate, m_plate : (n, k_max) N/m, kg
        Tensile stiffness and mass of each plate (0 where ``plate_mask`` is false).
    m_pin, c_pin : (n,) kg, N/m
        Pin mass and axial stiffness ``c_p`` (eq. 1.71).
    A_tau, A_n : float, N m^2
        Pin bending stiffness against deflection along the chain direction / its normal (§3.5).
    closed : bool
        Closed loop (all ``n`` links) or open chain (link ``n-1`` absent).
    """

    L: np.ndarray
    l: float
    xi: np.ndarray
    c_plate: np.ndarray
    m_plate: np.ndarray
    m_pin: np.ndarray
    c_pin: np.ndarray
    A_tau: float = 0.0
    A_n: float = 0.0
    closed: bool = True
    plate_mask: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        n = len(self.L)
        for name in ("xi", "c_plate", "m_plate"):
            if np.shape(getattr(self, name)) != np.shape(self.xi) or np.shape(self.xi)[0] != n:
                raise InputError(f"ChainGeometry.{name}", np.shape(getattr(self, name)), f"shape (n={n}, k_max)")
        if np.shape(self.m_pin) != (n,) or np.shape(self.c_pin) != (n,):
            raise InputError("ChainGeometry.m_pin/c_pin", (np.shape(self.m_pin), np.shape(self.c_pin)),
                             f"shape ({n},)")
        if n < 3 or np.any(np.asarray(self.L) <= 0) or self.l <= 0:
            raise InputError("ChainGeometry", (n, self.l), "n >= 3 pins, L > 0, l > 0")
        object.__setattr__(self, "plate_mask", np.asarray(self.c_plate) > 0)

    @property
    def n(self) -> int:
        """Number of pins (= links of the closed loop)."""
        return len(self.L)

    @property
    def link_on(self) -> np.ndarray:
        """1.0 for every existing link, 0.0 for the absent closing link of an open chain, (n,)."""
        on = np.ones(self.n)
        if not self.closed:
            on[-1] = 0.0
        return on

    @property
    def m_eff(self) -> np.ndarray:
        """Effective pin mass, kg (eq. 1.68): pin plus half the plates of both adjacent links."""
        half = 0.5 * (self.m_plate.sum(axis=1) * self.link_on)
        return self.m_pin + half + np.roll(half, 1)

    @property
    def c_link(self) -> np.ndarray:
        """Link stiffness ``c = sum_k c^k``, N/m (eq. 1.77); 0 for an absent link."""
        return self.c_plate.sum(axis=1) * self.link_on

    @property
    def c1_link(self) -> np.ndarray:
        """``c' = sum_k c^k h1(xi^k)``, N (eq. 1.108)."""
        return (self.c_plate * h1(self.xi, self.l)).sum(axis=1) * self.link_on

    @property
    def c2_link(self) -> np.ndarray:
        """``c'' = sum_k c^k h1(xi^k)^2``, N m (eq. 1.108)."""
        return (self.c_plate * h1(self.xi, self.l) ** 2).sum(axis=1) * self.link_on

    @property
    def length(self) -> float:
        """Chain length ``sum L`` over the existing links, m."""
        return float((self.L * self.link_on).sum())


@dataclass(frozen=True)
class PinSection:
    """Pin cross-section (two halves) and material; gives ``c_p`` and the bending stiffnesses.

    A rectangle ``width_tau`` (along the chain) by ``width_n``, split into two halves across its
    ``width_tau`` side.  Independent halves (§3.6, case (a)): ``A_tau = 2 E I_half``, ``A_n = E I_n``.
    """

    width_tau: float  # m
    width_n: float    # m
    E: float = E_STEEL

    @property
    def area(self) -> float:
        """Cross-section area of the whole pin, m^2."""
        return self.width_tau * self.width_n

    def axial_stiffness(self, l: float) -> float:
        """``c_p = E F / l``, N/m (eq. 1.136)."""
        return self.E * self.area / l

    @property
    def A_tau(self) -> float:
        """Stiffness against deflection along the chain, N m^2: two halves of thickness ``width_tau/2``."""
        return 2 * self.E * self.width_n * (self.width_tau / 2) ** 3 / 12

    @property
    def A_n(self) -> float:
        """Stiffness against deflection along the normal, N m^2 (halves side by side)."""
        return self.E * self.width_tau * self.width_n ** 3 / 12


def chain_geometry(n: int, l: float, pitch: float | np.ndarray, plates_per_link: int, c_link: float,
                   mass: float, section: PinSection, period: int = 3, pack: float = 0.8,
                   closed: bool = True, c_pin: float | None = None) -> ChainGeometry:
    """Chain with equal plates: ``c_link`` (N/m) shared by the plates, total ``mass`` (kg) split into
    steel pins of ``section`` over ``l`` and equal plates; ``pitch`` one length (m) or ``(n,)`` lengths;
    ``c_pin`` (N/m) defaults to ``E F / l`` of the section."""
    L = np.broadcast_to(np.asarray(pitch, float), (n,)).copy()
    m_pin = RHO_STEEL * section.area * l
    m_plates = mass - n * m_pin
    if m_plates <= 0:
        raise InputError("chain_geometry.mass", mass, f"> the pins' mass {n * m_pin:.4g} kg")
    xi = weave_stations(n, plates_per_link, period, pack)
    shape = xi.shape
    return ChainGeometry(L=L, l=l, xi=xi, c_plate=np.full(shape, c_link / plates_per_link),
                         m_plate=np.full(shape, m_plates / (n * plates_per_link)), m_pin=np.full(n, m_pin),
                         c_pin=np.full(n, section.axial_stiffness(l) if c_pin is None else c_pin), A_tau=section.A_tau, A_n=section.A_n,
                         closed=closed)


#: Pin section of the reference chain: 2.4 mm along the chain, 6 mm across (gives I_min = 6.9e-12 m^4
#: of the whole pin, chain-models-1 §6: 6.8e-12; area 1.44e-5 m^2 as the reference scene).
REFERENCE_SECTION = PinSection(width_tau=0.0024, width_n=0.006)


def reference_geometry(randomised: bool = False, seed: int = 0) -> ChainGeometry:
    """The reference chain (scene preset ``reference_cvt``): 84 pins, l = 33 mm, 12 plates per link
    laced with period 3, 1.5 kg, link stiffness 1.4e9 N/m, pin axial stiffness 2e8 N/m; pitch 9 mm or the randomised 8.5/9.5 mm
    pattern (half long, :func:`cvtfem.elements.link_pattern.link_lengths` seeded by ``seed``)."""
    n = 84
    pitch = (link_lengths(n, 0.0085, 0.0095, 0.5, np.random.default_rng(seed)) if randomised else 0.009)
    return chain_geometry(n, 0.033, pitch, 12, 1.4e9, 1.5, REFERENCE_SECTION, c_pin=2.0e8)


def ring_positions(L: np.ndarray) -> tuple[np.ndarray, float]:
    """Pins of a closed chain on a circle with every link straight and unstretched, counter-clockwise.

    Returns positions (n, 2) m, pin 0 on the ``x1`` axis, and the radius R (m) that solves
    ``sum 2 asin(L_p / (2 R)) = 2 pi`` (the circle through the vertices of a polygon with sides ``L``).
    """
    L = np.asarray(L, float)
    total = L.sum()
    R = brentq(lambda r: 2 * np.arcsin(np.minimum(L / (2 * r), 1.0)).sum() - 2 * np.pi, total / (2 * np.pi), total,
               xtol=1e-15 * total, rtol=4 * np.finfo(float).eps)
    theta = np.concatenate([[0.0], np.cumsum(2 * np.arcsin(L / (2 * R)))[:-1]])
    return R * np.stack([np.cos(theta), np.sin(theta)], axis=1), float(R)
