"""Periodic response of branched torsional networks by harmonic balance (spec section 8).

``solve_linear`` and ``solve_periodic`` (harmonic balance with the block sweep
and Newton-Kantorovich), ``continuation`` (arc-length in the frequency),
``floquet`` (stability) and ``transient.steady_state`` (the time-integration
comparison path).
"""
from __future__ import annotations

from cvtfem.periodic.hb import PeriodicSolution, solve_linear, solve_periodic

__all__ = ["PeriodicSolution", "solve_linear", "solve_periodic"]
