"""Step-to-step memory of a method as named float arrays of fixed sizes (for checkpoints).

A method's memory is a ``dict`` of 1-D float arrays whose sizes are known before the run
(:meth:`fields`), so a checkpoint file can reserve them. ``NaN`` everywhere means "unknown"
(``None``). Matrices go through :class:`MatrixSlot`: dense ``n*n`` without a sparsity pattern,
else compressed (data, indices, indptr), sized by the pattern's non-zeros plus the diagonal.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

__all__ = ["MatrixSlot", "scalar", "vector", "opt_scalar", "opt_vector"]

_FORMATS = ("dense", "csr", "csc")


def scalar(v) -> np.ndarray:
    """``[v]`` (NaN for None)."""
    return np.array([np.nan if v is None else float(v)])


def vector(v, n: int) -> np.ndarray:
    """``v`` as (n,) floats (NaN for None)."""
    return np.full(n, np.nan) if v is None else np.asarray(v, dtype=float).ravel()


def opt_scalar(a: np.ndarray) -> float | None:
    """Inverse of :func:`scalar`."""
    return None if np.isnan(a[0]) else float(a[0])


def opt_vector(a: np.ndarray) -> np.ndarray | None:
    """Inverse of :func:`vector` (a copy)."""
    return None if np.all(np.isnan(a)) else np.array(a, dtype=float)


@dataclass(frozen=True)
class MatrixSlot:
    """An (n, n) matrix in the memory: ``name`` dense (``nnz`` None) or ``name.data/.indices/.indptr/.format``
    with room for ``nnz`` stored entries; ``complex`` adds the imaginary parts (``name.imag`` or ``name.data_imag``)."""

    name: str
    n: int
    nnz: int | None = None
    complex: bool = False

    @classmethod
    def for_pattern(cls, name: str, n: int, pattern, complex: bool = False) -> MatrixSlot:
        """Dense without ``pattern``, else room for the pattern plus the diagonal (``c I - J``)."""
        return cls(name, n, None if pattern is None else int(sp.csr_matrix(pattern).nnz) + n, complex)

    def fields(self) -> tuple[tuple[str, int], ...]:
        n, k = self.n, self.name
        if self.nnz is None:
            return ((k, n * n),) + (((f"{k}.imag", n * n),) if self.complex else ())
        return ((f"{k}.data", self.nnz),) + (((f"{k}.data_imag", self.nnz),) if self.complex else ()) + (
            (f"{k}.indices", self.nnz), (f"{k}.indptr", n + 1), (f"{k}.format", 1))

    def pack(self, M) -> dict[str, np.ndarray]:
        """``M`` (ndarray, CSR/CSC or None) as this slot's fields."""
        out = {name: np.full(size, np.nan) for name, size in self.fields()}
        if M is None:
            return out
        k = self.name
        if self.nnz is None:
            D = M.toarray() if sp.issparse(M) else np.asarray(M)
            out[k] = np.array(D.real, dtype=float).ravel()
            if self.complex:
                out[f"{k}.imag"] = np.array(D.imag, dtype=float).ravel()
            return out
        fmt = M.format if sp.issparse(M) else "dense"
        S = M if fmt in ("csr", "csc") else sp.csr_matrix(M)
        if S.nnz > self.nnz:
            raise ValueError(f"matrix {k!r} has {S.nnz} stored entries, more than its sparsity pattern allows "
                             f"({self.nnz}); pass the structural pattern as jac_sparsity")
        out[f"{k}.data"][:S.nnz] = S.data.real
        if self.complex:
            out[f"{k}.data_imag"][:S.nnz] = S.data.imag
        out[f"{k}.indices"][:S.nnz] = S.indices
        out[f"{k}.indptr"][:] = S.indptr
        out[f"{k}.format"][0] = _FORMATS.index(fmt if fmt in _FORMATS else "csr")
        return out

    def unpack(self, d):
        """The matrix stored by :meth:`pack` (None if it was None)."""
        k, n = self.name, self.n
        if self.nnz is None:
            if np.all(np.isnan(d[k])):
                return None
            D = d[k].reshape(n, n)
            return D + 1j * d[f"{k}.imag"].reshape(n, n) if self.complex else D.copy()
        if np.isnan(d[f"{k}.format"][0]):
            return None
        indptr = d[f"{k}.indptr"].astype(np.int32)
        nnz = int(indptr[-1])
        data = d[f"{k}.data"][:nnz].copy()
        if self.complex:
            data = data + 1j * d[f"{k}.data_imag"][:nnz]
        indices = d[f"{k}.indices"][:nnz].astype(np.int32)
        fmt = _FORMATS[int(d[f"{k}.format"][0])]
        if fmt == "csc":
            return sp.csc_matrix((data, indices, indptr), shape=(n, n))
        S = sp.csr_matrix((data, indices, indptr), shape=(n, n))
        return S.toarray() if fmt == "dense" else S
