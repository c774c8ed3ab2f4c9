"""Steady state of a band on the driven arc with a slip that grows along the arc (creep).

The 6+2n band model (:mod:`cvtfem.elements.band.compressible`) evaluates its slip with the Jacobian at ``h = 0``: in
steady running the band slides over the whole arc at one speed, so its friction coefficient is uniform and the arc's
balance fixes the span tensions independently of the friction law.  A chain's slip is not uniform: its links stretch
with the tension (the chain leaves the driven arc faster than it enters) and its pins sit deeper in the wedge where
they carry more axial load (they meet a slower sheave point).  :func:`creep_arc` solves the arc's balance with such
a slip, for a band with the chain's extensional stiffness and pin give:

* radial balance ``T - rho v^2 = 2 r N sin(gamma)`` (``N`` per sheave and unit length, both sheaves),
* tangential balance ``dT/dtheta = 2 r f(w) N`` along the arc (``theta`` from the entry),
* axial balance of a sheave ``F = int N cos(gamma) r dtheta``,
* slip ``w(theta) = w_in + v (T - T_in) / EA + omega (d(P(T)) - d(P(T_in))) / tan(gamma)`` (m/s, the band faster
  than the sheave), ``P = (T - rho v^2) pitch / (2 r tan(gamma))`` the axial load of a pin end, ``d(P) =
  P / (2 c_pin) + (P / c_hertz)^(2/3)`` its axial give (pin spring of S1/S2, Hertz of H1), ``omega = v / r``;

with the tension gain ``D = T_out - T_in`` (the driven torque over ``r``) given, two unknowns ``T_in``, ``w_in``
solve ``T(wrap) - T_in = D`` and the axial balance.  Without creep (the defaults) ``f`` is uniform and
``T_in = rho v^2 + D / (exp(D wrap / (2 F tan(gamma))) - 1)`` for every friction law (tested).

:func:`held_arc` turns the question round for either arc: the clamping force a sheave needs to hold given span
tensions (driven arc: the slack span's at its entry, the tight span's at its exit; driving arc: the other way round),
with the same creep and, in addition, the radial slip of the pins as their give changes along the arc (spiral
running): a pin that sinks deeper as its load grows moves inwards at ``w_r = -omega d'(P) dP/dtheta / tan(gamma)``,
friction turns against that motion, and the radial balance becomes ``T - rho v^2 = 2 r N (sin(gamma) - f_r)`` with
the axial force per length ``N (cos(gamma) + f_a)`` (``f_r``, ``f_a`` the radial and axial parts of the friction
coefficient vector, the 6+2n band's own convention).  With no give it is the Euler arc, and the ratio of the two
arcs' forces is the band's ``F1/F2 = tan(gamma_2) wrap_1 / (tan(gamma_1) wrap_2)`` (tested).
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, newton, root

from cvtfem.elements.band.geometry import radii
from cvtfem.elements.contact.friction import friction_coefficient, friction_vector
from cvtfem.errors import InputError, NumericalError


def creep_arc(r: float, tan_gamma: float, wrap: float, v: float, rho: float, F: float, D: float, f0: float,
              v0: float, law: str = "tanh", EA: float = np.inf, c_pin: float = np.inf, c_hertz: float = np.inf,
              pitch: float = 0.009, n_out: int = 61) -> dict:
    """Steady band on the driven arc (module docstring): radius ``r`` m, ``tan(gamma)`` of the faces there, wrap
    angle ``wrap`` rad, band speed ``v`` m/s, mass per length ``rho`` kg/m, clamping force ``F`` N per sheave, tension
    gain ``D`` N, friction law ``f0``, ``v0`` m/s, ``law``; extensional stiffness ``EA`` N, pin axial stiffness
    ``c_pin`` N/m, Hertz stiffness ``c_hertz`` N/m^1.5, ``pitch`` m.  Returns ``T`` (tight, slack) N, ``slip``
    (entry, exit) m/s and ``n_out`` points along the arc: ``theta`` rad from the entry, ``T_theta`` N, ``f_theta``."""
    for key, val in (("r", r), ("tan_gamma", tan_gamma), ("v", v), ("rho", rho), ("F", F), ("D", D), ("f0", f0),
                     ("v0", v0), ("EA", EA), ("c_pin", c_pin), ("c_hertz", c_hertz), ("pitch", pitch)):
        if not val > 0:
            raise InputError(f"creep_arc.{key}", val, "must be > 0")
    if not 0 < wrap < 2 * np.pi:
        raise InputError("creep_arc.wrap", wrap, "must lie in (0, 2 pi) rad")
    sg = tan_gamma / np.hypot(1.0, tan_gamma)
    omega = v / r
    rv2 = rho * v * v

    def give(T):
        P = np.maximum(T - rv2, 0.0) * pitch / (2 * r * tan_gamma)
        return P / (2 * c_pin) + (P / c_hertz) ** (2 / 3)

    def slip(T, T_in, w_in):
        return w_in + v * (T - T_in) / EA + omega * (give(T) - give(T_in)) / tan_gamma

    def profile(T_in, w_in):
        def rhs(_, y):
            f = friction_coefficient(abs(slip(y[0], T_in, w_in)), f0, v0, law)
            return [f * (y[0] - rv2) / sg, y[0] - rv2]
        return solve_ivp(rhs, (0.0, wrap), [T_in, 0.0], rtol=1e-11, atol=1e-9, dense_output=True)

    def residual(p):
        T_out, integral = profile(*p).y[:, -1]
        return [(T_out - p[0] - D) / D, (integral / (2 * tan_gamma) - F) / F]

    # start from the uniform-slip state: the closed-form slack tension and the slip of its friction coefficient
    T0 = rv2 + D / np.expm1(D * wrap / (2 * F * tan_gamma))
    k = D / (2 * F * tan_gamma) * sg                     # the uniform friction coefficient
    w = np.geomspace(1e-6 * v0, 1e3 * v0, 4001)
    w0 = float(np.interp(k, friction_coefficient(w, f0, v0, law), w))
    if not k < f0:
        raise InputError("creep_arc.D", D, f"must need a friction coefficient below f0 = {f0} (needs {k:.3g})")
    sol = root(residual, [T0, w0], tol=1e-12)
    if not sol.success or np.max(np.abs(residual(sol.x))) > 1e-8:
        raise NumericalError(f"the arc balance did not converge ({sol.message})", component="creep_arc")
    T_in, w_in = sol.x
    theta = np.linspace(0.0, wrap, n_out)
    T = profile(T_in, w_in).sol(theta)[0]
    w_theta = slip(T, T_in, w_in)
    return {"T": np.array([T[-1], T_in]), "slip": w_theta[[0, -1]], "theta": theta, "T_theta": T,
            "f_theta": friction_coefficient(np.abs(w_theta), f0, v0, law)}


def held_arc(r: float, tan_gamma: float, wrap: float, v: float, rho: float, T_in: float, T_out: float, f0: float,
             v0: float, law: str = "tanh", EA: float = np.inf, c_pin: float = np.inf, c_hertz: float = np.inf,
             pitch: float = 0.009, radial: bool = True, n_out: int = 61) -> dict:
    """Steady band on an arc that takes the span tension ``T_in`` N at its entry and ``T_out`` N at its exit
    (module docstring): geometry, speed, friction law and give as :func:`creep_arc`; ``radial`` adds the pins'
    radial slip from their changing give.  Returns the sheave's axial force ``F`` N the arc needs, the slip offset
    ``w_in`` m/s at the entry and ``n_out`` points along the arc: ``theta`` rad from the entry, ``T_theta`` N, the
    tangential and radial slip ``w_t``, ``w_r`` m/s (band against sheave, outwards > 0) and friction coefficient
    parts ``f_t``, ``f_r`` (on the sheave; on the band they are reversed)."""
    for key, val in (("r", r), ("tan_gamma", tan_gamma), ("v", v), ("rho", rho), ("f0", f0), ("v0", v0),
                     ("EA", EA), ("c_pin", c_pin), ("c_hertz", c_hertz), ("pitch", pitch)):
        if not val > 0:
            raise InputError(f"held_arc.{key}", val, "must be > 0")
    if not 0 < wrap < 2 * np.pi:
        raise InputError("held_arc.wrap", wrap, "must lie in (0, 2 pi) rad")
    rv2 = rho * v * v
    for key, val in (("T_in", T_in), ("T_out", T_out)):
        if not val > rv2:
            raise InputError(f"held_arc.{key}", val, f"must exceed rho v^2 = {rv2:.4g} N")
    sg = tan_gamma / np.hypot(1.0, tan_gamma)
    cg, omega, k_P = sg / tan_gamma, v / r, pitch / (2 * r * tan_gamma)

    def give(T):
        P = np.maximum(T - rv2, 0.0) * k_P
        return P / (2 * c_pin) + (P / c_hertz) ** (2 / 3)

    def give_rate(T):                                   # d(give)/dT, m/N
        P = max(T - rv2, 1e-9) * k_P
        return k_P * (1 / (2 * c_pin) + (2 / 3) * P ** (-1 / 3) * c_hertz ** (-2 / 3))

    def coefficients(w_t, w_r):                         # friction coefficient vector (radial, tangential, axial)
        s = np.sqrt(w_t * w_t + w_r * w_r * (1 + tan_gamma * tan_gamma))
        g = float(friction_coefficient(s, f0, v0, law)) / s if s > 0 else 0.0
        return g * w_r, g * w_t, g * tan_gamma * w_r

    def slope(T, w_t):
        """``dT/dtheta``, ``w_r`` and the coefficients, ``w_r = -omega give'(T) dT/dtheta / tan(gamma)`` solved."""
        def dT(w_r):
            f = coefficients(w_t, w_r)
            return (T - rv2) * f[1] / (sg - f[0]), f
        c = omega * give_rate(T) / tan_gamma if radial else 0.0
        g0 = c * dT(0.0)[0]
        w_r = 0.0 if g0 == 0 else float(newton(lambda w: w + c * dT(w)[0], 0.0, x1=-g0, tol=1e-10, maxiter=50))
        return (*dT(w_r), w_r)

    def profile(w_in, dense=False):
        d_in = give(T_in)

        def rhs(_, y):
            w_t = w_in + v * (y[0] - T_in) / EA + omega * (give(y[0]) - d_in) / tan_gamma
            dT, f, _ = slope(y[0], w_t)
            return [dT, (y[0] - rv2) * (cg + f[2]) / (2 * (sg - f[0]))]
        return solve_ivp(rhs, (0.0, wrap), [T_in, 0.0], rtol=1e-8, atol=1e-6, dense_output=dense)

    def miss(w_in):
        return profile(w_in).y[0, -1] - T_out

    # bracket the entry slip around the uniform slip of the Euler arc (T_out is monotone in it)
    k = np.log((T_out - rv2) / (T_in - rv2)) / wrap * sg
    if not abs(k) < f0:
        raise InputError("held_arc.T_out", T_out, f"must need a friction coefficient below f0 = {f0} (needs {k:.3g})")
    w = np.geomspace(1e-6 * v0, 1e3 * v0, 4001)
    w0 = float(np.interp(abs(k), friction_coefficient(w, f0, v0, law), w)) * np.sign(k)
    lo, hi = w0 - v0, w0 + v0
    for _ in range(40):
        m_lo, m_hi = miss(lo), miss(hi)
        if m_lo < 0 < m_hi:
            break
        lo, hi = (lo - 2 * v0, hi) if m_lo >= 0 else (lo, hi + 2 * v0)
    else:
        raise NumericalError(f"no entry slip holds {T_in:.0f} -> {T_out:.0f} N (friction saturated)",
                             component="held_arc")
    w_in = brentq(miss, lo, hi, xtol=1e-9 * v0, rtol=1e-12)
    sol = profile(w_in, dense=True)
    theta = np.linspace(0.0, wrap, n_out)
    T = sol.sol(theta)[0]
    w_t = w_in + v * (T - T_in) / EA + omega * (give(T) - give(T_in)) / tan_gamma
    rows = np.array([(*slope(a, b)[1], slope(a, b)[2]) for a, b in zip(T, w_t)])
    return {"F": float(sol.y[1, -1]), "w_in": float(w_in), "theta": theta, "T_theta": T, "w_t": w_t,
            "w_r": rows[:, 3], "f_t": rows[:, 1], "f_r": rows[:, 0]}


