"""Jacobian providers (spec §11.3): analytic, graph-coloured finite differences, dense FD.

The colouring and the coloured difference are assembly's (:mod:`cvtfem.assembly.colouring`);
this module counts their right-hand-side calls for the stepper. For second-order systems the ``u' = v`` rows ``[0 I 0]`` are set analytically.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly.colouring import color_columns, coloured_difference
from cvtfem.integrate.linsolve import DENSE_MAX

__all__ = ["JacobianProvider"]


class JacobianProvider:
    """Computes ``J = dF/dx`` at ``(t, x)`` as CSR: analytic, coloured FD or dense FD.

    Counts ``njev``, and ``nfev_jac`` (also added to ``nfev``) for the RHS calls it makes.
    """

    def __init__(self, stepper) -> None:
        self.stepper = stepper
        system = stepper.system
        self.n, self.n2 = system.n, system.n2
        self.analytic = system.jac
        self.colors = None
        self.pattern = None
        if self.analytic is None:
            pattern = system.jac_sparsity
            if pattern is None:
                pattern = sp.csr_matrix(np.ones((self.n, self.n), dtype=bool))
            pattern = sp.csr_matrix(pattern, dtype=bool)
            n2 = self.n2
            if n2:  # rows u' = v are known: difference only the F_v, F_z rows
                pattern = sp.vstack([sp.csr_matrix((n2, self.n), dtype=bool), pattern[n2:]]).tocsr()
            self.pattern = pattern.tocoo()
            self.colors = color_columns(pattern)
        self.n_colors = None if self.colors is None else int(self.colors.max()) + 1

    def __call__(self, t: float, x: np.ndarray):
        """``J`` as an ndarray (``n <= DENSE_MAX``) or CSR matrix."""
        st = self.stepper.stats
        st.counts["njev"] += 1
        with st.timer("t_jac"):
            J = self.analytic(t, x) if self.analytic is not None else self._fd(t, x)
        if self.n <= DENSE_MAX:
            return J.toarray() if sp.issparse(J) else np.array(J, dtype=float)
        return sp.csr_matrix(J)

    def _fd(self, t, x):
        f = self.stepper.f
        st = self.stepper.stats
        f0 = f(t, x)
        saved = self.stepper._cache

        def counted(t, xp):
            st.counts["nfev_jac"] += 1
            return f(t, xp)

        J = coloured_difference(counted, t, x, f0, self.pattern, self.colors)
        self.stepper._cache = saved
        if self.n2:
            n2 = self.n2
            J = J + sp.csr_matrix((np.ones(n2), (np.arange(n2), np.arange(n2, 2 * n2))), shape=J.shape)
        return J
