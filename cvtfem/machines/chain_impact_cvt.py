"""The S2 chain on two rigid shafts with impact at contact onset: :class:`ImpactChainCVT` (``effects.contact =
"impact"``), the transmission of :class:`~cvtfem.machines.chain_cvt.ChainCVT` whose pin ends hit the sheaves.

A pin end entering a sheave (its penetration ``Delta`` rising through zero) is an event of the model protocol
(:meth:`ImpactChainCVT.events`, one indicator per pin and shaft); at the event :meth:`ImpactChainCVT.switch` applies
the C2 impulse (contact-models digest §3: perfectly inelastic normal, Coulomb tangential with the stick check, through
the model's own mass matrix and contact map, :mod:`cvtfem.elements.chain.pin_impact`) to the velocities of the pin,
the sheave pair and the shaft.  The contact then carries on as H1 (Hertz at the pin-axis end, regularised friction),
which starts at zero force and now at zero normal approach speed: the impact takes the kinetic energy a Hertz spring
alone would bounce back.  S1 has no axial inertia, so no impact (chain-models-1 §2.1): this model is S2's.

State: :class:`ChainCVT`'s with two first-order blocks before the work integrals: ``contact.state`` (2n, pin-major,
driving then driven) the discrete state of each pin end, 0 free, 1 in contact after a sliding impact (or present at
the start), 2 in contact after a stuck impact; and ``contact.impact_loss`` (J) the kinetic energy the impacts took,
which is also added to the dissipated work so that the work integrals close the energy balance across the jumps.
Both have zero rate; they change only at events, and checkpoints carry them with the state.
"""
from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly.model import StateLayout
from cvtfem.elements.base import Block
from cvtfem.elements.chain.pin_impact import (end_geometry, gap_indicators, impact_energy_change, pin_end_impulses,
                                              relative_velocity_map)
from cvtfem.elements.contact.impact import FREE, SLIDING
from cvtfem.machines.chain_cvt import ChainCVT
from cvtfem.outputs import OutputSpec


#: Offset (m) of the indicator of an end in contact: far above the round-off of ``Delta`` (~1e-17 m), far below the
#: Hertz penetrations (~1e-5 m); the release fires this far off the face, where H1 carries no force already.
HYSTERESIS = 1e-10