def band_arc(band, q, v, k: int) -> dict:
    """Arc ``k`` (0 driving, 1 driven) of the 6+2n band ``band`` at ``(q, v)``: the geometry arguments of
    :func:`held_arc` (``r``, ``tan_gamma``, ``wrap``, ``v``, ``rho``, friction law), the sheave's axial force ``F``
    N (the clamping force in steady running) and the tension ``T_theta = rho v^2 + 2 r N sin(gamma)`` N at the
    band's nodes ``theta`` rad from the arc's entry."""
    p = band.p
    g = band.arcs(q[0])
    _, N, _ = band._friction(q, v, g, band.strain(q, g))
    tg, half, th, ds = g["tg"][k], g["ts"][k], g["th"][k], g["ds"][k]
    sg = tg / np.hypot(1.0, tg)
    r = radii(q[0], p.length, p.L)[0][k]
    geometry = {"r": r, "tan_gamma": tg, "wrap": 2 * half, "v": v[1], "rho": p.rho, "f0": p.f0, "v0": p.v0,
                "law": p.law}
    return {"args": geometry, "F": float(np.sum(N[k] * sg / tg * ds)), "theta": th + half,
            "T_theta": p.rho * v[1] ** 2 + 2 * r * N[k] * sg}


def driven_arc(band, q, v) -> dict:
    """The driven arc of the 6+2n band ``band`` (:class:`~cvtfem.elements.band.compressible.CompressibleBand`) at
    ``(q, v)``: ``args``, the arguments of :func:`creep_arc` (``r``, ``tan_gamma``, ``wrap``, ``v``, ``rho``, the
    sheave's axial force ``F`` = the clamping force in steady running, the friction law, and the tension gain ``D`` of
    the arc's momentum balance) and, for comparison, at the band's nodes ``theta`` rad from the arc's entry the tension
    ``T_theta = rho v^2 + 2 r N sin(gamma)`` N and the tangential friction coefficient ``f_theta``; ``T`` (tight,
    slack) N from the momentum balance of the whole arc (steady running: the span tensions less ``rho v^2`` pulling
    at the tangents balance the in-plane resultant of the contact forces)."""
    p = band.p
    g = band.arcs(q[0])
    _, N, vr = band._friction(q, v, g, band.strain(q, g))
    ft = friction_vector(vr, p.f0, p.v0, p.law, axis=0)[:, 1]   # f t (radial, tangential, axial) at the nodes
    tg, half, th, ds = g["tg"][1], g["ts"][1], g["th"][1], g["ds"][1]
    sg = tg / np.hypot(1.0, tg)
    rv2 = p.rho * v[1] ** 2
    c_r, c_t = 2 * N[1] * (sg - ft[0]), -2 * N[1] * ft[1]       # in-plane force on the band per length, N/m
    along = np.sum((c_r * np.cos(th) - c_t * np.sin(th)) * ds)  # resultant along the arc's axis and across it
    across = np.sum((c_r * np.sin(th) + c_t * np.cos(th)) * ds)
    total, gain = along / np.sin(half) + 2 * rv2, -across / np.cos(half)
    r = radii(q[0], p.length, p.L)[0][1]
    args = {"r": r, "tan_gamma": tg, "wrap": 2 * half, "v": v[1], "rho": p.rho, "F": np.sum(N[1] * sg / tg * ds),
            "D": gain, "f0": p.f0, "v0": p.v0, "law": p.law}
    return {"args": args, "T": np.array([total + gain, total - gain]) / 2, "theta": th + half,
            "T_theta": rv2 + 2 * r * N[1] * sg, "f_theta": ft[1]}
