"""Generator of the DUMKA3 data (spec §5, §11.6); run ``studies/integrators/generate_dumka3.py``.

cvtfem regenerates Medovikov's 14 third-order stability polynomials from their definition
(Medovikov, BIT 38(2) 1998) instead of vendoring the published coefficient tables (GPL-3):

1. ``R_s(z) = sum c_k T_k(1 + 2z/beta)`` of degree ``s`` with ``R = 1 + z + z^2/2 + z^3/6 +
   O(z^4)``. For a given ``beta`` a linear programme (HiGHS) minimises the damping bound
   ``t = max |R|`` over ``[-beta, -zeta]`` (``|R| <= 1`` on ``[-zeta, 0]``, ``zeta = -2 ln t``);
   ``eta = 1 - t`` (then re-measured on an 80x finer grid: the LP bound holds at its grid
   points only; this verified ``eta`` is stored). ``beta`` is adjusted (secant) until the
   real stability length of ``R`` (largest ``L`` with ``|R| <= 1`` on ``[-L, 0]``) equals the
   published DUMKA3 bound, so ``eta`` is the damping that reproduces the published length
   (degree 3 has no freedom).
2. Roots of ``R`` (colleague matrix). The complex pair nearest 0 and one real root form the
   finishing block ``Q(z) = (1 + a43 z)(1 + (a31 + a32) z + a32 a21 z^2)`` (three
   evaluations, DUMKA3's six-coefficient shape with ``a41 = a31, a42 = a32``); the real root is
   the one minimising ``max |Q|`` on the interval. ``a32`` is then fixed by the nonlinear
   order-3 condition ``sum b c^2 = 1/3`` of the composed method.
3. The other roots (all real for the 14 degrees) become forward-Euler sub-steps, ordered
   greedily so that ``max|head_k| * max|tail_k|`` (products of the factors before and after
   sub-step ``k``, the rounding-error amplification) stays small.

The result is ``dumka3_data.npz`` next to this module (see :mod:`cvtfem.integrate.dumka3`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.polynomial import chebyshev as C

DEGREES = (3, 6, 9, 15, 21, 27, 36, 48, 63, 81, 135, 189, 243, 324)
#: Published DUMKA3 real stability bounds per polynomial (Medovikov's code, as distributed in
#: the port inducer/hedge, hedge/timestep/dumka3.py, ``_STAB_REG``): figures only.
PUBLISHED_BETA = (2.5005127005, 9.784756428464169, 23.81876047528256, 68.93281712434914,
                  136.6481867305713, 226.8897061613812, 404.7232537379578, 720.7401653373073,
                  1337.12683126432, 3266.027113424224, 9072.02551332534, 17784.54409334144,
                  29376.45408008588, 50666.52463738416)
#: ``|R| <= 1 + TOL`` counts as stable (evaluation round-off of the Chebyshev sum).
TOL = 1e-9
DATA_FILE = Path(__file__).with_name("dumka3_data.npz")


def _order_rows(s: int, beta: float) -> np.ndarray:
    """Rows of ``R^(j)(0) = 1`` (j = 0..3) in the Chebyshev basis on ``[-beta, 0]``."""
    k2 = np.arange(s + 1.0) ** 2
    d = [np.ones(s + 1), k2, k2 * (k2 - 1) / 3, k2 * (k2 - 1) * (k2 - 4) / 15]
    return np.array([dj * (2 / beta) ** j for j, dj in enumerate(d)])


def minimax_polynomial(s: int, beta: float, zeta: float, grid_factor: int = 12):
    """Chebyshev coefficients of the order-3 ``R_s`` minimising ``max |R|`` on ``[-beta, -zeta]``
    with ``|R| <= 1`` on ``[-zeta, 0]``; returns ``(coefficients, t)``."""
    from scipy.optimize import linprog

    m = grid_factor * s + 200
    x = np.cos(np.pi * np.arange(m + 1) / m)
    far = beta * (x - 1) / 2 <= -zeta
    T = C.chebvander(x, s)
    col = np.where(far, -1.0, 0.0)[:, None]
    rhs = np.where(far, 0.0, 1.0)
    a_ub = np.vstack([np.hstack([T, col]), np.hstack([-T, col])])
    a_eq = np.hstack([_order_rows(s, beta), np.zeros((4, 1))])
    cost = np.zeros(s + 2)
    cost[-1] = 1.0
    res = linprog(cost, A_ub=a_ub, b_ub=np.concatenate([rhs, rhs]), A_eq=a_eq, b_eq=np.ones(4),
                  bounds=[(None, None)] * (s + 1) + [(0, None)], method="highs")
    if res.status != 0:
        raise RuntimeError(f"DUMKA3 s = {s}, beta = {beta}: LP failed ({res.message})")
    return res.x[:-1], float(res.x[-1])


def cheb_length(cheb: np.ndarray, beta: float, x_max: float) -> float:
    """Real stability length of ``R(z) = chebval(1 + 2z/beta)``: sampled on ``[0, x_max]``
    (50 s points, Chebyshev-spaced on ``[0, beta]``), first crossing of ``|R| = 1`` bisected."""
    s = len(cheb) - 1
    th = np.linspace(0.0, np.pi, 50 * s + 1)
    xs = np.concatenate([beta * (1 - np.cos(th)) / 2, np.linspace(beta, max(x_max, beta), 20 * s)])

    def r(v):
        return np.abs(C.chebval(1 - 2 * v / beta, cheb))

    bad = np.flatnonzero(r(xs) > 1 + TOL)
    if not len(bad):
        return float(xs[-1])
    lo, hi = xs[bad[0] - 1], xs[bad[0]]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if r(mid) <= 1 + TOL else (lo, mid)
    return float(lo)


def fit_polynomial(s: int, target: float):
    """``(cheb, beta, eta, zeta, length)`` whose stability length equals ``target`` (secant on
    beta); ``|R| <= 1 - eta`` on ``[-beta, -zeta]``, ``|R| <= 1`` on ``[-zeta, 0]``."""
    def run(beta):
        t, zeta = 0.9, 0.2
        for _ in range(4):   # fixed point zeta = -2 ln t (|R| <= 1 near 0, damped beyond)
            cheb, t_new = minimax_polynomial(s, beta, zeta)
            done = abs(t_new - t) < 1e-6
            t = t_new
            if done:
                break
            zeta = max(-2 * np.log(max(t, 1e-3)), 1e-3)
        return cheb, t, zeta, cheb_length(cheb, beta, 1.2 * target)

    if s == 3:   # unique: the Taylor polynomial, expressed in x = 1 + 2z/beta
        x = np.cos(np.pi * np.arange(9) / 8)
        z = target * (x - 1) / 2
        cheb = C.chebfit(x, 1 + z + z * z / 2 + z ** 3 / 6, 3)
        return cheb, target, 0.0, 0.0, cheb_length(cheb, target, 1.2 * target)
    b0, l0 = target, run(target)[3]
    b1 = target * target / l0
    c1, t1, z1, l1 = run(b1)
    for _ in range(8):   # secant on L(beta) ~ beta, steps limited to 5 %
        if abs(l1 / target - 1) < 1e-6:
            break
        step = (target - l1) * (b1 - b0) / (l1 - l0) if l1 != l0 else target - l1
        b0, l0, b1 = b1, l1, b1 + float(np.clip(step, -0.05 * b1, 0.05 * b1))
        c1, t1, z1, l1 = run(b1)
    return c1, b1, 1 - t1, z1, l1


def verified_damping(cheb: np.ndarray, beta: float, zeta: float) -> float:
    """``eta = 1 - max |R|`` on ``[-beta, -zeta]`` sampled ~80x finer than the LP grid (the LP
    bound holds only at its grid points; between them ``|R|`` overshoots it slightly)."""
    s = len(cheb) - 1
    x = np.cos(np.linspace(0.0, np.pi, 1000 * s + 2001))
    r = np.abs(C.chebval(x, cheb))
    return float(1 - r[beta * (x - 1) / 2 <= -zeta].max())


def _factors(roots: np.ndarray):
    """Real roots (ascending) and the upper members of complex pairs (by modulus)."""
    real = np.sort(roots[np.abs(roots.imag) <= 1e-9 * np.abs(roots)].real)
    cplx = roots[roots.imag > 1e-9 * np.abs(roots)]
    return real, cplx[np.argsort(np.abs(cplx))]


def _log_factor(z: np.ndarray, r, pair: bool = False) -> np.ndarray:
    """``log |1 - z/r|`` (``pair``: of ``(1 - z/r)(1 - z/conj(r))``) on the grid ``z``."""
    f = np.abs(1 - z / r)
    return np.log(np.maximum(f * f if pair else f, 1e-300))


def finishing_block(pair: complex, r3: float, sp: float, cg: float):
    """``(a21, a31, a32, a43)`` for factor ``(1 - z/r3)(1 - z/pair)(1 - z/conj(pair))`` after a
    chain with ``sum b c^2 = sp`` and total weight ``cg``, so that the whole is order 3."""
    alpha, bq, a43 = -2 * (1 / pair).real, abs(1 / pair) ** 2, -1 / r3
    defect = 1 / 3 - sp - alpha * cg ** 2 - 2 * bq * cg - a43 * (cg + alpha) ** 2
    a32 = bq * bq / defect
    return bq / a32, alpha - a32, a32, a43


def chain_moments(roots):
    """``(sum b, sum b c^2)`` of the chain of Euler sub-steps ``tau = -1/r``."""
    c = sp = 0.0
    for r in roots:
        tau = -1 / r
        sp += tau * c * c
        c += tau
    return c, sp


def order_chain(roots, tail_log, z):
    """Greedy order of ``roots`` minimising ``max log|head| + max log|tail|`` at each sub-step;
    ``tail_log`` is the log modulus of the fixed last factor. Returns the order and the bound."""
    logs = np.array([_log_factor(z, r) for r in roots])
    head = np.zeros_like(z)
    tail = logs.sum(axis=0) + tail_log
    left, out, worst = list(range(len(roots))), [], 0.0
    while left:
        cand = logs[left]
        cost = np.max(head + cand, axis=1) + np.max(tail - cand, axis=1)
        j = int(np.argmin(cost))
        worst = max(worst, float(cost[j]))
        i = left.pop(j)
        head, tail = head + logs[i], tail - logs[i]
        out.append(roots[i])
    return np.array(out), float(np.exp(worst))


def build(k: int) -> dict:
    """All data of polynomial ``k``."""
    s, target = DEGREES[k], PUBLISHED_BETA[k]
    cheb, beta, eta_lp, zeta, length = fit_polynomial(s, target)
    eta = verified_damping(cheb, beta, zeta) if eta_lp > 0 else 0.0
    real, cplx = _factors((C.chebroots(cheb) - 1) * beta / 2)
    if len(cplx) != 1:   # the finishing block holds one pair; the chain is Euler steps only
        raise RuntimeError(f"DUMKA3 s = {s}: {len(cplx)} complex pairs, the scheme expects one")
    pair = cplx[0]
    m = 8 * s + 200
    z = beta * (np.cos(np.pi * np.arange(m + 1) / m) - 1) / 2
    q_log = [_log_factor(z, r3) + _log_factor(z, pair, pair=True) for r3 in real]
    i3 = int(np.argmin([q.max() for q in q_log]))   # finishing real root: smallest max |Q|
    r3 = real[i3]
    chain = real[np.arange(len(real)) != i3]
    if len(chain):
        chain, amp = order_chain(chain, q_log[i3], z)
    else:
        amp = float(np.exp(q_log[i3].max()))
    cg, sp = chain_moments(chain)
    fin = finishing_block(pair, r3, sp, cg)
    return {"s": s, "beta": beta, "eta": eta, "eta_lp": eta_lp, "zeta": zeta, "length": length,
            "cheb": cheb, "roots": chain, "finish": np.array(fin), "amplification": amp}


def generate(out: Path = DATA_FILE, report=None) -> dict:
    """Regenerate all 14 polynomials into ``out`` (.npz, about 10 min on one core);
    ``report(k, data)`` is called after each polynomial."""
    data = {}
    for k in range(len(DEGREES)):
        d = build(k)
        data.update({f"{key}_{k}": val for key, val in d.items()})
        if report is not None:
            report(k, d)
    np.savez(out, **data)
    return data
