"""DUMKA3: third-order stabilized explicit method with 14 stability polynomials (spec §5, §11.6).

After Medovikov (BIT 38(2) 1998): polynomial ``Pk`` has degree ``s_k`` in
``3, 6, 9, 15, 21, 27, 36, 48, 63, 81, 135, 189, 243, 324`` and costs ``s_k`` RHS calls per
step. cvtfem does not ship Medovikov's tables: the polynomials and the scheme's coefficients
are regenerated (:mod:`cvtfem.integrate.dumka3_gen`, data in ``dumka3_data.npz``).

A step is a chain of forward-Euler sub-steps ``y += h tau F(y)`` (``tau = -1/r`` for the
real roots ``r`` of ``R_s`` but one), ordered for internal stability, then a finishing block
of three evaluations (the remaining real root and the complex pair),
``Y1 = g + h a21 F(g)``, ``Y2 = g + h (a31 F(g) + a32 F(Y1))``, ``x1 = Y2 + h a43 F(Y2)``,
whose coefficients realise the remaining cubic factor of ``R_s`` and make the composed method
order 3 for nonlinear problems (``sum b c^2 = 1/3``).

Error estimate (ours): ``err = h [(alpha - a21) F(g) - alpha F(Y1) + a21 F(Y2)] / (6 a21 beta)``
with ``alpha = a31 + a32``, ``beta = a21 a32``. It is ``O(h^3)`` for any smooth problem (the
weights satisfy ``sum d = sum d c = 0``); for ``x' = J x`` it is ``(hJ)^3 P(hJ) x / 6``,
``P = R_s / Q`` the chain's factor: the third-order Taylor term, damped like the step itself
for stiff modes. The controller treats it as the error of a second-order companion.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.polynomial import chebyshev as C

from cvtfem.errors import InputError
from cvtfem.integrate.base import Attempt, Stepper
from cvtfem.integrate.dumka3_gen import DATA_FILE, DEGREES, PUBLISHED_BETA
from cvtfem.integrate.stabilized import SpectralRadiusTracker

__all__ = ["DUMKA3", "DEGREES", "PUBLISHED_BETA", "polynomial", "stability_polynomial",
           "product_form", "stability_length", "butcher"]


@lru_cache(maxsize=1)
def _data() -> dict:
    with np.load(DATA_FILE) as z:
        return {key: z[key] for key in z.files}


@lru_cache(maxsize=None)
def polynomial(k: int) -> dict:
    """Data of polynomial ``Pk``: ``s``, ``beta`` (interval of the Chebyshev form), ``eta``
    (damping: ``|R| <= 1 - eta`` on ``[-beta, -zeta]``), ``zeta``, ``length`` (real stability
    length), ``cheb``, ``taus`` (Euler sub-steps, in order), ``finish``
    ``(a21, a31, a32, a43)``, ``amplification`` (rounding-error growth bound)."""
    if not (isinstance(k, (int, np.integer)) and 0 <= k < len(DEGREES)):
        raise InputError("polynomial", k, f"must be an integer in 0..{len(DEGREES) - 1}")
    d = {key[: -len(f"_{k}")]: v for key, v in _data().items() if key.endswith(f"_{k}")}
    return {"s": int(d["s"]), "beta": float(d["beta"]), "eta": float(d["eta"]), "zeta": float(d["zeta"]),
            "length": float(d["length"]), "cheb": d["cheb"], "taus": tuple(-1 / d["roots"]),
            "finish": tuple(float(v) for v in d["finish"]),
            "amplification": float(d["amplification"])}


def stability_polynomial(k: int, z) -> np.ndarray:
    """``R_s(z)`` of ``Pk`` from its Chebyshev form (the generator's polynomial)."""
    p = polynomial(k)
    return C.chebval(1 + 2 * np.asarray(z) / p["beta"], p["cheb"])


def product_form(k: int, z) -> np.ndarray:
    """``R_s(z)`` as the product of the stepping scheme's sub-step factors (what a step does)."""
    p = polynomial(k)
    z = np.asarray(z, dtype=complex)
    out = np.ones_like(z)
    for tau in p["taus"]:
        out = out * (1 + tau * z)
    a21, a31, a32, a43 = p["finish"]
    return out * (1 + a43 * z) * (1 + (a31 + a32) * z + a21 * a32 * z * z)


def stability_length(k: int) -> float:
    """Real stability length of ``Pk`` (largest ``L`` with ``|R| <= 1`` on ``[-L, 0]``)."""
    return polynomial(k)["length"]


def butcher(k: int):
    """Butcher tableau ``(A, b, c)`` of the composed ``s``-stage method ``Pk`` (for tests)."""
    p = polynomial(k)
    s = p["s"]
    A = np.zeros((s, s))
    w = np.zeros(s)          # the chain value y = x + h sum_j w_j k_j
    n = len(p["taus"])
    for i, tau in enumerate(p["taus"]):   # stage i is F at the chain value before sub-step i
        w[i] = tau
        A[i + 1] = w
    a21, a31, a32, a43 = p["finish"]
    A[n + 1] = w
    A[n + 1, n] += a21
    A[n + 2] = w
    A[n + 2, n] += a31
    A[n + 2, n + 1] += a32
    b = A[n + 2].copy()
    b[n + 2] += a43
    return A, b, A.sum(axis=1)


class DUMKA3(SpectralRadiusTracker, Stepper):
    """DUMKA3, order 3; ``polynomial`` (0..13) or ``stages`` (its degree) fixed, or None:
    the smallest polynomial whose real stability length covers ``h rho``."""

    name, order, error_order = "dumka3", 3, 2
    OPTIONS = frozenset({"stages", "polynomial", "spectral_radius", "rho_every"})

    def __init__(self, system, stats=None, stages: int | None = None, polynomial: int | None = None,
                 spectral_radius=None, rho_every: int = 25) -> None:
        super().__init__(system, stats)
        if stages is not None and polynomial is not None:
            raise InputError("stages", stages, "cannot be combined with `polynomial`; give one of them")
        if stages is not None:
            if stages not in DEGREES:
                raise InputError("stages", stages,
                                 f"must be one of the DUMKA3 degrees {list(DEGREES)} or None")
            polynomial = DEGREES.index(stages)
        if polynomial is not None and not (isinstance(polynomial, (int, np.integer))
                                           and 0 <= polynomial < len(DEGREES)):
            raise InputError("polynomial", polynomial, f"must be an integer in 0..{len(DEGREES) - 1} or None")
        if spectral_radius is not None and not (callable(spectral_radius) or spectral_radius > 0):
            raise InputError("spectral_radius", spectral_radius,
                             "must be a positive number, a callable or None")
        self.fixed = None if polynomial is None else int(polynomial)
        self._init_rho(spectral_radius, rho_every)
        self.stages = DEGREES[self.fixed or 0]

    def _choose(self, t, x, f0, h) -> int:
        if self.fixed is not None:
            return self.fixed
        hr = h * self._current_rho(t, x, f0)
        for k in range(len(DEGREES)):
            if stability_length(k) >= hr:
                return k
        return len(DEGREES) - 1

    def max_step(self) -> float:
        """The longest polynomial's (or the fixed one's) real stability length over the last spectral-radius
        estimate, s: longer steps would leave every region and only be rejected by the error estimate."""
        return self._step_cap(stability_length(len(DEGREES) - 1 if self.fixed is None else self.fixed))

    def attempt(self, t, x, h):
        f0 = self.f0(t, x)
        p = polynomial(self._choose(t, x, f0, h))
        self.stages = p["s"]
        y, c, fy = x, 0.0, f0
        for tau in p["taus"]:
            y = y + (h * tau) * fy
            c += tau
            fy = self.f(t + c * h, y)
        a21, a31, a32, a43 = p["finish"]
        alpha = a31 + a32
        k1 = self.f(t + (c + a21) * h, y + (h * a21) * fy)
        y2 = y + h * (a31 * fy + a32 * k1)
        k2 = self.f(t + (c + alpha) * h, y2)
        x1 = y2 + (h * a43) * k2
        err = None
        if self.need_error:
            err = (h / (6 * a21 * a21 * a32)) * ((alpha - a21) * fy - alpha * k1 + a21 * k2)
        return Attempt(t, x, h, x1, err, f0)
