"""Sparse global matrices from vectorised element blocks.

An element family supplies its local matrices as one array ``(n_elem, nd, nd)``
and its DOF map as ``(n_elem, nd)`` integer array of global indices; the whole
family becomes COO triplets and CSR in one call (duplicates are summed).
Nothing here knows what the DOFs mean.
"""
from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import scipy.sparse as sp


def dof_map_nodes(nodes: np.ndarray, dofs_per_node: int) -> np.ndarray:
    """DOF map of elements whose DOFs are whole nodes.

    Parameters
    ----------
    nodes : int array, shape (n_elem, n_nodes_per_elem)
        Global node numbers of each element.
    dofs_per_node : int
        DOFs per node (node ``i`` owns ``i*dofs_per_node ... + dofs_per_node-1``).

    Returns
    -------
    int array, shape (n_elem, n_nodes_per_elem * dofs_per_node)

    Examples
    --------
    >>> dof_map_nodes(np.array([[0, 1]]), 2).tolist()
    [[0, 1, 2, 3]]
    """
    nodes = np.asarray(nodes, dtype=np.int64)
    local = np.arange(dofs_per_node, dtype=np.int64)
    return (nodes[:, :, None] * dofs_per_node + local).reshape(nodes.shape[0], -1)


def expand_blocks(blocks: np.ndarray, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """COO triplets ``(rows, cols, values)`` of a family of element blocks.

    Parameters
    ----------
    blocks : array, shape (n_elem, nd, nd)
    dofs : int array, shape (n_elem, nd)
    """
    blocks = np.asarray(blocks)
    dofs = np.asarray(dofs, dtype=np.int64)
    nd = dofs.shape[1]
    rows = np.broadcast_to(dofs[:, :, None], (dofs.shape[0], nd, nd))
    cols = np.broadcast_to(dofs[:, None, :], (dofs.shape[0], nd, nd))
    return rows.ravel(), cols.ravel(), blocks.ravel()


def assemble(n: int, families: Iterable[tuple[np.ndarray, np.ndarray]]) -> sp.csr_matrix:
    """Sum element families into one ``n x n`` CSR matrix.

    Parameters
    ----------
    n : int
        Number of global DOFs.
    families : iterable of (blocks, dofs)
        ``blocks`` of shape (n_elem, nd, nd) and ``dofs`` of shape (n_elem, nd);
        a family with ``n_elem = 0`` contributes nothing.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
        Duplicates summed, explicit zeros removed.

    Examples
    --------
    >>> k = np.array([[[1.0, -1.0], [-1.0, 1.0]]] * 2)
    >>> assemble(3, [(k, np.array([[0, 1], [1, 2]]))]).toarray().tolist()
    [[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]
    """
    parts = [expand_blocks(b, d) for b, d in families if np.asarray(d).size]
    if not parts:
        return sp.csr_matrix((n, n))
    rows, cols, vals = (np.concatenate(x) for x in zip(*parts))
    dtype = np.result_type(*[p[2].dtype for p in parts])
    out = sp.coo_matrix((vals.astype(dtype, copy=False), (rows, cols)), shape=(n, n)).tocsr()
    out.eliminate_zeros()
    return out
