"""Eigen-analysis of linear rotors (``M q'' + (C + Omega G) q' + K q = 0``) and Campbell diagrams."""
from cvtfem.modal.campbell import Campbell, campbell, chain_orders, shaft_orders
from cvtfem.modal.eigen import ModalProblem, Modes, solve_modes
from cvtfem.modal.whirl import mac

__all__ = ["Campbell", "ModalProblem", "Modes", "campbell", "chain_orders", "mac", "shaft_orders",
           "solve_modes"]
