"""Optional SLEPc backend: the quadratic eigenproblem ``(lambda^2 M + lambda D + K) x = 0`` by PEP.

Used by ``ModalProblem(method="slepc")`` when ``slepc4py`` is importable
(extra ``cvtfem[slepc]``); TOAR with shift-and-invert about a real target
``sigma`` (rad/s, below the band of interest), the same spectral
transformation as the scipy backend, so both return the same modes.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.errors import InputError, NumericalError


def available() -> bool:
    """True when slepc4py and petsc4py can be imported."""
    try:
        import petsc4py  # noqa: F401
        import slepc4py  # noqa: F401
    except ImportError:
        return False
    return True


def _petsc(A: sp.spmatrix):  # noqa: ANN202 - PETSc.Mat
    from petsc4py import PETSc

    A = sp.csr_matrix(A, dtype=PETSc.ScalarType)
    A.sort_indices()
    mat = PETSc.Mat().createAIJ(size=A.shape, csr=(A.indptr.astype(PETSc.IntType),
                                                   A.indices.astype(PETSc.IntType), A.data),
                                comm=PETSc.COMM_SELF)
    mat.assemble()
    return mat


def solve_pep(M: sp.spmatrix, K: sp.spmatrix, D: sp.spmatrix, n_eig: int, sigma: float,
              tol: float = 1e-13) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs of ``lambda^2 M + lambda D + K`` nearest to ``sigma``.

    Parameters
    ----------
    M, K, D : sparse (n, n)
        Mass, stiffness and ``C + Omega G``.
    n_eig : int
        Oscillatory modes wanted (conjugate pairs are requested as well).
    sigma : float
        Real shift, rad/s.

    Returns
    -------
    lam : complex array (k,), eigenvalues; X : complex array (n, k), eigenvectors.
    """
    if not available():
        raise InputError("method", "slepc", "needs slepc4py and petsc4py (pip install 'cvtfem[slepc]')")
    import slepc4py

    slepc4py.init()
    from petsc4py import PETSc
    from slepc4py import SLEPc

    pep = SLEPc.PEP().create(comm=PETSc.COMM_SELF)
    pep.setOperators([_petsc(K), _petsc(D), _petsc(M)])
    pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
    pep.setType(SLEPc.PEP.Type.TOAR)
    n = M.shape[0]
    nev = min(2 * n_eig + 6, 2 * n - 2)
    pep.setDimensions(nev=nev, ncv=min(2 * n, max(2 * nev, nev + 15)))
    pep.setScale(SLEPc.PEP.Scale.SCALAR)      # K and M differ by many orders of magnitude
    pep.setTarget(sigma)
    pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
    nconv = _solve_shift_invert(pep, tol, "PEP")
    xr, xi = pep.getOperators()[0].createVecs()
    lam = np.empty(nconv, dtype=complex)
    X = np.empty((M.shape[0], nconv), dtype=complex)
    for i in range(nconv):
        lam[i] = pep.getEigenpair(i, xr, xi)
        X[:, i] = xr.getArray() + 1j * xi.getArray() if np.isrealobj(xr.getArray()) else xr.getArray()
    pep.destroy()
    return lam, X


def _solve_shift_invert(solver, tol: float, kind: str) -> int:
    """Shift-invert with a direct LU, solve, and return the number of converged pairs (SLEPc PEP or EPS)."""
    from slepc4py import SLEPc

    st = solver.getST()
    st.setType(SLEPc.ST.Type.SINVERT)
    st.getKSP().setType("preonly")
    st.getKSP().getPC().setType("lu")
    solver.setTolerances(tol=tol, max_it=1000)
    solver.solve()
    nconv = solver.getConverged()
    if nconv == 0:
        raise NumericalError(f"SLEPc {kind} found no eigenpairs", component="modal.slepc")
    return nconv


def solve_gep(M: sp.spmatrix, K: sp.spmatrix, n_eig: int, sigma: float,
              tol: float = 1e-13) -> tuple[np.ndarray, np.ndarray]:
    """Undamped, gyroscope-free block: ``K x = w^2 M x`` by EPS (GHEP, shift-invert at ``-sigma^2``).

    Returns ``lambda = i w`` and real eigenvectors, like the quadratic solver (rigid modes stay simple).
    """
    if not available():
        raise InputError("method", "slepc", "needs slepc4py and petsc4py (pip install 'cvtfem[slepc]')")
    import slepc4py

    slepc4py.init()
    from petsc4py import PETSc
    from slepc4py import SLEPc

    eps = SLEPc.EPS().create(comm=PETSc.COMM_SELF)
    eps.setOperators(_petsc(K), _petsc(M))
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    n = M.shape[0]
    nev = min(n_eig + 4, n - 1)
    eps.setDimensions(nev=nev, ncv=min(n, max(2 * nev, nev + 15)))
    eps.setTarget(-sigma * sigma)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    nconv = _solve_shift_invert(eps, tol, "EPS")
    xr, xi = eps.getOperators()[0].createVecs()
    w2 = np.empty(nconv)
    X = np.empty((M.shape[0], nconv), dtype=complex)
    for i in range(nconv):
        w2[i] = eps.getEigenpair(i, xr, xi).real
        X[:, i] = xr.getArray()
    eps.destroy()
    return 1j * np.sqrt(np.clip(w2, 0.0, None)), X
