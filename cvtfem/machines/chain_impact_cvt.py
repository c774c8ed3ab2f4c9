"""Chains on two rigid shafts with impact at contact onset (``effects.contact = "impact"``): :class:`ImpactChainCVT`
(the mirrored chains S2 and S3 of :class:`~cvtfem.machines.chain_cvt.ChainCVT`) and :class:`ImpactChainACVT` (the
whole-pin chain A1 of :class:`~cvtfem.machines.chain_a_cvt.ChainACVT`), both through :class:`ContactOnsetImpacts`.

A pin end entering a sheave (its penetration ``Delta`` rising through zero) is an event of the model protocol
(:meth:`ContactOnsetImpacts.events`, one indicator per pin end and shaft, read through the model's contact map); at
the event :meth:`ContactOnsetImpacts.switch` applies the C2 impulse (contact-models digest §3: perfectly inelastic
normal, Coulomb tangential with the stick check) in the generalized coordinates: ``M dv = e G^T P`` with ``w = G v``
the end's velocity relative to the sheave point it meets, ``e`` the ends one contact stands for (2 mirrored, 1 single)
and the constraint ``n . G v+ = 0`` (:mod:`cvtfem.elements.chain.pin_impact`).  So the pin end's inertia is the
model's own: S2's per-end ``m_p / 2`` (axial ``m_p / 6``), S3's bending pin ``m_p / 12`` in the plane, A1's end of a
Hermite beam whose mass matrix couples its two ends (an impact at one end moves the other).  The kinetic energy
changes by ``(e / 2) P . (w- + w+) <= 0``.  The contact then carries on as H1 (Hertz at the pin-axis end, regularised
friction), which starts at zero force and now at zero normal approach speed.  S1 has no axial inertia, so no impact
(chain-models-1 §2.1).

State: the base model's with two first-order blocks before the work integrals: ``contact.state`` (one per pin end and
shaft, end-major, driving then driven) the discrete state of each pin end, 0 free, 1 in contact after a sliding impact
(or present at the start), 2 in contact after a stuck impact; and ``contact.impact_loss`` (J) the kinetic energy the
impacts took, which is also added to the dissipated work so that the work integrals close the energy balance across
the jumps.  Both have zero rate; they change only at events, and checkpoints carry them with the state.
"""
from __future__ import annotations

from functools import cached_property
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from cvtfem.assembly.model import StateLayout
from cvtfem.elements.base import Block
from cvtfem.elements.chain.pin_impact import (end_geometry, friction_coefficient, impact_energy_change, input_gaps,
                                              pin_end_impulses, relative_velocity_map)
from cvtfem.elements.contact.impact import FREE, SLIDING
from cvtfem.errors import NumericalError
from cvtfem.machines.chain_a_cvt import ChainACVT
from cvtfem.machines.chain_cvt import ChainCVT
from cvtfem.outputs import OutputSpec

#: Offset (m) of the indicator of an end in contact: far above the round-off of ``Delta`` (~1e-17 m), far below the
#: Hertz penetrations (~1e-5 m); the release fires this far off the face, where H1 carries no force already.
HYSTERESIS = 1e-10
#: Largest kinetic energy gain (relative to ``|P . w-|``) an impulse may show in round-off.
ENERGY_ROUNDOFF = 1e-9
#: Sweeps of the joint impacts of ends that fired together, and the change of a relative velocity in a sweep
#: (relative to the largest before) below which they have settled.
SWEEPS, SETTLED = 200, 1e-10