class ImpactChainCVT(ChainCVT):
    """chain-S2 + H1 contact with C2 impacts at contact onset + two rigid shafts + regime + loops."""

    # ----- layout -------------------------------------------------------------------------------
    @property
    def n_discrete(self) -> int:
        """Discrete contact states: one per pin end and shaft."""
        return 2 * self.n_ends

    @cached_property
    def layout(self) -> StateLayout:
        blocks = super().layout.blocks
        return StateLayout(blocks[:-1] + (Block("contact.state", self.n_discrete, "-", order=1),
                                          Block("contact.impact_loss", 1, "J", order=1), blocks[-1]))

    @cached_property
    def _discrete(self) -> slice:
        """State slice of ``contact.state`` and ``contact.impact_loss``."""
        start = 2 * self.n2 + self.control.size
        return slice(start, start + self.n_discrete + 1)

    def split(self, x):
        """Views ``q, v, z_control, W`` of a state vector (the discrete block between the last two)."""
        n, nz = self.n2, self.control.size
        return x[:n], x[n:2 * n], x[2 * n:2 * n + nz], x[self._discrete.stop:]

    def discrete_state(self, x) -> tuple[np.ndarray, float]:
        """``(state (2n,), impact loss J)`` of a state vector."""
        d = x[self._discrete]
        return d[:-1], float(d[-1])

    def state_label(self, i: int) -> str:
        i, d = int(i), self._discrete
        if d.start <= i < d.stop - 1:
            j = i - d.start
            return f"pin {j // 2}, contact state with the {('driving', 'driven')[j % 2]} sheave"
        if i == d.stop - 1:
            return "contact.impact_loss"
        return super().state_label(i if i < d.start else i - self.n_discrete - 1)

    def _with_discrete(self, x_base) -> np.ndarray:
        """A state of :class:`ChainCVT`'s layout with the discrete block inserted: ends in contact (``Delta > 0``) in
        state 1, no loss so far."""
        x_base = np.asarray(x_base, float)
        cut = self._discrete.start
        x = np.concatenate([x_base[:cut], np.zeros(self.n_discrete + 1), x_base[cut:]])
        x[cut:cut + self.n_discrete] = np.where(self.events(0.0, x) > 0, SLIDING, FREE)
        return x

    def _static(self, ratio: float, w1: float, F2: float, tol: float):
        x0, report = super()._static(ratio, w1, F2, tol)
        return self._with_discrete(x0), report

    # ----- right-hand side and Jacobian ----------------------------------------------------------
    def evaluate(self, t: float, x, slip: bool = True):
        dx, diag = super().evaluate(t, x, slip)
        cut = self._discrete.start
        return np.concatenate([dx[:cut], np.zeros(self.n_discrete + 1), dx[cut:]]), diag

    def _zero_rows(self, J) -> sp.csr_matrix:
        """``J`` with the (zero) rows of the discrete block inserted."""
        cut = self._discrete.start
        J = sp.csr_matrix(J)
        return sp.vstack([J[:cut], sp.csr_matrix((self.n_discrete + 1, J.shape[1])), J[cut:]], format="csr")

    def jac(self, t: float, x) -> sp.csr_matrix:
        return self._zero_rows(super().jac(t, x))

    @cached_property
    def jac_sparsity(self) -> sp.csr_matrix:
        return self._zero_rows(super().jac_sparsity.astype(float)).astype(bool)

    # ----- events and the discrete state -------------------------------------------------------------
    def events(self, t: float, x) -> np.ndarray:
        """Penetration ``Delta`` (2n,) m of every pin end against each shaft's sheave (pin-major), plus
        :data:`HYSTERESIS` for the ends in contact: a free end's rise through zero is a contact onset (impact), an
        end in contact is released where ``Delta`` falls below ``-HYSTERESIS``.  Without the offset an end left at
        ``Delta = 0`` by its impact would cross zero again in round-off and be hit again and again (Zeno)."""
        q = x[:self.n2]
        nc, _, iz, _ = self._idx
        u3 = self.family.split(q[:nc])[1]
        e = gap_indicators(self.contact, self.pin_positions(q[:nc]), u3, q[iz]).ravel()
        return e + HYSTERESIS * (x[self._discrete.start:self._discrete.stop - 1] != FREE)

    @cached_property
    def event_direction(self) -> np.ndarray:
        return np.zeros(self.n_discrete, int)

    @cached_property
    def event_terminal(self) -> np.ndarray:
        return np.zeros(self.n_discrete, bool)

    def switch(self, t: float, x, fired) -> np.ndarray:
        """The state after the events ``fired`` (2n,) bool at ``(t, x)``: each end that approaches its sheave
        (``n . w < 0``) gets its impact (one after the other, with the velocities the previous left), the others are
        released; the impacts' kinetic energy goes to ``contact.impact_loss`` and to the dissipated work.  An end the
        flow pulls off the face right after its impact (touch and leave: ``Delta'' < 0`` at zero approach speed, which
        the event locator does not see as a crossing) is free again."""
        x = np.array(x, float)
        ends = np.flatnonzero(fired)
        for j in ends:
            x = self.impact(x, np.array([j // 2]), np.array([j % 2]))[0]
        hit = ends[x[self._discrete.start + ends] != FREE]
        if len(hit):
            leaving = self._gap_curvature(t, x)[hit] < 0
            x[self._discrete.start + hit[leaving]] = FREE
        return x

    def _gap_curvature(self, t: float, x, dt: float = 1e-9) -> np.ndarray:
        """``Delta''`` (2n,) m/s^2 estimated from two explicit steps of ``dt`` s (the positions move by ``2 dt v + dt^2
        a``): its sign says where an end at zero approach speed goes next."""
        x1 = x + dt * self.rhs(t, x)
        x2 = x1 + dt * self.rhs(t + dt, x1)
        return (self.events(t, x2) - 2 * self.events(t, x1) + self.events(t, x)) / dt ** 2

    def impact_map(self, x, end: int, shaft: int):
        """``(w (3,), normal (3,), G (3, n2), MinvGt (n2, 3))`` of pin end ``end`` on ``shaft``: relative velocity,
        outward normal, ``w = G v`` and ``M^-1 G^T`` of the model's mass matrix."""
        q, v = x[:self.n2], x[self.n2:2 * self.n2]
        cols, coef = self._contact_map(np.array([end]), np.array([shaft]))
        X = (coef * np.concatenate([q, v, self._constants])[cols]).sum(axis=2)
        arm, normal = end_geometry(self.contact, X, np.array([shaft]))
        B = relative_velocity_map(arm)[0]
        C = np.zeros((5, self.n2))                            # local velocity inputs from v
        vc, vw = cols[0, 4:9] - self.n2, coef[0, 4:9]
        inside = (vc >= 0) & (vc < self.n2)                    # constants act on nothing
        np.add.at(C, (np.nonzero(inside)[0], vc[inside]), vw[inside])
        G = B @ C
        MinvGt = np.column_stack([self.solve_mass(G[i]) for i in range(3)])
        return G @ v, normal[0], G, MinvGt

    def impact(self, x, ends, shafts):
        """The state after the impacts of ``ends`` on ``shafts`` (applied in order) and per impact ``(P (3,) N s,
        state, energy change J, w- (3,), w+ (3,))``."""
        x = np.array(x, float)
        d0, n2 = self._discrete.start, self.n2
        log = []
        for end, shaft in zip(ends, shafts):
            w, normal, G, MinvGt = self.impact_map(x, int(end), int(shaft))
            A = 2 * G @ MinvGt
            P, state = pin_end_impulses(w[None], normal[None], A[None], self.contact.f0)
            P, state = P[0], int(state[0])
            x[n2:2 * n2] += 2 * MinvGt @ P
            w_after = G @ x[n2:2 * n2]
            dT = float(impact_energy_change(P, w, w_after))
            x[d0 + 2 * end + shaft] = state
            x[self._discrete.stop - 1] -= dT
            x[-2] -= dT                                        # the dissipated work
            log.append((P, state, dT, w, w_after))
        return x, log

    # ----- outputs -----------------------------------------------------------------------------------
    @cached_property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        return super().output_specs + (
            OutputSpec("contact.state", "-", "Discrete state of each pin end and shaft (pin-major, driving then "
                       "driven): 0 free, 1 in contact after a sliding impact (or at the start), 2 after a stuck "
                       "impact.",
                       self.n_discrete),
            OutputSpec("contact.impact_loss", "J", "Kinetic energy taken by the impacts at contact onset since t = 0 "
                       "(included in the dissipated work)."))

    def _more_outputs(self, x):
        state, loss = self.discrete_state(x)
        return {"contact.state": state.copy(), "contact.impact_loss": loss}


def from_scene(scene, geom, F_appl, model: str = "chain-S2", **overrides) -> ImpactChainCVT:
    """The chain of :func:`~cvtfem.machines.chain_cvt.from_scene` with H1 contact (``overrides`` as there), with the
    impacts at contact onset."""
    from dataclasses import fields

    from cvtfem.machines.chain_cvt import from_scene as hertz_from_scene

    base = hertz_from_scene(scene, geom, F_appl, model=model, **{**overrides, "contact": "hertz"})
    return ImpactChainCVT(**{f.name: getattr(base, f.name) for f in fields(base)})
