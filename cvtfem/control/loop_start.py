"""Start value ``F11(0)`` of the ratio loop's integral: at zero (the source) or at the chain's own clamping ratio.

Spec: low-order digest section 5.3 sets ``F11(0) = 0``, so the driving clamping force starts at the prescribed
``F1a`` of the estimate (1.13) (the ``equilibrium`` split: the band's force ratio, 0.8335 at the stationary regime).
A discrete chain runs at the target ratio at another force ratio (its pins give axially under load and run in a
spiral along the driving arc: S1 needs F1/F2 = 1.00, S2 1.094, A1 with H2 ~0.9-1.3; docs/chain.md and transmission.md),
and the integral (``c_f1`` ~1e6 N/s per unit ratio error) takes 0.3-0.5 s of simulated time to move ``F1`` there.
Starting the integral at ``F11(0) = rho F2a - F1a``, the loop's equilibrium at zero ratio error, puts ``F1`` at
``rho F2a`` from the first step; ``rho`` is measured by open-loop runs at held forces
(``studies/chain/clamping_ratio_variant.py``: the F1/F2 whose settled speed ratio is the target).
"""
from __future__ import annotations

from cvtfem.errors import InputError

#: How ``F11(0)`` is set (scene key ``cvt.control.ratio_loop_start``).
START_MODES = ("zero", "force-ratio")


def integral_start(mode: str, force_ratio: float, F_appl, k_sat: float) -> float:
    """``F11(0)``, N: 0 for ``"zero"``; for ``"force-ratio"`` the offset that starts the driving clamping force at
    ``force_ratio`` times the driven one, ``force_ratio F2a - F1a``.

    ``F_appl`` (2,) N are the prescribed forces at ``t = 0``; the seeded ``F1`` must lie inside the loop's saturation
    band ``[F1a / k_sat, k_sat F1a]`` (else the loop would clip it at once), an :class:`InputError` naming
    ``cvt.control.start_force_ratio`` otherwise.
    """
    if mode not in START_MODES:
        raise InputError("cvt.control.ratio_loop_start", mode, "must be one of " + ", ".join(START_MODES))
    if mode == "zero":
        return 0.0
    F1a, F2a = float(F_appl[0]), float(F_appl[1])
    lo, hi = F1a / k_sat / F2a, k_sat * F1a / F2a
    if not lo <= force_ratio <= hi:
        raise InputError("cvt.control.start_force_ratio", force_ratio,
                         f"must lie within the ratio loop's saturation band {lo:.4g} .. {hi:.4g} (F1 within "
                         f"[F1a / k_sat, k_sat F1a] = [{F1a / k_sat:.0f}, {k_sat * F1a:.0f}] N for F2 = {F2a:.0f} N)")
    return force_ratio * F2a - F1a
