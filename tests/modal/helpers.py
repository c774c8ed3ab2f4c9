"""Test models built directly from element families (no scenes)."""
import numpy as np
import scipy.sparse as sp

from cvtfem.assembly import assemble
from cvtfem.elements.beam import BeamFamily, BeamOptions

STEEL = dict(E=2.11e11, G=8.12e10, rho=7810.0)


def uniform_shaft(n, length, Do, Di=0.0, **opts):
    """Assembled (M, K, G, kind) of a uniform shaft of n elements, all 6 DOF per node."""
    b = BeamFamily(nodes=np.stack([np.arange(n), np.arange(1, n + 1)], 1), L=np.full(n, length / n),
                   Do=np.full(n, Do), Di=np.full(n, Di), E=np.full(n, STEEL["E"]), G=np.full(n, STEEL["G"]),
                   rho=np.full(n, STEEL["rho"]), options=BeamOptions(**opts))
    N = 6 * (n + 1)
    M = assemble(N, [(b.mass(), b.dofs)])
    K = assemble(N, [(b.stiffness(), b.dofs)])
    G = assemble(N, [(b.gyroscopic(), b.dofs)])
    return b, M, K, G, np.tile(np.arange(6), n + 1)


def restrict(keep, *mats):
    """Sub-matrices on the kept DOFs (constraint by elimination)."""
    return [sp.csr_matrix(X)[keep][:, keep] for X in mats]


def simply_supported_lateral(n, length, Do, Di=0.0, **opts):
    """Lateral DOFs only, u1 = u2 = 0 at both ends: (M, K, G, kind, beam)."""
    b, M, K, G, kind = uniform_shaft(n, length, Do, Di, **opts)
    node = np.repeat(np.arange(n + 1), 6)
    lateral = np.isin(kind, [0, 1, 3, 4])
    pinned = np.isin(kind, [0, 1]) & ((node == 0) | (node == n))
    keep = np.flatnonzero(lateral & ~pinned)
    M, K, G = restrict(keep, M, K, G)
    return M, K, G, kind[keep], b
