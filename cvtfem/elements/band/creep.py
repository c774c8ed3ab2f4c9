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
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

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
