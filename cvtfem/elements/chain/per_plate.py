"""Whole-pin chains with per-plate plates, models A3 and A4 (spec chain-models-2 section 4).

A :class:`ChainA1` carries everything the per-plate models keep from A1 (pin inertia, pin axial
and bending energy, link twist (1.146), all pin and joint damping, twist damping); its homogenised
link extension and shear (1.141), (1.153) and their damping are switched off (zero plate stiffness and
bending stiffness in the base) and replaced by the forces of every plate of :mod:`.plates`
(section 4: "only Pi^link,ext, Pi^link,shear, Phi^link,ext, Phi^link,shear are replaced").  A4 bounds
the plate end moments by ``T h/2`` (ten contact states), A3 clamps the plates to the pins.

Plate forces come from the compiled :func:`.plates_kernel.plate_forces_kernel`, plate Jacobians (within
the current plate states) from :func:`.per_plate_kernel.plate_jacobians_kernel`, or both from the numpy
functions of :mod:`.plates` (their reference twin, ``use_numba=False``); the base adds its exact blocks.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.elements.chain import plates as P
from cvtfem.elements.chain import per_plate_kernel as PJK
from cvtfem.elements.chain import plates_kernel as PK
from cvtfem.elements.chain.asymmetric import ChainA1
from cvtfem.errors import InputError
from cvtfem.outputs import OutputSpec

MODELS = ("A3", "A4")


class ChainPerPlate:
    """Model A3 or A4 of a whole chain, vectorised over pins and plates.

    Parameters
    ----------
    model : "A4" | "A3"
        Bounded moment with the ten plate states (A4) or plates clamped to the pins (A3).
    plate_thickness : (n_links, Kmax) or scalar, m
        Plate thickness ``h`` (A4: the moment bound ``|M| <= T h/2``; unused by A3).
    drop_compressed : bool
        A3 only: plates with ``Delta <= 0`` carry nothing (default, (1.190)); otherwise they push.
    **a1 :
        The arguments of :class:`ChainA1` (same meaning): ``plate_stiffness`` ``c^k`` (N/m) and
        ``plate_bending_stiffness`` ``a^k`` (N m^2, end-moment stiffnesses ``c_1 = 4a/L``, ``c_2 = 2a/L``)
        go to the plates, ``beta_link_ext`` and ``beta_link_shear`` (s) become the plates' damping
        times (1.192)-(1.193); ``use_numba`` selects the compiled kernels of both.
    """

    def __init__(self, *, model: str = "A4", plate_thickness=1.5e-3, drop_compressed: bool = True, **a1) -> None:
        if model not in MODELS:
            raise InputError("model", model, " or ".join(MODELS))
        c_pl, a_pl = a1.pop("plate_stiffness"), a1.pop("plate_bending_stiffness")
        self.base = base = ChainA1(plate_stiffness=0.0, plate_bending_stiffness=0.0, **a1)
        shape, mask = base.plate_xi.shape, base.plate_mask
        arrays = {}
        for name, val, low in (("plate_stiffness", c_pl, 0.0), ("plate_bending_stiffness", a_pl, 0.0),
                               ("plate_thickness", plate_thickness, 0.0)):
            x = np.broadcast_to(np.asarray(val, float), shape)[mask]
            if np.any(~(x > low)):
                raise InputError(name, val, "> 0 for every plate")
            arrays[name] = x
        self.model = model
        self.drop_compressed = bool(drop_compressed)
        self.plate_link = np.nonzero(mask)[0]                 # link of each plate (row-major over (links, Kmax))
        self.n_plates = self.plate_link.size
        self.xi = base.plate_xi[mask]
        self.pitch = base.L[self.plate_link]
        self.c = arrays["plate_stiffness"]
        self.c1, self.c2 = P.bending_stiffnesses(arrays["plate_bending_stiffness"], self.pitch)
        self.h = arrays["plate_thickness"]
        self.beta_ext = float(a1.get("beta_link_ext", 0.0))
        self.beta_shear = float(a1.get("beta_link_shear", 0.0))
        d = base.dof_index
        self.plate_dofs = np.concatenate([d, d[base._next]], 1)[self.plate_link]      # (n_plates, 20)
        self._l = np.full(self.n_plates, base.l)
        self._code = PK.A4 if model == "A4" else (PK.A3_DROP if drop_compressed else PK.A3_KEEP)
        self.backend = base.backend
        self.n_pins, self.n2, self.l = base.n_pins, base.n2, base.l
        self.mass_matrix, self.jac_sparsity, self.dof_index = base.mass_matrix, base.jac_sparsity, base.dof_index

    # ------------------------------------------------------------------ layout and outputs
    @property
    def blocks(self):
        return self.base.blocks

    @property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        """A1's pin and twist outputs, the link tension as the sum of plate tensions, the plates' outputs."""
        keep = tuple(s for s in self.base.output_specs if s.name not in ("chain.link_tension", "chain.plate_tension"))
        link = OutputSpec("chain.link_tension", "N", "Link tension: sum of the plate tensions T^k of the link.",
                          self.base.n_links)
        return (link,) + P.output_specs(self.n_plates) + keep

    def outputs(self, q: np.ndarray, v: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Values of :attr:`output_specs` (elastic; ``v`` unused)."""
        out = self.base.outputs(q)
        del out["chain.plate_tension"]
        st, _, _ = self._plates_numpy(q)
        out["chain.link_tension"] = np.bincount(self.plate_link, st.tension, self.base.n_links)
        out.update(P.outputs(st, self.h))
        return out

    # ------------------------------------------------------------------ plates
    def _local(self, x: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(u1perp, u1par, u2perp, u2par)`` of every plate from a global vector (layout of ``plates.N_LOCAL``)."""
        loc = x[self.plate_dofs]
        return loc[:, :8].reshape(-1, 4, 2), loc[:, 8:10], loc[:, 10:18].reshape(-1, 4, 2), loc[:, 18:20]

    def _state(self, eps: np.ndarray) -> P.PlateState:
        if self.model == "A4":
            return P.plate_state(eps, self.c, self.c1, self.c2, self.h)
        return P.clamped_plate_state(eps, self.c, self.c1, self.c2, self.drop_compressed)

    def _plates_numpy(self, q: np.ndarray):
        """Plate states, strains and strain gradients (numpy reference)."""
        eps, J = P.plate_strains(*self._local(q), self.xi, self.l, self.pitch)
        return self._state(eps), eps, J

    def plate_forces(self, q: np.ndarray, v: np.ndarray | None) -> np.ndarray:
        """Global generalized forces of all plates (N, N m): elastic, plus damping when ``v`` is given."""
        n_pl = self.n_plates
        ql = np.ascontiguousarray(q[self.plate_dofs])
        vl = np.zeros_like(ql) if v is None else np.ascontiguousarray(v[self.plate_dofs])
        if self.backend == "numba":
            Q, T, M, state = np.empty((n_pl, 20)), np.empty(n_pl), np.empty((n_pl, 2)), np.empty(n_pl, np.int64)
            PK.plate_forces_kernel(ql, vl, self.xi, self._l, self.pitch, self.c, self.c1, self.c2, self.h,
                                   self.beta_ext, self.beta_shear, self._code, Q, T, M, state)
        else:
            st, _, J = self._plates_numpy(q)
            Q = P.plate_forces(st, J, vl, self.c, self.c1, self.c2, self.beta_ext, self.beta_shear)
        return np.bincount(self.plate_dofs.ravel(), Q.ravel(), self.n2)

    # ------------------------------------------------------------------ forces and energies
    def elastic_forces(self, q: np.ndarray) -> np.ndarray:
        """``-dPi/dq`` of pins, twist and plates."""
        return self.base.elastic_forces(q) + self.plate_forces(q, None)

    def dissipative_forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``-dPhi/dv`` of A1's remaining damping and of the plates (1.192)-(1.193)."""
        return self.base.dissipative_forces(q, v) + self.plate_forces(q, v) - self.plate_forces(q, None)

    def forces(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.base.forces(q, v) + self.plate_forces(q, v)

    def accel(self, q: np.ndarray, v: np.ndarray, q_ext: np.ndarray | None = None) -> np.ndarray:
        """``M^-1 (Q + Q_d + Q_ext)`` by the base's per-pin block solve."""
        plates = self.plate_forces(q, v)
        return self.base.accel(q, v, plates if q_ext is None else plates + q_ext)

    def kinetic_energy(self, v: np.ndarray) -> float:
        return self.base.kinetic_energy(v)

    def potential_energy(self, q: np.ndarray) -> float:
        """Pins and twist (A1) plus the plate energies (1.190)-(1.191), J."""
        st, _, _ = self._plates_numpy(q)
        return self.base.potential_energy(q) + float(st.energy.sum())

    def rayleigh(self, q: np.ndarray, v: np.ndarray) -> float:
        """A1's remaining Rayleigh terms plus the plates' (1.192)-(1.193), W."""
        st, _, J = self._plates_numpy(q)
        epsdot = np.einsum("pij,pj->pi", J, v[self.plate_dofs])
        plates = P.rayleigh(st, epsdot, self.c, self.c1, self.c2, self.beta_ext, self.beta_shear)
        return self.base.rayleigh(q, v) + float(plates.sum())

    def momentum(self, q: np.ndarray, v: np.ndarray):
        return self.base.momentum(q, v)

    # ------------------------------------------------------------------ Jacobian blocks
    def _plate_blocks(self, q: np.ndarray, v: np.ndarray | None) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``dQ/dq`` and ``dQ/dv`` of the plate forces at ``(q, v)`` (elastic only for ``v = None``), within the
        current states, summed per link: compiled (:mod:`.per_plate_kernel`) or numpy (``force_jacobians``)."""
        first = np.unique(self.plate_link, return_index=True)[1]          # plates are sorted by link
        vl = np.zeros((self.n_plates, 20)) if v is None else v[self.plate_dofs]
        if self.backend == "numba":
            n_links = self.base.n_links
            blocks = (np.zeros((n_links, 20, 20)), np.zeros((n_links, 20, 20)))
            PJK.plate_jacobians_kernel(np.ascontiguousarray(q[self.plate_dofs]), np.ascontiguousarray(vl),
                                       self.plate_link, self.xi, self._l, self.pitch, self.c, self.c1, self.c2,
                                       self.h, self.beta_ext, self.beta_shear, self._code, *blocks)
            blocks = tuple(b[self.plate_link[first]] for b in blocks)
        else:
            st, _, J = self._plates_numpy(q)
            H = P.strain_hessians(*self._local(q), self.xi, self.l, self.pitch)
            blocks = P.force_jacobians(st, J, H, vl, self.c, self.c1, self.c2, self.beta_ext, self.beta_shear)
            blocks = tuple(np.add.reduceat(b, first, axis=0) for b in blocks)
        dofs = self.plate_dofs[first]
        rows = np.repeat(dofs[:, :, None], 20, 2).ravel()
        cols = np.repeat(dofs[:, None, :], 20, 1).ravel()
        shape = (self.n2, self.n2)
        return tuple(sp.csr_matrix((b.ravel(), (rows, cols)), shape=shape) for b in blocks)

    def jacobians(self, q: np.ndarray, v: np.ndarray | None = None) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``(dQ/dq, dQ/dv)``: the base's exact elastic and damping blocks plus the plates' (which jump with a
        plate state); ``dQ/dq`` includes the plates' damping forces at ``v`` but not the base's."""
        dq, dv = self._plate_blocks(q, v)
        return (self.base.stiffness_matrix(q) + dq).tocsr(), (self.base.damping_matrix(q) + dv).tocsr()

    def stiffness_matrix(self, q: np.ndarray) -> sp.csr_matrix:
        """``dQ/dq`` of the elastic forces (within the current plate states)."""
        return self.jacobians(q)[0]

    def damping_matrix(self, q: np.ndarray) -> sp.csr_matrix:
        """``dQ/dv`` of the dissipative forces (linear in ``v``)."""
        return self.jacobians(q)[1]
