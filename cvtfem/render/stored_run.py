"""A chain-CVT results file opened for drawing: the model rebuilt from the stored scene and the stored rows.

A row's chain is drawn from the stored outputs ``chain.coordinates`` (the chain family's q) and, on rigid shafts,
``driving.sheave_position`` / ``driven.sheave_position``, on elastic shafts ``driving.shaft_coordinates`` /
``driven.shaft_coordinates`` (the shafts' beam nodes and sheaves), through the rebuilt model's geometry
(:func:`~cvtfem.render.transmission.chain_frame`);
colours come from the stored per-link, per-pin, per-pin-half or per-pin-end series, so nothing is recomputed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from cvtfem.errors import InputError
from cvtfem.io.results import Results
from cvtfem.render.transmission import ChainFrame, chain_frame, check_colour, colour_kind

#: Series a results file needs for drawing its chain: on rigid shafts, on elastic shafts.
GEOMETRY = {False: ("chain.coordinates", "driving.sheave_position", "driven.sheave_position"),
            True: ("chain.coordinates", "driving.shaft_coordinates", "driven.shaft_coordinates")}


@dataclass(frozen=True, eq=False)
class StoredRun:
    """A chain-CVT results file with the scene it stores; :attr:`model` is built on first use."""

    results: Results
    scene: object

    @cached_property
    def model(self):
        """The transmission of the stored scene (:func:`~cvtfem.machines.cvt.chain_loop`); on elastic shafts with the
        faces' reference the run stored (no start solved)."""
        from cvtfem.machines.chain_cvt_elastic import FACE_REFERENCE, with_face_reference
        from cvtfem.machines.cvt import chain_loop

        series = self.results.series                     # already read: the first row of each reference series
        stored = all(name in series and len(series[name]) for name in FACE_REFERENCE)
        return with_face_reference(chain_loop(self.scene),
                                   {name: series[name][0] for name in FACE_REFERENCE} if stored else None)

    @classmethod
    def of(cls, results: Results, scene, where: str = "RESULTS") -> StoredRun:
        """The results file ``results`` whose stored scene is ``scene`` (validated by the caller); InputError when it
        is not the results file of a chain-CVT run with its chain's geometry and at least one row."""
        from cvtfem.machines.cvt import chain_refusal

        res = results
        model_name = scene.cvt.model if scene.kind == "cvt" and scene.cvt is not None else None
        if model_name is None or chain_refusal(scene) is not None:
            what = f"a {scene.kind} scene" if model_name is None else f"cvt.model = {model_name!r}"
            raise InputError(where, str(res.path), "must be the results file of a chain-CVT run (a chain model that "
                             "runs, on rigid or elastic shafts); its scene has " + what)
        elastic = bool(scene.cvt.effects.shaft_elasticity)
        missing = [name for name in GEOMETRY[elastic] if name not in res.series]
        if missing:
            raise InputError(where, str(res.path), "must store the chain's geometry to be drawn: it lacks the "
                             "series " + ", ".join(missing), "add them to `output.names` (or leave it empty: all "
                             "outputs) and run again" + (" (runs on elastic shafts store their shafts' "
                                                         "coordinates since session 17)" if elastic else ""))
        if res.time.size == 0:
            raise InputError(where, str(res.path), "must hold at least one output row (it has none)")
        return cls(res, scene)

    @property
    def time(self) -> np.ndarray:
        """Stored output times, s."""
        return self.results.time

    @property
    def slack(self) -> float:
        """Rounding allowance of times asked for, s: 1e-6 of the mean output step (a time typed as ``1e-5`` means
        the row stored at ``1.0000000000000001e-05``)."""
        t = self.time
        return 1e-6 * (t[-1] - t[0]) / (t.size - 1) if t.size > 1 else 1e-12 * max(abs(t[0]), 1e-3)

    def _range_text(self) -> str:
        return f"[{self.time[0]:.6g}, {self.time[-1]:.6g}] s (the stored rows)"

    def row_at(self, t: float, option: str = "--time") -> int:
        """Index of the stored row nearest ``t`` (s; the earlier one on a tie); ``t`` must lie in the stored range
        (give or take :attr:`slack`)."""
        t0, t1 = self.time[0] - self.slack, self.time[-1] + self.slack
        if not (math.isfinite(t) and t0 <= t <= t1):
            raise InputError(option, t, f"must be a time in {self._range_text()}")
        i = int(np.searchsorted(self.time, t))
        if i == self.time.size or (i > 0 and t - self.time[i - 1] <= self.time[i] - t):
            i -= 1
        return i

    def rows_in(self, t_start: float, t_stop: float, frames: int | None = None, option: str = "--window") -> np.ndarray:
        """Rows with ``t_start <= t <= t_stop`` (s, give or take :attr:`slack`), or with ``frames`` the rows nearest ``frames`` equally spaced
        times of the window; the window must lie in the stored range and hold at least two rows."""
        t0, t1, eps = self.time[0], self.time[-1], self.slack
        if not (math.isfinite(t_start) and math.isfinite(t_stop) and t0 - eps <= t_start < t_stop <= t1 + eps):
            raise InputError(option, [t_start, t_stop], f"must be two increasing times in {self._range_text()}")
        rows = np.flatnonzero((self.time >= t_start - eps) & (self.time <= t_stop + eps))
        if rows.size < 2:
            raise InputError(option, [t_start, t_stop], f"must hold at least two stored rows (it holds {rows.size}; "
                             f"output step about {np.diff(self.time).mean() if self.time.size > 1 else 0:.3g} s)")
        if frames is None:
            return rows
        if not 2 <= frames <= rows.size:
            raise InputError("--frames", frames, f"must be between 2 and the {rows.size} stored rows of the window")
        return np.array([self.row_at(t, option) for t in np.linspace(self.time[rows[0]], self.time[rows[-1]], frames)])

    def geometry(self, row: int) -> tuple[np.ndarray, np.ndarray]:
        """Chain coordinates and the placement of :func:`~cvtfem.render.transmission.chain_frame` stored at ``row``:
        the sheave positions ``z`` (2,) m on rigid shafts, the structure's coordinates on elastic ones."""
        s = self.results.series
        if self.scene.cvt.effects.shaft_elasticity:
            return s["chain.coordinates"][row], np.concatenate([s["driving.shaft_coordinates"][row],
                                                                s["driven.shaft_coordinates"][row]])
        return s["chain.coordinates"][row], np.array([s["driving.sheave_position"][row, 0],
                                                      s["driven.sheave_position"][row, 0]])

    def frame(self, row: int, axial_scale: float = 1.0) -> ChainFrame:
        """The drawn geometry at ``row``, axial positions exaggerated by ``axial_scale`` about the first row."""
        return chain_frame(self.model, *self.geometry(row), reference=self.geometry(0), axial_scale=axial_scale)

    def check_colour(self, name: str, option: str = "--color") -> str:
        """The unit of a colouring output stored in the file (else InputError listing those stored)."""
        return check_colour(self.model, name, stored=self.results.series, option=option)

    def colourable(self) -> list[str]:
        """Stored outputs that colour the chain (per link, per pin, per pin end and shaft)."""
        return [s.name for s in self.model.output_specs
                if s.name in self.results.series and colour_kind(self.model, s) is not None]