class ContactOnsetImpacts:
    """The impacts at contact onset of a chain transmission built on :class:`ChainCVT` (mixed in before it)."""

    #: Pin ends one contact stands for: 2 on a mirrored chain (both ends hit at once), 1 for single ends.
    ends_per_contact: ClassVar[int] = 2

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
        """``(state (2 n_ends,), impact loss J)`` of a state vector (the state rounded: a dense output between two
        steps may carry it as ``1 - 1e-15``)."""
        d = x[self._discrete]
        return np.rint(d[:-1]), float(d[-1])

    def end_name(self, end: int) -> str:
        """``"pin 17"`` (a mirrored pair of ends)."""
        return f"pin {int(end)}"

    def state_label(self, i: int) -> str:
        i, d = int(i), self._discrete
        if d.start <= i < d.stop - 1:
            j = i - d.start
            return f"{self.end_name(j // 2)}, contact state with the {('driving', 'driven')[j % 2]} sheave"
        if i == d.stop - 1:
            return "contact.impact_loss"
        return super().state_label(i if i < d.start else i - self.n_discrete - 1)

    def _with_discrete(self, x_base) -> np.ndarray:
        """A state of the base layout with the discrete block inserted: ends in contact (``Delta > 0``) in state 1, no
        loss so far."""
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
    @cached_property
    def _gap_map(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(cols, coef, shafts)`` of the position inputs ``(u1, u2, u3, z)`` of every ``(end, shaft)`` pair, row
        ``2 end + shaft`` (from the contact map, built once)."""
        ends, shafts = self._all_pairs()
        cols, coef = self._contact_map(ends, shafts)
        return cols[:, :4], coef[:, :4], shafts

    def events(self, t: float, x) -> np.ndarray:
        """Penetration ``Delta`` (2 n_ends,) m of every pin end against each shaft's sheave (end-major), plus
        :data:`HYSTERESIS` for the ends in contact: a free end's rise through zero is a contact onset (impact), an
        end in contact is released where ``Delta`` falls below ``-HYSTERESIS``.  Without the offset an end left at
        ``Delta = 0`` by its impact would cross zero again in round-off and be hit again and again (Zeno)."""
        cols, coef, shafts = self._gap_map
        y = np.concatenate([x[:2 * self.n2], self._constants])
        e = input_gaps(self.contact, (coef * y[cols]).sum(axis=2), shafts)
        return e + HYSTERESIS * (x[self._discrete.start:self._discrete.stop - 1] > 0.5)      # not FREE

    @cached_property
    def event_direction(self) -> np.ndarray:
        return np.zeros(self.n_discrete, int)

    @cached_property
    def event_terminal(self) -> np.ndarray:
        return np.zeros(self.n_discrete, bool)

    def switch(self, t: float, x, fired) -> np.ndarray:
        """The state after the events ``fired`` (2 n_ends,) bool at ``(t, x)``: each end that approaches its sheave
        (``n . w < 0``) gets its impact, the others are released; the impacts' kinetic energy goes to
        ``contact.impact_loss`` and to the dissipated work.  Ends that fire together are solved together by block
        Gauss-Seidel on their impulses (:meth:`joint_impacts`): where the mass matrix couples them (A1's two ends of a
        pin) an impact at one end changes the other's velocity.  An end the flow pulls off the face right after its
        impact (touch and leave: ``Delta'' < 0`` at zero approach speed, which the event locator does not see as a
        crossing) is free again.  NumericalError if the impacts would add kinetic energy (a sliding impulse can, for
        ``f^2 tau- . A tau- > n . A n``; far from the chains' ``f``) or do not settle."""
        ends = np.flatnonzero(fired)
        x, P, w0, dT = self.joint_impacts(t, x, ends // 2, ends % 2)
        if dT > ENERGY_ROUNDOFF * np.abs(np.sum(P * w0, axis=1)).sum():
            raise NumericalError(f"the impacts of {', '.join(self.end_name(j // 2) for j in ends)} would add {dT:.3g} "
                                 f"J of kinetic energy (sliding impulses with f = "
                                 f"{friction_coefficient(self.contact):g})", t=t, component=type(self).__name__)
        hit = ends[x[self._discrete.start + ends] > 0.5]                                    # not FREE
        if len(hit):
            leaving = self._gap_curvature(t, x)[hit] < 0
            x[self._discrete.start + hit[leaving]] = FREE
        return x

    def joint_impacts(self, t: float, x, ends, shafts):
        """``(x+, P (m, 3) N s, w- (m, 3), dT J)``: the C2 impacts of ``ends`` on ``shafts`` at once.  Block
        Gauss-Seidel over the ends: each visit solves one end's C2 impulse for its relative velocity without its own
        impulse (``w - A_ii P_i``) and applies the difference, until no visit changes a relative velocity by more than
        :data:`SETTLED` of the largest before (frictionless, the limit is the joint inelastic impact: the projected
        Gauss-Seidel solution of its complementarity problem).  One end: the single impact, in one sweep."""
        x = np.array(x, float)
        e, f = self.ends_per_contact, friction_coefficient(self.contact)
        P, w_before, dT = np.zeros((len(ends), 3)), np.zeros((len(ends), 3)), 0.0
        scale = 0.0
        for sweep in range(SWEEPS):
            change = 0.0
            for i, (end, shaft) in enumerate(zip(ends, shafts)):
                w, normal, G, MinvGt = self.impact_map(x, int(end), int(shaft))
                if sweep == 0:
                    w_before[i], scale = w, max(scale, float(np.linalg.norm(w)))
                A = e * G @ MinvGt
                P_new, state = pin_end_impulses((w - A @ P[i])[None], normal[None], A[None], f)
                dP = P_new[0] - P[i]
                _, dT_i = self._jump(x, G, MinvGt, w, dP)
                x[self._discrete.start + 2 * end + shaft] = int(state[0])
                P[i], dT = P_new[0], dT + dT_i
                change = max(change, float(np.linalg.norm(A @ dP)))
            if sweep and change <= SETTLED * scale:
                return x, P, w_before, dT
        raise NumericalError(f"the impacts of {len(ends)} pin ends did not settle in {SWEEPS} sweeps", t=t,
                             component=type(self).__name__)

    def _jump(self, x, G, MinvGt, w, P):
        """Apply the impulse ``P`` (3,) N s of a contact with ``w = G v`` (m/s before) and ``M^-1 G^T`` to the
        velocities of ``x`` (in place), its kinetic energy change to the loss and the dissipated work; return
        ``(w+, dT J)``."""
        e, n2 = self.ends_per_contact, self.n2
        x[n2:2 * n2] += e * MinvGt @ P
        w_after = G @ x[n2:2 * n2]
        dT = float(impact_energy_change(P, w, w_after, e))
        x[self._discrete.stop - 1] -= dT
        x[-2] -= dT                                            # the dissipated work
        return w_after, dT

    def _gap_curvature(self, t: float, x, dt: float = 1e-9) -> np.ndarray:
        """``Delta''`` (2 n_ends,) m/s^2 estimated from two explicit steps of ``dt`` s (the positions move by
        ``2 dt v + dt^2 a``): its sign says where an end at zero approach speed goes next."""
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
        inside = (vc >= 0) & (vc < self.n2) & (vw != 0)       # constants act on nothing
        np.add.at(C, (np.nonzero(inside)[0], vc[inside]), vw[inside])
        G = B @ C
        MinvGt = np.column_stack([self.solve_mass(G[i]) for i in range(3)])
        return G @ v, normal[0], G, MinvGt

    def impact(self, x, ends, shafts):
        """The state after the single impacts of ``ends`` on ``shafts`` (applied in order, each with the velocities the
        previous left) and per impact ``(P (3,) N s, state, energy change J, w- (3,), w+ (3,))``."""
        x = np.array(x, float)
        log = []
        for end, shaft in zip(ends, shafts):
            w, normal, G, MinvGt = self.impact_map(x, int(end), int(shaft))
            A = self.ends_per_contact * G @ MinvGt
            P, state = pin_end_impulses(w[None], normal[None], A[None], friction_coefficient(self.contact))
            w_after, dT = self._jump(x, G, MinvGt, w, P[0])
            x[self._discrete.start + 2 * end + shaft] = int(state[0])
            log.append((P[0], int(state[0]), dT, w, w_after))
        return x, log

    # ----- outputs -----------------------------------------------------------------------------------
    @cached_property
    def output_specs(self) -> tuple[OutputSpec, ...]:
        return super().output_specs + (
            OutputSpec("contact.state", "-", "Discrete state of each pin end and shaft (end-major, driving then "
                       "driven): 0 free, 1 in contact after a sliding impact (or at the start), 2 after a stuck "
                       "impact.",
                       self.n_discrete),
            OutputSpec("contact.impact_loss", "J", "Kinetic energy taken by the impacts at contact onset since t = 0 "
                       "(included in the dissipated work)."))

    def _more_outputs(self, x):
        state, loss = self.discrete_state(x)
        return {**super()._more_outputs(x), "contact.state": state, "contact.impact_loss": loss}


class ImpactChainCVT(ContactOnsetImpacts, ChainCVT):
    """chain-S2 or chain-S3 + H1 contact with C2 impacts at contact onset + two rigid shafts + regime + loops."""


class ImpactChainACVT(ContactOnsetImpacts, ChainACVT):
    """chain-A1 + H1 contact at every pin end with C2 impacts at contact onset + two rigid shafts (a fixed and a movable
    sheave each) + regime + loops.  End ``e = 2 p + near`` of pin ``p`` (far: ``x3 < 0``)."""

    ends_per_contact: ClassVar[int] = 1

    def end_name(self, end: int) -> str:
        """``"pin 17 near end"``."""
        return f"pin {int(end) // 2} {('far', 'near')[int(end) % 2]} end"


def from_scene(scene, geom, F_appl, model: str = "chain-S2", **overrides) -> ImpactChainCVT | ImpactChainACVT:
    """The chain of :func:`~cvtfem.machines.chain_cvt.from_scene` with H1 contact (``overrides`` as there), with the
    impacts at contact onset."""
    from dataclasses import fields

    from cvtfem.machines.chain_cvt import from_scene as hertz_from_scene

    base = hertz_from_scene(scene, geom, F_appl, model=model, **{**overrides, "contact": "hertz"})
    cls = ImpactChainACVT if isinstance(base, ChainACVT) else ImpactChainCVT
    return cls(**{f.name: getattr(base, f.name) for f in fields(base)})
