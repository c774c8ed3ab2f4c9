"""Stills and animations of a chain-CVT results file (:class:`~cvtfem.render.stored_run.StoredRun`): the
transmission at a stored row, and a window of rows as a GIF (pyvista's ``open_gif``, imageio) or an MP4
(``open_movie``, imageio-ffmpeg), one frame per row with the colour limits of the whole window and the time
in the title."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from cvtfem.errors import InputError
from cvtfem.render.rotor import plotter
from cvtfem.render.stored_run import StoredRun
from cvtfem.render.transmission import View, colour_limits, colour_values, draw_frame, set_view

#: Pixel size of animation frames (stills use the size their caller gives).
MOVIE_SIZE = (960, 560)


def _title(run: StoredRun, row: int, name: str, axial_scale: float) -> str:
    note = f", axial positions x{axial_scale:g} about t = {run.time[0]:.4g} s" if axial_scale != 1.0 else ""
    return f"{run.results.path.name}: t = {run.time[row]:.6g} s, coloured by {name}{note}"


def _draw(p, run: StoredRun, row: int, name: str, unit: str, axial_scale: float, clim) -> None:
    draw_frame(p, run.model, run.frame(row, axial_scale), name, run.results.series[name][row], unit, clim)
    p.add_text(_title(run, row, name, axial_scale), font_size=10, color="black")


def render_row(run: StoredRun, row: int, path: str | Path, name: str = "chain.link_tension",
               axial_scale: float = 1.0, size: tuple[int, int] = (1400, 800), view: View = View()) -> Path:
    """PNG of the transmission at stored ``row``, coloured by the stored output ``name``."""
    unit = run.check_colour(name)
    p = plotter(size)
    _draw(p, run, row, name, unit, axial_scale, None)
    set_view(p, view)
    p.screenshot(str(path))
    p.close()
    return Path(path)


def window_limits(run: StoredRun, rows, name: str) -> tuple[float, float]:
    """Colour limits of output ``name`` over ``rows`` (the values as drawn: contact outputs summed over shafts)."""
    return colour_limits(np.concatenate([np.ravel(colour_values(run.model, name, run.results.series[name][r])[0])
                                         for r in rows]))


def check_animation(path: str | Path, fps: float, option: str = "--gif") -> bool:
    """InputError unless ``fps`` is positive and the package writing ``path`` is installed (imageio for a GIF,
    imageio-ffmpeg for a movie); returns True for a movie."""
    if not (np.isfinite(fps) and fps > 0):
        raise InputError("--fps", fps, "must be a positive number of frames per second")
    movie = Path(path).suffix.lower() != ".gif"
    needed = "imageio_ffmpeg" if movie else "imageio"
    if importlib.util.find_spec(needed) is None:
        raise InputError(option, str(path), f"needs the Python package {needed.replace('_', '-')}, which is not "
                         "installed", "pip install " + needed.replace("_", "-") + (" (or write a --gif)" if movie else ""))
    return movie


def write_animation(run: StoredRun, rows, path: str | Path, name: str = "chain.link_tension",
                    axial_scale: float = 1.0, fps: float = 10.0, option: str = "--gif",
                    size: tuple[int, int] = MOVIE_SIZE, view: View = View()) -> Path:
    """GIF (``.gif``) or MP4 (other suffixes, needs imageio-ffmpeg) of the stored ``rows``, one frame each at
    ``fps`` frames per second, coloured by ``name`` with fixed limits over the rows."""
    unit = run.check_colour(name)
    movie = check_animation(path, fps, option)
    clim = window_limits(run, rows, name)
    p = plotter(size)
    if movie:
        p.open_movie(str(path), framerate=fps, quality=7)
    else:
        p.open_gif(str(path), fps=fps)
    for i, row in enumerate(rows):
        p.clear()
        _draw(p, run, int(row), name, unit, axial_scale, clim)
        if i == 0:
            set_view(p, view)
        p.write_frame()
    p.close()
    return Path(path)
