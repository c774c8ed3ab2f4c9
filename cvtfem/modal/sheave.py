"""Modes of a solid sheave per nodal-diameter number, standing and spinning, and its wedge opening.

Uses the axisymmetric-harmonic model of :mod:`cvtfem.elements.sheave_solid`, bore clamped to a rigid shaft.
Spinning at ``Omega`` (rad/s) the frequencies come out in the rotating frame, split by Coriolis forces into a
wave running with the spin and one against it; a fixed observer sees the wave of ``n`` diameters at
``f + n Omega / 2 pi`` (forward) and ``f - n Omega / 2 pi`` (backward, negative once it runs backwards past
the critical speed).
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection
from cvtfem.errors import InputError

#: Most nodal diameters and modes per diameter a spectrum computes (each diameter is one 2D eigenproblem).
MAX_DIAMETERS, MAX_MODES = 40, 50


def sheave_spectrum(section: SheaveSection, diameters: int = 4, count: int = 2, speed: float = 0.0,
                    mesh: tuple[int, int] = (24, 2)) -> list[dict]:
    """The lowest modes of every nodal-diameter number up to ``diameters``, as rows
    ``{n, wave, rotating_hz, fixed_hz}`` sorted by ``fixed_hz``; ``speed`` in rad/s.

    At rest ``count`` modes per ``n`` (``n = 0`` in both families: umbrella/radial and torsion), ``wave``
    ``"standing"`` (double for ``n >= 1``).  Spinning, the two families of each ``n`` are coupled by Coriolis
    forces and prestressed (:meth:`HarmonicSheave.travelling_modes`): ``2 count`` waves per ``n``, ``"fw"``
    running with the spin relative to the disc (a fixed observer sees ``f + n Omega / 2 pi``), ``"bw"`` against
    it (``f - n Omega / 2 pi``, negative past the critical speed); ``n = 0`` stays ``"standing"``."""
    if not 0 <= diameters <= MAX_DIAMETERS:
        raise InputError("--diameters", diameters, f"must be 0..{MAX_DIAMETERS} nodal diameters")
    if not 1 <= count <= MAX_MODES:
        raise InputError("--modes", count, f"must be 1..{MAX_MODES} modes per nodal diameter")
    if not (np.isfinite(speed) and speed >= 0.0):
        raise InputError("--speed", speed, "must be a finite spin speed >= 0")
    rows = []
    if speed == 0.0:
        for n, family in [(0, "cos"), (0, "sin")] + [(n, "cos") for n in range(1, diameters + 1)]:
            f, _ = HarmonicSheave(section, n, family, *mesh).modes(count)
            rows += [{"n": n, "wave": "standing", "rotating_hz": float(v), "fixed_hz": float(v)} for v in f]
        return sorted(rows, key=lambda row: row["fixed_hz"])
    axisym = HarmonicSheave(section, 0, "cos", *mesh)
    prestress = axisym.stress(axisym.centrifugal_displacement(speed))
    for n in range(diameters + 1):
        f, sense = HarmonicSheave(section, n, "cos", *mesh).travelling_modes(speed, prestress, count)
        rows += [{"n": n, "wave": {1.0: "fw", -1.0: "bw"}.get(float(d), "standing"), "rotating_hz": float(v),
                  "fixed_hz": float(v + d * n * speed / (2 * np.pi))} for v, d in zip(f, sense)]
    return sorted(rows, key=lambda row: row["fixed_hz"])


def mode_shape(section: SheaveSection, n: int, family: str, k: int,
               mesh: tuple[int, int] = (24, 2)) -> tuple[HarmonicSheave, np.ndarray, float]:
    """Model, shape (section DOFs, largest amplitude 1) and frequency (Hz) of mode ``k`` of harmonic ``n``."""
    model = HarmonicSheave(section, n, family, *mesh)
    f, shapes = model.modes(k + 1)
    shape = shapes[:, k]
    return model, shape / np.abs(shape).max(), float(f[k])


def wedge_opening(section: SheaveSection, force: float,
                  mesh: tuple[int, int] = (24, 2)) -> tuple[HarmonicSheave, np.ndarray]:
    """Model and displacement (m) of the sheave, bore clamped, pushed back (towards ``-z``, away from the chain)
    by an axial ring load ``force`` (N) spread over its rim: the opening of the wedge, per sheave."""
    if not (np.isfinite(force) and 0.0 < abs(force) < 1e9):
        raise InputError("--load", force, "must be a finite axial force in N with 0 < |F| < 1e9")
    model = HarmonicSheave(section, 0, "cos", *mesh)
    return model, model.static(model.rim_load(-force))


def sheave_waves(section: SheaveSection, diameters: int, speeds: np.ndarray,
                 mesh: tuple[int, int] = (24, 2), first: int = 2) -> list[tuple[str, np.ndarray]]:
    """Campbell lines of the sheave's own lowest waves of ``n = first..diameters`` nodal diameters (bore clamped: they
    do not move the shaft), as ``(label, fixed-frame Hz per speed)`` with labels ``"sheave n=2 fw"`` and
    ``"sheave n=2 bw"``.  Each wave follows ``f(Omega)^2 = f_0^2 + lambda Omega^2`` in the rotating frame
    (``lambda`` fitted to the Coriolis-coupled model at the highest speed, rad/s) and is seen at
    ``f +- n Omega / 2 pi``."""
    speeds = np.asarray(speeds, float)
    top = float(speeds.max())
    lines = []
    if diameters < first:
        return lines
    prestress = None
    if top > 0.0:
        axisym = HarmonicSheave(section, 0, "cos", *mesh)
        prestress = axisym.stress(axisym.centrifugal_displacement(top))
    for n in range(max(first, 2), diameters + 1):
        model = HarmonicSheave(section, n, "cos", *mesh)
        f0 = model.modes(1)[0][0]
        if prestress is None:
            spun = {1.0: f0, -1.0: f0}
        else:
            f, sense = model.travelling_modes(top, prestress, 1)
            spun = dict(zip(sense.tolist(), f))
        for sense, wave in ((1.0, "fw"), (-1.0, "bw")):
            lam = (spun[sense] ** 2 - f0 ** 2) / top ** 2 if top > 0.0 else 0.0
            rotating = np.sqrt(f0 ** 2 + lam * speeds ** 2)
            lines.append((f"sheave n={n} {wave}", rotating + sense * n * speeds / (2 * np.pi)))
    return lines
