"""Results files: one HDF5 file per run, written incrementally.

Layout::

    /                attrs: cvtfem_version, created, status, message, kind
    /scene           TOML text of the resolved scene (string dataset)
    /stats           attrs: solver statistics (counters, wall time)
    /series/time     (n,) float64, unit "s"
    /series/NAME     (n, size) float64, attrs unit, doc
    /checkpoint/slots  full state for resuming (payload chosen by the run driver;
                     layout in :mod:`cvtfem.io.checkpoint`)

Rows are collected in memory (one float64 block, a row per sample) and
appended to resizable datasets, one write per series, when the file is
flushed: every ``flush_interval`` seconds of wall time, so a run killed
half-way leaves a readable file with every row up to the last flush
(``status`` then stays "running"): the file is in HDF5's single-writer/multiple-reader mode, which
keeps it consistent on disk at every moment, and readers open it with
``swmr=True``.  Attributes and datasets cannot be created in that mode, so
statistics, whole arrays and the final status are written when the run
closes the file.  At each flush the series are extended first and ``time``
last; a reader trusts the shortest of them.

Checkpoints (``checkpoint=Layout``) are pre-created before SWMR starts and
overwritten in place (:meth:`ResultsWriter.checkpoint`); each one records the
number of rows written so far.  :meth:`ResultsWriter.resume` continues a killed
run in the same file: a killed SWMR writer leaves the file flagged "open for
writing", which HDF5 refuses to reopen for writing, so the file is rebuilt
(rows up to the newest checkpoint, the checkpoint itself) under a temporary
name next to it and moved over the original once it is consistent.
"""
from __future__ import annotations

import ctypes
import fcntl
import functools
import os
import struct
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from cvtfem import __version__
from cvtfem.errors import InputError, NumericalError
from cvtfem.io import checkpoint as ckpt
from cvtfem.outputs import OutputSpec

CHUNK_ROWS = 256


