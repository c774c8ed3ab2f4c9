"""ODE integrator playground (spec numerics §1-7, §11): ``solve(fun, t_span, y0, method=...)``.

Methods are small compositions of a tableau, a step-size controller, an event locator and,
for implicit ones, a Newton solver with a pluggable Jacobian provider; every costly operation
is counted (:mod:`cvtfem.integrate.stats`).
"""
from cvtfem.integrate.adapter import CvtfemSolver
from cvtfem.integrate.driver import IgnoredOptionWarning, OdeResult, solve
from cvtfem.integrate.methods import METHODS, SCIPY_METHODS, register_method, unregister_method
from cvtfem.integrate.system import OdeSystem, as_system

__all__ = ["solve", "OdeResult", "OdeSystem", "as_system", "METHODS", "SCIPY_METHODS",
           "IgnoredOptionWarning", "CvtfemSolver", "register_method", "unregister_method"]
