"""Modes of a solid sheave per nodal-diameter number, standing and spinning, and its wedge opening.

Uses the axisymmetric-harmonic model of :mod:`cvtfem.elements.sheave_solid`, bore clamped to a rigid shaft.
Spinning at ``Omega`` (rad/s) the frequencies come out in the rotating frame; a fixed observer sees the wave of
``n`` diameters at ``f + n Omega / 2 pi`` (forward) and ``f - n Omega / 2 pi`` (backward, negative once it
runs backwards past the critical speed).
"""
from __future__ import annotations

import numpy as np

from cvtfem.elements.sheave_solid import HarmonicSheave, SheaveSection
from cvtfem.errors import InputError

#: Most nodal diameters and modes per diameter a spectrum computes (each diameter is one 2D eigenproblem).
MAX_DIAMETERS, MAX_MODES = 40, 50


def harmonics(diameters: int) -> list[tuple[int, str]]:
    """``(n, family)`` of a spectrum: ``n = 0`` in both families (umbrella/axial and torsion), ``n >= 1`` once."""
    if not 0 <= diameters <= MAX_DIAMETERS:
        raise InputError("--diameters", diameters, f"must be 0..{MAX_DIAMETERS} nodal diameters")
    return [(0, "cos"), (0, "sin")] + [(n, "cos") for n in range(1, diameters + 1)]


def sheave_spectrum(section: SheaveSection, diameters: int = 4, count: int = 2, speed: float = 0.0,
                    mesh: tuple[int, int] = (24, 2)) -> list[dict]:
    """The ``count`` lowest modes of every harmonic up to ``diameters`` nodal diameters, as rows
    ``{n, family, k, rotating_hz, forward_hz, backward_hz}`` sorted by frequency; ``speed`` in rad/s."""
    if not 1 <= count <= MAX_MODES:
        raise InputError("--modes", count, f"must be 1..{MAX_MODES} modes per nodal diameter")
    if not (np.isfinite(speed) and speed >= 0.0):
        raise InputError("--speed", speed, "must be a finite spin speed >= 0")
    prestress = None
    if speed > 0.0:
        axisym = HarmonicSheave(section, 0, "cos", *mesh)
        prestress = axisym.stress(axisym.centrifugal_displacement(speed))
    rows = []
    for n, family in harmonics(diameters):
        model = HarmonicSheave(section, n, family, *mesh)
        f, _ = model.spinning_modes(speed, prestress, count) if prestress is not None else model.modes(count)
        shift = n * speed / (2 * np.pi)
        rows += [{"n": n, "family": family, "k": k, "rotating_hz": float(v), "forward_hz": float(v + shift),
                  "backward_hz": float(v - shift)} for k, v in enumerate(f)]
    return sorted(rows, key=lambda row: row["rotating_hz"])


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
