"""A window of a chain-CVT results file as a VTU time series for ParaView (meshio), one file per stored row
and mesh, collected by a ``.pvd`` file per mesh (``chain.pvd``, ``sheaves.pvd``) with the stored times.

``chain_NNNNN.vtu``: every drawn axis (a pin, or a pin half of A5) a polyline of ``PIN_POINTS - 1`` line cells
(block 0), every link a line cell between the mid-points of the two axes it joins (block 1), with the chain's
points of :func:`~cvtfem.render.transmission.chain_frame` (m), and for the chains with plates every plate a quad
(block 2, :func:`~cvtfem.render.transmission.plate_corners`); for each stored output that colours the chain, cell data
(per-axis values on the axis cells, per-link values on the link cells, per-plate values on the plates, NaN on the
other blocks; per-end values: their mean on an axis's cells) and, for the per-axis outputs, point data (an end's
value at its end, linear along the axis; NaN at the plates' corners).  ``sheaves_NNNNN.vtu``: the four sheave
faces as drawn (on elastic shafts displaced and tilted) as quads and the shafts' axes as lines (on elastic shafts
through their displaced beam nodes), with cell data ``shaft`` (0 driving, 1 driven) and ``side`` (-1, +1; 0 on a
shaft).  The times are in the ``.pvd`` files
(meshio's VTU writer drops field data).  meshio reads a chain file back with one line block (the axis cells,
then the links) and the plates' quads.
"""
from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from cvtfem.errors import InputError
from cvtfem.render.stored_run import StoredRun
from cvtfem.render.transmission import colour_values, plate_corners


def chain_mesh(run: StoredRun, row: int, names, axial_scale: float = 1.0):
    """The chain at ``row`` as a meshio Mesh with the outputs ``names`` as point and cell data."""
    import meshio

    frame = run.frame(row, axial_scale)
    n, m, _ = frame.pin_axes.shape
    points = [frame.pin_axes.reshape(-1, 3), frame.pin_axes[:, (m - 1) // 2]]
    start = m * np.arange(n)[:, None] + np.arange(m - 1)
    blocks = [("line", np.stack([start, start + 1], axis=-1).reshape(-1, 2)), ("line", n * m + frame.link_ends)]
    if frame.plate_ends is not None:
        corners = plate_corners(frame)
        blocks.append(("quad", n * m + n + np.arange(corners.size // 3).reshape(-1, 4)))
        points.append(corners.reshape(-1, 3))
    points = np.concatenate(points)
    n_plate_points = len(points) - n * m - n
    point_data, cell_data = {}, {}
    xi = np.linspace(-1.0, 1.0, m)

    def nan(block):
        return np.full(len(blocks[block][1]), np.nan)
    for name in names:
        v, kind = colour_values(run.model, name, run.results.series[name][row])
        if kind in ("link", "plate"):
            cell_data[name] = [nan(0), v if kind == "link" else nan(1)] + (
                [v[frame.plate_slots] if kind == "plate" else nan(2)] if len(blocks) == 3 else [])
            continue
        ends = np.column_stack([v, v]) if kind == "pin" else v
        along = ends[:, :1] + (ends[:, 1:] - ends[:, :1]) * (xi + 1) / 2
        point_data[name] = np.concatenate([along.ravel(), ends.mean(axis=1), np.full(n_plate_points, np.nan)])
        cell_data[name] = [np.repeat(ends.mean(axis=1), m - 1), nan(1)] + ([nan(2)] if len(blocks) == 3 else [])
    return meshio.Mesh(points, blocks, point_data=point_data, cell_data=cell_data)


def sheave_mesh(run: StoredRun, row: int, axial_scale: float = 1.0):
    """The four sheave faces at ``row`` as drawn, quads (block 0), and the two shafts' axes, lines (block 1), in one
    mesh with cell data ``shaft`` (0 driving, 1 driven) and ``side`` (-1, +1 for a face, 0 for a shaft)."""
    import meshio

    frame = run.frame(row, axial_scale)
    faces = frame.faces                                        # (2, 2, 3, n_r, n_theta)
    n_r, n_theta = faces.shape[-2:]
    idx = np.arange(n_r * n_theta).reshape(n_r, n_theta)
    one = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
    points, quads, shaft, side = [], [], [], []
    for k in range(2):
        for j, s in enumerate((-1, 1)):
            quads.append(one + len(points) * n_r * n_theta)
            points.append(faces[k, j].reshape(3, -1).T)
            shaft.append(np.full(len(one), k))
            side.append(np.full(len(one), s))
    base, lines, line_shaft = 4 * n_r * n_theta, [], []
    for k, axis in enumerate(frame.shafts):
        lines.append(base + np.column_stack([np.arange(len(axis) - 1), np.arange(1, len(axis))]))
        line_shaft.append(np.full(len(axis) - 1, k))
        points.append(axis)
        base += len(axis)
    lines, line_shaft = np.concatenate(lines), np.concatenate(line_shaft)
    return meshio.Mesh(np.concatenate(points), [("quad", np.concatenate(quads)), ("line", lines)],
                       cell_data={"shaft": [np.concatenate(shaft), line_shaft],
                                  "side": [np.concatenate(side), np.zeros(len(lines), int)]})


def write_pvd(path: Path, times, files) -> Path:
    """A ParaView collection file listing ``files`` (relative names) at ``times`` (s)."""
    root = ElementTree.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    coll = ElementTree.SubElement(root, "Collection")
    for t, f in zip(times, files):
        ElementTree.SubElement(coll, "DataSet", timestep=repr(float(t)), group="", part="0", file=str(f))
    ElementTree.indent(root)
    ElementTree.ElementTree(root).write(path, xml_declaration=True, encoding="utf-8")
    return path


def read_pvd(path: str | Path) -> tuple[np.ndarray, list[Path]]:
    """Times (s) and file paths of a ``.pvd`` collection."""
    path = Path(path)
    sets = ElementTree.parse(path).getroot().iter("DataSet")
    pairs = [(float(d.get("timestep")), path.parent / d.get("file")) for d in sets]
    return np.array([t for t, _ in pairs]), [f for _, f in pairs]


def write_vtu_series(run: StoredRun, rows, directory: str | Path, axial_scale: float = 1.0,
                     names=None) -> list[Path]:
    """``chain.pvd`` and ``sheaves.pvd`` with one VTU per stored row in ``directory`` (created; existing series
    files there are refused); ``names``: the outputs written (default: every stored output that colours)."""
    import meshio

    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise InputError("--vtu", str(directory), "must be a directory (it is a file)")
    directory.mkdir(parents=True, exist_ok=True)
    if any(directory.glob("chain*.pvd")) or any(directory.glob("chain_*.vtu")):
        raise InputError("--vtu", str(directory), "must not hold a series already (results are never overwritten)",
                         "choose another directory")
    if names is None:
        names = run.colourable()
    for name in names:
        run.check_colour(name, "--vtu")
    times, chain_files, sheave_files = [], [], []
    for i, row in enumerate(rows):
        row = int(row)
        chain_files.append(f"chain_{i:05d}.vtu")
        sheave_files.append(f"sheaves_{i:05d}.vtu")
        meshio.write(directory / chain_files[-1], chain_mesh(run, row, names, axial_scale))
        meshio.write(directory / sheave_files[-1], sheave_mesh(run, row, axial_scale))
        times.append(run.time[row])
    return [write_pvd(directory / "chain.pvd", times, chain_files),
            write_pvd(directory / "sheaves.pvd", times, sheave_files)]
