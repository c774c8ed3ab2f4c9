"""Column colouring for sparse difference Jacobians."""
import numpy as np
import scipy.sparse as sp

from cvtfem.assembly.colouring import color_columns


def test_columns_sharing_many_rows_never_share_a_colour():
    """Two dense columns that share 256 (and 512) rows, next to a diagonal: the shared-row count must not wrap
    around in a small integer type, which gave both dense columns the same colour."""
    for shared in (255, 256, 512):
        n = shared + 3
        dense = np.zeros((n, 2), bool)
        dense[:shared] = True
        pattern = sp.hstack([sp.identity(n, dtype=bool, format="csc"), sp.csc_matrix(dense)]).tocsc()
        colors = color_columns(pattern)
        S = pattern.toarray()
        for c in np.unique(colors):
            cols = np.flatnonzero(colors == c)
            assert S[:, cols].sum(axis=1).max() <= 1, (shared, cols)     # columns of a colour never overlap
