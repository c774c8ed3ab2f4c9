"""Prescribed clamping forces of the band CVT: the estimate (1.13) times a safety factor (spec section 3.1)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

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
