"""H2 contact at an end of an independent pin half (model A5, variant (e); contact digest §5.5 "independent
halves", eq. (1.352)): the refined pin–sheave kernel of
:class:`~cvtfem.elements.chain.sheave_contact_refined.RefinedSheaveContact` at the end of the half's own axis,
whose spin is the direction of the one link that carries the half.

Half ``p-`` carries the plates of link ``(p, p+1)`` and turns with its chord ``u+_{p+1,0} - u-_{p,0}``; half
``p+`` those of ``(p-1, p)`` with ``u+_{p,0} - u-_{p-1,0}`` (chain-models-2 §5.1, (1.215)).  The face is the
crowned face of the kernel (radius ``R_f`` in both directions), so the fixed turn ``gamma_0`` of the half's
section axes does not change it, and the contact point sits on the half's own axis end (``H = 0``).  The
kernel reads the spin from the bisector of two unit chords at the end; both are given the half's link chord
``c``: its rear neighbour at ``x - c`` and its front neighbour at ``x + c`` (``x`` the half end).  The bisector is
then the unit chord, the spin rate ``n . c' / |c|``, and the kernel's twist forces ``Q_rear``, ``Q_front`` act on
``c`` as ``Q_front - Q_rear``, which is (1.352): the twist moment over ``|c|`` on the two halves of the link.
The map is linear, so the kernel's properties carry over exactly: the normal forces are the gradient of its
Hertz potential and its friction power is the work rate of the generalized forces.

Local inputs per contact: the half end ``x`` (2, in-plane), the link chord ``c`` (2), ``u3`` (the end's axial
position), the end slope (2), ``z_k``, the same rates and the shaft spin rate (17); outputs the forces on the
same positions, on ``phi_k`` and the friction power (10), in the kernel's units (SI) and mirror convention.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cvtfem.elements.chain.pair_geometry import PairGeometry
from cvtfem.elements.chain.sheave_contact import central_local_jacobian
from cvtfem.elements.chain.sheave_contact_refined import RefinedSheaveContact
from cvtfem.elements.jit import njit
from cvtfem.errors import InputError

#: Position inputs: half end (2), link chord (2), ``u3``, end slope (2), ``z``.
N_POS = 8


@njit(cache=True)
def _spread(X, Xk, n_pos_kernel):
    """Compiled :meth:`HalfEndContact.kernel_inputs` into ``Xk`` (m, 2 n_pos_kernel + 1)."""
    for i in range(X.shape[0]):
        for a in range(2):
            off, ko = a * N_POS, a * n_pos_kernel
            for j in range(2):
                x, c = X[i, off + j], X[i, off + 2 + j]
                Xk[i, ko + j] = x - c
                Xk[i, ko + 2 + j] = x
                Xk[i, ko + 4 + j] = x + c
            for j in range(4):
                Xk[i, ko + 6 + j] = X[i, off + 4 + j]
        Xk[i, Xk.shape[1] - 1] = X[i, X.shape[1] - 1]


@njit(cache=True)
def _gather(Yk, Y):
    """Compiled back map of :meth:`HalfEndContact.local` into ``Y`` (m, 10)."""
    for i in range(Yk.shape[0]):
        for j in range(2):
            Y[i, j] = Yk[i, j] + Yk[i, 2 + j] + Yk[i, 4 + j]
            Y[i, 2 + j] = Yk[i, 4 + j] - Yk[i, j]
        for j in range(Y.shape[1] - 4):
            Y[i, 4 + j] = Yk[i, 6 + j]


@dataclass(frozen=True)
class HalfEndContact(PairGeometry):
    """H2 contact of the ends of independent pin halves (A5) with the sheaves of two shafts, mirrored pair.

    Attributes
    ----------
    pair : RefinedSheaveContact
        The kernel (with slopes: the half's end slope; ``c`` the Hertz constant of one half end).
    """

    pair: RefinedSheaveContact

    def __post_init__(self):
        if not self.pair.slopes:
            raise InputError("HalfEndContact.pair.slopes", False, "must be true: a half end has a slope (A5 bends)")

    @property
    def n_pos(self) -> int:
        return N_POS

    @property
    def n_in(self) -> int:
        """Positions, their rates, the shaft spin rate."""
        return 2 * N_POS + 1

    @property
    def n_out(self) -> int:
        """Forces on the positions, on ``phi_k``, friction power."""
        return N_POS + 2

    def extra_approach(self, k: int, r):
        return self.pair.extra_approach(k, r)

    def kernel_inputs(self, X):
        """The kernel's inputs (m, 21): neighbours ``x -+ c`` around the end ``x`` (positions and rates)."""
        n = N_POS
        Xk = np.empty((len(X), self.pair.n_in))
        for off, ko in ((0, 0), (n, self.pair.n_pos)):
            x, c = X[:, off:off + 2], X[:, off + 2:off + 4]
            Xk[:, ko:ko + 2] = x - c
            Xk[:, ko + 2:ko + 4] = x
            Xk[:, ko + 4:ko + 6] = x + c
            Xk[:, ko + 6:ko + 10] = X[:, off + 4:off + 8]
        Xk[:, -1] = X[:, -1]
        return Xk

    def local(self, X, shafts, details: bool = False, reference: bool = False):
        """Outputs ``Y`` (m, 10): the kernel's forces mapped back by the transpose of :meth:`kernel_inputs`
        (end: the sum of the three; chord: front minus rear), the rest as the kernel's (``details`` too).
        Without ``details`` or ``reference`` the map and the kernel run compiled; else the numpy twins."""
        if not (details or reference):
            X = np.ascontiguousarray(X, float)
            Xk = np.empty((len(X), self.pair.n_in))
            _spread(X, Xk, self.pair.n_pos)
            Y = np.empty((len(X), self.n_out))
            _gather(self.pair.local(Xk, shafts), Y)
            return Y
        out = self.pair.local(self.kernel_inputs(X), shafts, details, reference)
        Yk = out[0] if details else out
        Y = np.empty((len(X), self.n_out))
        Y[:, 0:2] = Yk[:, 0:2] + Yk[:, 2:4] + Yk[:, 4:6]
        Y[:, 2:4] = Yk[:, 4:6] - Yk[:, 0:2]
        Y[:, 4:] = Yk[:, 6:]
        return (Y, out[1]) if details else Y

    def local_jacobian(self, X, shafts):
        """``dY/dX`` (m, n_out, n_in) by central differences (steps as the kernel's)."""
        scale = np.full(self.n_in, 1e-6)
        scale[:N_POS] = 1e-9
        scale[-1] = 1e-5
        return central_local_jacobian(self.local, X, shafts, scale, self.n_out)