class RunLock:
    """An exclusive lock on a results file while one process writes it (``flock`` on a hidden sidecar
    ``.NAME.lock``, released by :meth:`release` or by the process's death, also by ``kill -9``)."""

    def __init__(self, path: Path, where: str) -> None:
        self.path = path.with_name(f".{path.name}.lock")
        path.parent.mkdir(parents=True, exist_ok=True)
        self._fh = open(self.path, "a+")
        try:
            fcntl.flock(self._fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._fh.seek(0)
            owner = self._fh.read().strip() or "unknown"
            self._fh.close()
            raise InputError(where, str(path), f"must not be in use: a running cvtfem process (pid {owner}) is "
                             "writing it", "wait for it to end, or stop it first") from None
        self._fh.seek(0)
        self._fh.truncate()
        self._fh.write(str(os.getpid()))
        self._fh.flush()

    def release(self) -> None:
        """Unlock and remove the sidecar (idempotent)."""
        if not self._fh.closed:
            self.path.unlink(missing_ok=True)
            self._fh.close()


class ResultsWriter:
    """Append time histories of named outputs to an HDF5 file.

    Parameters
    ----------
    path : str or Path
        File to create (an existing file is refused unless ``overwrite``).
    scene_toml : str
        Resolved scene as TOML text.
    kind : str
        What produced the file ("run", "modes", ...).
    outputs : sequence of OutputSpec
        Series to record; each sample of a series is ``size`` floats.
    flush_interval : float
        Wall time between flushes, s.
    overwrite : bool
        Replace an existing file.
    checkpoint : Layout, optional
        Payload fields of the checkpoints (a ``rows`` field is added); None: no checkpoints.
    """

    def __init__(self, path: str | Path, scene_toml: str, kind: str, outputs: Sequence[OutputSpec],
                 flush_interval: float = 2.0, overwrite: bool = False, checkpoint: ckpt.Layout | None = None,
                 _resume: dict[str, Any] | None = None, _lock: RunLock | None = None) -> None:
        self.path = Path(path)
        if self.path.exists() and not overwrite:
            raise InputError("results file", str(self.path), "must not exist already (results are never overwritten)",
                             "choose another name or delete it")
        self._lock = _lock or RunLock(self.path, "results file")
        self.flush_interval = flush_interval
        self.scene_toml = scene_toml
        self._file = h5py.File(self.path, "w", libver="latest")
        f = self._file
        f.attrs.update(cvtfem_version=__version__, kind=kind, status="running", message="",
                       created=datetime.now(timezone.utc).isoformat(timespec="seconds"))
        f.create_dataset("scene", data=scene_toml, dtype=h5py.string_dtype())
        f.create_group("stats")
        series = f.create_group("series")
        t = series.create_dataset("time", shape=(0,), maxshape=(None,), chunks=(CHUNK_ROWS,), dtype="f8")
        t.attrs.update(unit="s", doc="Simulated time.")
        self._specs = {spec.name: spec for spec in outputs}
        for spec in outputs:
            d = series.create_dataset(spec.name, shape=(0, spec.size), maxshape=(None, spec.size),
                                      chunks=(CHUNK_ROWS, spec.size), dtype="f8")
            d.attrs.update(unit=spec.unit, doc=spec.doc)
        self._rows = 0
        self._layout = None
        if checkpoint is not None:
            self._layout = ckpt.Layout(tuple(checkpoint.fields) + (("rows", 1),))
            ckpt.create(f, self._layout)
        if _resume is not None:  # rows and checkpoint of the killed run, written before SWMR starts
            n = _resume["time"].size
            for name, data in [("time", _resume["time"]), *_resume["series"].items()]:
                d = series[name]
                d.resize((n, *d.shape[1:]))
                d[:] = data
            self._rows = n
            f.attrs.update(_resume["attrs"])
            ckpt.write(f, self._layout, _resume["seq"], _resume["values"])
        ends = np.cumsum([0] + [spec.size for spec in outputs]).tolist()
        self._columns = [(spec.name, a, b) for spec, a, b in zip(outputs, ends[:-1], ends[1:])]  # columns in a row
        self._scalars = [name for name, a, b in self._columns if b - a == 1]  # one-value series, set in one go
        self._scalar_cols = np.array([a for _, a, b in self._columns if b - a == 1], dtype=np.intp)
        self._vectors = [(name, a, b) for name, a, b in self._columns if b - a > 1]
        self._block = np.empty((CHUNK_ROWS, ends[-1]))  # rows buffered since the last flush, grown by doubling
        self._times = np.empty(CHUNK_ROWS)
        self._buffered = 0
        self._stats: dict[str, Any] = {}
        self._arrays: dict[str, tuple[np.ndarray, str, str]] = {}
        self._last_flush = time.monotonic()
        f.swmr_mode = True  # single-writer/multiple-reader: the file stays consistent if the writer dies

    @property
    def specs(self) -> list[OutputSpec]:
        """The recorded series."""
        return list(self._specs.values())

    @property
    def checkpoint_layout(self) -> tuple[tuple[str, int], ...]:
        """Checkpoint payload fields (``rows`` included), empty without checkpoints."""
        return self._layout.fields if self._layout is not None else ()

    @property
    def rows(self) -> int:
        """Rows on disk (appended rows still buffered are not counted)."""
        return self._rows

    def checkpoint(self, seq: int, values: Mapping[str, Any]) -> None:
        """Flush the rows, then store checkpoint ``seq`` (1, 2, ...) with the row count; on disk when it returns."""
        if self._layout is None:
            raise ValueError("this results file was created without checkpoint slots")
        self.flush()
        ckpt.write(self._file, self._layout, seq, {**values, "rows": self._rows})

    @classmethod
    def resume(cls, path: str | Path, flush_interval: float = 2.0, where: str = "--resume",
               scene_toml: str | None = None, extend: bool = False) -> tuple[ResultsWriter, int, dict[str, np.ndarray]]:
        """Reopen a killed run's file for appending from its newest checkpoint.

        Returns the writer (rows up to the checkpoint, later rows dropped: the run recomputes
        them), the checkpoint number and its payload (``rows`` included).  Refused with
        :class:`InputError` for a finished run (unless ``extend``: a run continued to a later end
        time), a file without checkpoint or not a run.  ``scene_toml`` replaces the stored scene (a
        resume with changed values).
        """
        path = Path(path)
        if not path.is_file():
            raise InputError(where, str(path), "must be an existing results file (.h5) of a killed run")
        lock = RunLock(path, where)
        try:
            return cls._resume(path, flush_interval, where, lock, scene_toml, extend)
        except BaseException:
            lock.release()
            raise

    @classmethod
    def _resume(cls, path: Path, flush_interval: float, where: str, lock: RunLock,
                scene_toml: str | None, extend: bool) -> tuple[ResultsWriter, int, dict[str, np.ndarray]]:
        with _reading(path, where) as f:
            attrs, group = _checked(f, path, where)
            if attrs.get("kind") != "run":
                raise InputError(where, str(path), f"must be the results file of `cvtfem run` (kind is "
                                 f"{attrs.get('kind')!r})")
            if attrs.get("status") == "finished" and not extend:
                t = group["time"]
                last = f"{t[-1]:.6g} s" if t.shape[0] else "its end"
                raise InputError(where, str(path), f"must be an unfinished run: this one finished (t = {last})",
                                 "to continue it to a later end time add `--until T`; results are never "
                                 "overwritten otherwise")
            latest = ckpt.read_latest(f)
            if latest is None:
                raise InputError(where, str(path), "must hold a checkpoint: this run wrote none",
                                 "set `output.checkpoint_interval` > 0 (simulated seconds) in the scene; a run "
                                 "without checkpoints can only be started again")
            seq, values = latest
            layout = ckpt.Layout.from_attrs(f[ckpt.GROUP]["slots"].attrs)
            rows = int(values["rows"][0])
            if min(d.shape[0] for d in group.values()) < rows:
                raise InputError(where, str(path), f"is inconsistent: checkpoint {seq} counts {rows} rows, the "
                                 "series hold fewer")
            specs = [OutputSpec(name, str(d.attrs.get("unit", "")), str(d.attrs.get("doc", "")), d.shape[1])
                     for name, d in group.items() if name != "time"]
            texts = [n for n, _ in layout.fields] + [t for sp in specs for t in (sp.name, sp.unit, sp.doc)]
            if not all(_is_utf8(t) for t in texts):   # h5py hands damaged bytes over as surrogates
                raise InputError(where, str(path), "is damaged: a series or checkpoint name, unit or description "
                                 "stored in it is not UTF-8 text")
            kept = {name: d[:rows] for name, d in group.items()}
            bad = next((name for name, a in kept.items() if not np.isfinite(a).all()), None)
            if bad is not None:   # the writer never stores one: the file is damaged
                raise InputError(where, str(path), f"is damaged: `/series/{bad}` holds non-finite values in the "
                                 f"{rows} rows up to checkpoint {seq}")
            resume = {"time": kept["time"], "series": {s.name: kept[s.name] for s in specs},
                      "attrs": {"created": attrs.get("created", ""), "resumed": int(attrs.get("resumed", 0)) + 1},
                      "seq": seq, "values": values}
            scene_toml = _scene_text(f, path, where) if scene_toml is None else scene_toml
        fields = tuple(fd for fd in layout.fields if fd[0] != "rows")
        tmp = path.with_name(path.name + ".resume-tmp")
        writer = cls(tmp, scene_toml, "run", specs, flush_interval, overwrite=True, checkpoint=ckpt.Layout(fields),
                     _resume=resume, _lock=lock)
        os.replace(tmp, path)  # the open file follows the rename
        writer.path = path
        return writer, seq, values

    def append(self, t: float, values: Mapping[str, Any]) -> None:
        """Record one output sample at time ``t`` (s) in the in-memory block (a scalar per one-value series,
        an array of the series' size otherwise); flushes when due."""
        i = self._buffered
        if i == self._times.size:
            self._block = np.concatenate([self._block, np.empty_like(self._block)])
            self._times = np.concatenate([self._times, np.empty_like(self._times)])
        row = self._block[i]
        try:
            row[self._scalar_cols] = [values[name] for name in self._scalars]
        except (TypeError, ValueError) as err:
            raise ValueError(f"outputs {self._scalars} must be one number each ({err})") from None
        for name, a, b in self._vectors:
            value = values[name]
            if np.size(value) != b - a:
                raise ValueError(f"output {name!r} has {np.size(value)} values, its series {b - a}")
            row[a:b] = value
        self._times[i] = t
        self._buffered = i + 1
        if time.monotonic() - self._last_flush >= self.flush_interval:
            self.flush()

    def flush(self) -> None:
        """Write buffered rows and make them visible to readers.

        A row holding a non-finite value is not written, nor any after it: :class:`NumericalError` names the
        first such output and its time (the rows before it are on disk).
        """
        n_new = self._buffered
        finite = np.isfinite(self._block[:n_new]).all(axis=1) & np.isfinite(self._times[:n_new])
        bad = None if finite.all() else int(np.argmin(finite))
        if bad is not None:
            n_new = bad
        if n_new:
            series = self._file["series"]
            end = self._rows + n_new
            for name, a, b in self._columns:
                d = series[name]
                d.resize((end, b - a))
                d[self._rows:end] = self._block[:n_new, a:b]
                d.flush()
            times = series["time"]
            times.resize((end,))
            times[self._rows:end] = self._times[:n_new]
            times.flush()
            self._rows = end
        self._buffered = 0
        self._file.flush()
        self._last_flush = time.monotonic()
        if bad is not None:
            row, t = self._block[bad], float(self._times[bad])
            name = next((name for name, a, b in self._columns if not np.isfinite(row[a:b]).all()), "time")
            raise NumericalError(f"output `{name}` became non-finite (that row and later ones are not written)",
                                 t=t, component="results file")

    def set_stats(self, stats: Mapping[str, Any]) -> None:
        """Solver statistics (numbers or strings), stored as ``/stats`` attributes at close."""
        self._stats.update({k: v for k, v in stats.items() if v is not None})

    def add_array(self, name: str, data: Any, unit: str = "", doc: str = "") -> None:
        """A whole array (mode shapes, a Campbell table), stored at close."""
        self._arrays[name] = (np.asarray(data), unit, doc)

    def close(self, status: str = "finished", message: str = "") -> None:
        """Flush, then record statistics, arrays and the final status ("finished" or "failed")."""
        if not self._file.id.valid:
            return
        failure = None
        try:
            try:
                self.flush()
            except NumericalError as err:
                failure, status, message = err, "failed", str(err)
            self._file.close()
            with h5py.File(self.path, "r+", libver="latest") as f:
                f.attrs.update(status=status, message=message)
                f["stats"].attrs.update(self._stats)
                for name, (data, unit, doc) in self._arrays.items():
                    d = f.create_dataset(name, data=data)
                    d.attrs.update(unit=unit, doc=doc)
        finally:
            self._lock.release()
        if failure is not None:
            raise failure

    def __enter__(self) -> ResultsWriter:
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if exc is None:
            self.close()
        else:
            self.close("failed", f"{type(exc).__name__}: {exc}")


@dataclass(frozen=True)
class Results:
    """A results file read back: plain arrays with names and units."""

    path: Path
    attrs: dict[str, Any]
    scene_toml: str
    stats: dict[str, Any]
    time: np.ndarray
    series: dict[str, np.ndarray] = field(repr=False)
    units: dict[str, str] = field(repr=False)


#: First 8 bytes of every HDF5 file.
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


@contextmanager
def _reading(path: Path, where: str) -> Iterator[h5py.File]:
    """An open results file (read-only, SWMR) for the ``with`` body; whatever HDF5 raises on damaged metadata or
    data there (OSError, RuntimeError, KeyError, TypeError, ValueError from h5py) becomes one :class:`InputError` line.

    A truncated file (a partial copy, a full disk) is refused before HDF5 opens it: HDF5's SWMR reader
    retries metadata reads of a missing region without end, so reading one would hang.  The check reads the
    end-of-file address of the version 2/3 superblock that the writer creates (``libver="latest"``).
    """
    if not path.is_file():
        raise InputError(where, str(path), "must be an existing results file (.h5)")
    try:
        with open(path, "rb") as raw:
            head = raw.read(44)
            size = os.fstat(raw.fileno()).st_size
    except OSError as err:
        raise InputError(where, str(path), f"must be a readable file ({err.strerror})") from None
    if head[:8] == HDF5_SIGNATURE and len(head) == 44 and head[8] in (2, 3) and head[9] == 8:
        base, _, eof = struct.unpack("<QQQ", head[12:36])
        if size < base + eof:
            raise InputError(where, str(path), f"is truncated: HDF5 says {base + eof} bytes, the file has {size} "
                             "(a partial copy or a full disk?)")
    try:
        with _open_swmr(path) as f:
            yield f
    except InputError:
        raise
    except (OSError, RuntimeError, KeyError, TypeError, ValueError) as err:
        text = " ".join(str(err).split()) or type(err).__name__
        raise InputError(where, str(path), f"must be a readable HDF5 results file (damaged: {text})") from None


#: Metadata read attempts of a SWMR reader: HDF5's default of 100 retried a file with damaged metadata for more
#: than 10 minutes (the fuzz of `show`); 10 end in ~0.02 s and leave a live writer's torn reads 9 retries.
READ_ATTEMPTS = 10


@functools.cache
def _hdf5_library() -> ctypes.CDLL | None:
    """The HDF5 library h5py runs on, for the one setting h5py does not offer (None where it is not found)."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        return None
    names = {line.split()[-1] for line in maps.splitlines() if "/libhdf5" in line and "libhdf5_hl" not in line}
    if len(names) != 1:
        return None
    lib = ctypes.CDLL(names.pop())
    if not hasattr(lib, "H5Pset_metadata_read_attempts"):
        return None
    lib.H5Pset_metadata_read_attempts.argtypes = [ctypes.c_int64, ctypes.c_uint]
    return lib


def _open_swmr(path: Path) -> h5py.File:
    """``h5py.File(path, "r", libver="latest", swmr=True, locking=False)`` with at most :data:`READ_ATTEMPTS`
    metadata read attempts."""
    fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
    fapl.set_libver_bounds(h5py.h5f.LIBVER_LATEST, h5py.h5f.LIBVER_LATEST)
    fapl.set_file_locking(False, True)
    lib = _hdf5_library()
    if lib is not None:
        lib.H5Pset_metadata_read_attempts(fapl.id, READ_ATTEMPTS)
    return h5py.File(h5py.h5f.open(os.fsencode(path), h5py.h5f.ACC_RDONLY | h5py.h5f.ACC_SWMR_READ, fapl=fapl))


#: Root attributes of a results file that hold text.
TEXT_ATTRS = ("cvtfem_version", "kind", "status", "message", "created")


def _checked(f: h5py.File, path: Path, where: str) -> tuple[dict[str, Any], h5py.Group]:
    """Root attributes and ``/series`` of an open results file, once its structure is that of one: text
    attributes, groups ``/series`` (a 1-D float ``time``, 2-D float arrays) and ``/stats``, a ``/scene``."""
    def refuse(what: str) -> InputError:
        return InputError(where, str(path), f"must be a cvtfem results file ({what})")

    missing = [name for name in ("series", "scene", "stats") if name not in f]
    if missing:
        raise refuse(f"it has no {', '.join(missing)}")
    attrs = dict(f.attrs)
    for key in TEXT_ATTRS:
        if key in attrs and not (isinstance(attrs[key], str) and _utf8(attrs[key])):
            raise refuse(f"its attribute `{key}` is not UTF-8 text")
    group = f["series"]
    if not isinstance(group, h5py.Group) or not isinstance(f["stats"], h5py.Group):
        raise refuse("`/series` and `/stats` must be groups")
    if "time" not in group:
        raise refuse("it has no `/series/time`")
    for name, d in group.items():
        ndim = 1 if name == "time" else 2
        if not isinstance(d, h5py.Dataset) or d.ndim != ndim or d.dtype.kind != "f":
            raise refuse(f"`/series/{name}` is not a {ndim}-D float array")
        texts = [name] + [d.attrs[key] for key in ("unit", "doc") if key in d.attrs]
        if not all(isinstance(text, str) and _utf8(text) for text in texts):
            raise refuse(f"the name, unit or doc of `/series/{name!r}` is not UTF-8 text")
    return attrs, group


def _utf8(text: str) -> bool:
    """False for a string h5py decoded from invalid UTF-8 (it maps the bad bytes to surrogates)."""
    try:
        text.encode()
    except UnicodeEncodeError:
        return False
    return True


def _is_utf8(text: str) -> bool:
    """True if ``text`` encodes as UTF-8 (a string read from damaged bytes carries lone surrogates)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def _scene_text(f: h5py.File, path: Path, where: str) -> str:
    """The scene TOML stored in an open results file."""
    d = f.get("scene")
    if not isinstance(d, h5py.Dataset) or d.shape != () or d.dtype.kind not in "OSU":
        raise InputError(where, str(path), "must be a cvtfem results file (its `/scene` is not a text)")
    text = d[()]
    try:
        return text.decode() if isinstance(text, bytes) else str(text)
    except UnicodeDecodeError:
        raise InputError(where, str(path), "must be a cvtfem results file (its `/scene` is not UTF-8)") from None


def read_scene_toml(path: str | Path, where: str = "RESULTS") -> str:
    """The scene TOML stored in a results file (nothing else is read)."""
    path = Path(path)
    with _reading(path, where) as f:
        return _scene_text(f, path, where)


def read_checkpoint(path: str | Path, where: str = "--resume") -> dict[str, np.ndarray] | None:
    """The payload of the newest intact checkpoint of a results file (``t``, ``t_end``, ...), None without one;
    the file is only read."""
    path = Path(path)
    with _reading(path, where) as f:
        latest = ckpt.read_latest(f)
        return None if latest is None else latest[1]


def read_results(path: str | Path) -> Results:
    """Read a results file (also one whose run was killed: complete rows only)."""
    path = Path(path)
    with _reading(path, "RESULTS") as f:
        attrs, group = _checked(f, path, "RESULTS")
        rows = min(d.shape[0] for d in group.values())
        series = {name: d[:rows] for name, d in group.items() if name != "time"}
        units = {name: str(d.attrs.get("unit", "")) for name, d in group.items()}
        return Results(path=path, attrs=attrs, scene_toml=_scene_text(f, path, "RESULTS"),
                       stats=dict(f["stats"].attrs), time=group["time"][:rows], series=series, units=units)


def read_first_row(path: str | Path, names: Sequence[str], where: str = "RESULTS") -> dict[str, np.ndarray] | None:
    """The first stored row of each series ``names`` (the file is only read), None when the file lacks one of
    them or holds no row."""
    path = Path(path)
    with _reading(path, where) as f:
        _, group = _checked(f, path, where)
        if any(name not in group or group[name].shape[0] == 0 for name in names):
            return None
        return {name: np.array(group[name][0]) for name in names}

