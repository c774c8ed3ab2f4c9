"""Parameter sweeps: variants of a scene (a grid of ``--vary`` axes and/or a list file, each applied with
:meth:`Scene.replace`), each an independent run of one analysis (a pure function of the variant's scene),
on a local process pool or a dask.distributed cluster, into one folder with an index file.

The index (``index.json``, rewritten atomically after each variant) maps variant id -> parameters ->
results file -> status -> summary numbers.  A variant's id is a hash of its parameters, so running the
same command again skips finished variants (resume) and a larger grid adds only the new points (extend).
"""
from __future__ import annotations

import csv
import hashlib
import itertools
import json
import math
import os
import time
import tomllib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cvtfem.errors import CvtfemError, InputError

ANALYSES = ("run", "modes", "campbell", "periodic")
ENGINES = ("local", "dask")
INDEX = "index.json"
FORMAT = "cvtfem-sweep 1"
#: Attempts after the first for a variant whose worker died or that raised an unexpected exception.
RETRIES = 2
#: Most variants one sweep expands to (a typo like `0:1:1e6` should not fill a disk).
MAX_VARIANTS = 100_000
#: Seconds to wait for an external dask scheduler, by default.
CONNECT_TIMEOUT = 10.0


@dataclass(frozen=True)
class Variant:
    """One point of a sweep: its id and its parameters (dotted scene key -> value)."""

    id: str
    params: dict[str, Any]


def _scalar(text: str) -> Any:
    """A TOML scalar from a command-line token: integer, float, boolean, else a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_vary(text: str) -> tuple[str, list[Any]]:
    """``KEY=a:b:n`` (``n`` evenly spaced numbers from a to b) or ``KEY=v1,v2,...`` -> ``(KEY, values)``."""
    key, sep, spec = text.partition("=")
    key = key.strip()
    parts = key.split(".")
    if not sep or not spec.strip() or not all(p.strip() for p in parts):
        raise InputError("--vary", text, "must be KEY=START:STOP:COUNT or KEY=V1,V2,... with a dotted scene key, "
                         "e.g. cvt.regime.torque=50:250:5")
    if ":" in spec:
        try:
            a, b, n = spec.split(":")
            start, stop, count = float(a), float(b), int(n)
        except ValueError:
            raise InputError("--vary", text, "must give START:STOP:COUNT as two numbers and a whole count") from None
        if not (math.isfinite(start) and math.isfinite(stop) and 1 <= count <= MAX_VARIANTS):
            raise InputError("--vary", text, f"needs finite START, STOP and 1 <= COUNT <= {MAX_VARIANTS}")
        values = np.linspace(start, stop, count)
        integral = all(_is_int(t) for t in (a, b)) and np.all(values == np.round(values))
        return key, [int(v) if integral else float(v) for v in values]
    return key, [_scalar(v.strip()) for v in spec.split(",")]


def _is_int(token: str) -> bool:
    try:
        int(token)
    except ValueError:
        return False
    return True


def read_list(path: str | Path) -> list[dict[str, Any]]:
    """Variants from a file: CSV (a header of dotted keys, one row per variant) or TOML (``[[variant]]`` tables
    of dotted keys)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise InputError("--list", str(path), f"must be a readable UTF-8 file ({err})") from None
    if path.suffix == ".toml":
        try:
            rows = tomllib.loads(text).get("variant")
        except tomllib.TOMLDecodeError as err:
            raise InputError("--list", str(path), f"must be valid TOML: {err}") from None
        if not isinstance(rows, list) or not rows:
            raise InputError("--list", str(path), "must hold [[variant]] tables of dotted keys")
        return [_flatten(r) for r in rows]
    if path.suffix != ".csv":
        raise InputError("--list", str(path), "must be a .csv or .toml file")
    rows = list(csv.DictReader(text.splitlines()))
    if not rows or any(None in r or None in r.values() for r in rows):   # extra or missing cells
        raise InputError("--list", str(path), "must be a CSV file with a header of dotted keys and one complete "
                         "row per variant")
    return [{k.strip(): _scalar(v.strip()) for k, v in row.items()} for row in rows]


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in table.items():
        if isinstance(v, Mapping):
            out.update(_flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def nested(params: Mapping[str, Any]) -> dict[str, Any]:
    """Dotted keys -> the nested overrides :meth:`Scene.replace` takes."""
    out: dict[str, Any] = {}
    for key, value in params.items():
        node = out
        *path, last = key.split(".")
        for part in path:
            node = node.setdefault(part, {})
        node[last] = value
    return out


def variant_id(params: Mapping[str, Any]) -> str:
    """A short, stable id of a parameter set (the same parameters give the same id in every sweep)."""
    text = json.dumps(params, sort_keys=True, separators=(",", ":"))
    return "v" + hashlib.sha1(text.encode()).hexdigest()[:10]


def expand(varies: list[tuple[str, list[Any]]], rows: list[dict[str, Any]] | None = None) -> list[Variant]:
    """The variants: every list row (or one empty row) combined with every point of the grid of ``varies``."""
    keys = [k for k, _ in varies]
    if len(set(keys)) < len(keys):
        raise InputError("--vary", keys, "must name each key once")
    total = len(rows or [{}]) * math.prod(len(v) for _, v in varies)
    if total > MAX_VARIANTS:
        raise InputError("--vary", total, f"must give at most {MAX_VARIANTS} variants")
    out = []
    for row in rows or [{}]:
        for point in itertools.product(*(v for _, v in varies)):
            params = {**row, **dict(zip(keys, point))}
            out.append(Variant(variant_id(params), params))
    return list({v.id: v for v in out}.values())   # a repeated point runs once


def variant_scenes(scene, variants: list[Variant]) -> dict[str, str]:
    """Each variant's full scene as TOML, validated here (an unknown key fails before any work starts)."""
    return {v.id: scene.replace(nested(v.params)).to_toml() for v in variants}


# -- the work of one variant (runs in a worker process) ------------------------------------------------------

def run_variant(analysis: str, scene_toml: str, source: str, results: str | None,
                options: Mapping[str, Any]) -> dict[str, Any]:
    """Run one variant; a pure function of its scene.  Returns ``{"status", "summary", "error", "wall_s"}``:
    an expected failure (:class:`CvtfemError`: bad input, numerical failure) is a "failed" record, not
    an exception (it would fail again on a retry); anything else propagates and the engine retries."""
    from threadpoolctl import threadpool_limits

    from cvtfem.scene.loader import _parse, scene_from_dict

    t0 = time.perf_counter()
    try:
        with threadpool_limits(1):   # one thread per worker: no oversubscription, same bits on every engine
            scene = scene_from_dict(_parse(scene_toml, source), source=source)
            summary = _ANALYSES[analysis](scene, results, options)
    except CvtfemError as err:
        return {"status": "failed", "summary": {}, "error": str(err), "wall_s": time.perf_counter() - t0}
    return {"status": "finished", "summary": summary, "error": "", "wall_s": time.perf_counter() - t0}


def _run(scene, results: str | None, options: Mapping[str, Any]) -> dict[str, Any]:
    from cvtfem.analysis.run import run_scene

    s = run_scene(scene, until=options.get("until"), results=results, show_progress=False, overwrite=True)
    F1, F2 = s.clamping_force_N
    return {"ratio": s.ratio, "efficiency": s.efficiency, "efficiency_kinetic": s.efficiency_kinetic,
            "F1_N": F1, "F2_N": F2, "F1_F2": F1 / F2, "input_speed_rpm": s.input_speed_rpm,
            "output_speed_rpm": s.output_speed_rpm, "slip1_m_s": s.slip_speed_m_s[0],
            "slip2_m_s": s.slip_speed_m_s[1], "steps": s.solver["steps"], "nfev": s.solver["nfev"]}


def _rotor_problem(scene):
    from cvtfem.machines.rotor import build_model
    from cvtfem.modal import ModalProblem

    if scene.kind != "rotor":
        raise InputError("SCENE", scene.source, f"must be a rotor scene for this analysis, not {scene.kind!r}")
    m = build_model(scene)
    return ModalProblem(m.M, m.K, m.C, m.G, m.dof_kind), (scene.rotor.n_modes if scene.rotor else 12)


def _modes(scene, results: str | None, options: Mapping[str, Any]) -> dict[str, Any]:
    problem, n_modes = _rotor_problem(scene)
    modes = problem.solve(scene.rotor.speed if scene.rotor else 0.0, n_modes)
    _write_json(results, modes.to_dict())
    f, z = modes.wd / (2 * np.pi), modes.damping_ratio
    return {**{f"f{i}_Hz": float(f[i]) for i in range(len(f))}, **{f"zeta{i}": float(z[i]) for i in range(len(z))}}


def _campbell(scene, results: str | None, options: Mapping[str, Any]) -> dict[str, Any]:
    from cvtfem.modal import campbell, shaft_orders
    from cvtfem.units import parse_speeds

    problem, n_modes = _rotor_problem(scene)
    result = campbell(problem, parse_speeds(options["speeds"]), n_modes, shaft_orders((1.0,)))
    _write_json(results, result.to_dict())
    crit = sorted(c["speed_rad_s"] * 30 / math.pi for c in result.crossings)
    return {"n_critical": len(crit), "first_critical_rpm": crit[0] if crit else None}


def _periodic(scene, results: str | None, options: Mapping[str, Any]) -> dict[str, Any]:
    from cvtfem.machines.torsional import build, periodic_settings
    from cvtfem.periodic.response import response_sweep

    if scene.kind != "torsional":
        raise InputError("SCENE", scene.source, f"must describe a torsional network, not a {scene.kind}")
    cfg, net = periodic_settings(scene), build(scene)
    freqs = np.linspace(*cfg.sweep[:2], int(cfg.sweep[2])) if cfg.sweep else np.array([cfg.frequency])
    result = response_sweep(net, 2 * np.pi * freqs, cfg.harmonics, cfg.samples, cfg.tol, cfg.max_iter, cfg.backlash)
    _write_json(results, result.to_dict())
    nonlinear = np.flatnonzero(net.law != 0)
    probe = net.link_names.index(cfg.probe) if cfg.probe else int(nonlinear[0]) if nonlinear.size else 0
    peaks = result.peaks("nonlinear")[:, probe]
    k = int(np.argmax(peaks))
    return {"peak_moment_Nm": float(peaks[k]), "peak_frequency_Hz": float(freqs[k]),
            "converged": sum(s.converged for s in result.nonlinear), "frequencies": len(freqs)}


def _write_json(path: str | None, data: Mapping[str, Any]) -> None:
    if path is not None:
        _atomic_write(Path(path), json.dumps(data, allow_nan=True))


_ANALYSES: dict[str, Callable[..., dict[str, Any]]] = {
    "run": _run, "modes": _modes, "campbell": _campbell, "periodic": _periodic}


# -- engines: yield (variant id, record or exception) as variants finish ---------------------------------

Job = tuple[str, tuple]   # (variant id, arguments of the work function)


def _local(work: Callable, jobs: list[Job], workers: int, retries: int) -> Iterator[tuple[str, Any, int]]:
    """A concurrent.futures process pool with at most ``workers`` variants in flight; a dead worker breaks the
    pool: the variants in flight are charged one attempt and resubmitted to a new pool."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    queue, attempts = list(jobs), dict.fromkeys((vid for vid, _ in jobs), 0)
    while queue:
        with ProcessPoolExecutor(workers) as pool:
            flight: dict[Any, Job] = {}
            broken = False
            while (queue or flight) and not broken:
                while queue and len(flight) < workers:
                    job = queue.pop(0)
                    flight[pool.submit(work, *job[1])] = job
                done, _ = wait(flight, return_when=FIRST_COMPLETED)
                for fut in done:
                    job = flight.pop(fut)
                    attempts[job[0]] += 1
                    err = fut.exception()
                    if err is None:
                        yield job[0], fut.result(), attempts[job[0]]
                    else:   # a dead worker (BrokenProcessPool) or an unexpected exception: retried, then recorded
                        broken = broken or isinstance(err, BrokenProcessPool)
                        yield from _retry(job, err, attempts, retries, queue)
            for fut, job in flight.items():   # the pool broke: what was in flight did not finish
                attempts[job[0]] += 1
                yield from _retry(job, BrokenProcessPool("a worker process died"), attempts, retries, queue)


def _retry(job: Job, err: BaseException, attempts: dict[str, int], retries: int, queue: list[Job]):
    """Queue ``job`` again while it has retries left, else yield it with its error."""
    if attempts[job[0]] <= retries:
        queue.append(job)
    else:
        yield job[0], err, attempts[job[0]]


def _dask(work: Callable, jobs: list[Job], client, retries: int) -> Iterator[tuple[str, Any, int]]:
    """dask.distributed: a task raising is retried ``retries`` times by dask; a task whose worker dies is
    rescheduled by the scheduler (``distributed.scheduler.allowed-failures`` times, then KilledWorker)."""
    from uuid import uuid4

    from distributed import as_completed

    tag = uuid4().hex[:8]
    futures = {client.submit(work, *args, key=f"cvtfem-sweep-{vid}-{tag}", pure=False, retries=retries): vid
               for vid, args in jobs}
    for fut in as_completed(futures):
        vid = futures[fut]
        try:
            yield vid, fut.result(), 1
        except Exception as err:  # noqa: BLE001 - retries exhausted or KilledWorker: recorded
            yield vid, err, retries + 1
        fut.release()


def dask_client(workers: int | None, scheduler: str | None, timeout: float = CONNECT_TIMEOUT):
    """A dask Client: on a LocalCluster of ``workers`` single-threaded worker processes started here, or on
    the external scheduler at ``scheduler`` (InputError if it cannot be reached within ``timeout`` s)."""
    import logging

    from distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError, ValueError) as err:
            raise InputError("--scheduler", scheduler, "must be the address of a running dask scheduler "
                             f"(tcp://HOST:PORT) reachable within {timeout:g} s",
                             f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}") from None
    logging.getLogger("distributed").setLevel(logging.WARNING)   # no INFO chatter on the terminal
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=logging.ERROR)
    return Client(cluster)


# -- the sweep folder --------------------------------------------------------------------------------------

def _atomic_write(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def read_index(folder: str | Path) -> dict[str, Any]:
    """The index of a sweep folder (InputError if it holds none)."""
    path = Path(folder) / INDEX
    try:
        index = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as err:
        raise InputError("SWEEP_DIR", str(folder), f"must be a sweep folder with a readable {INDEX} ({err})") from None
    if index.get("format") != FORMAT:
        raise InputError("SWEEP_DIR", str(folder), f"must hold a {FORMAT!r} index, found {index.get('format')!r}")
    return index


def run_sweep(scene, variants: list[Variant], analysis: str, out: str | Path, engine: str = "local",
              workers: int | None = None, scheduler: str | None = None, options: Mapping[str, Any] | None = None,
              files: bool = True, retries: int = RETRIES, retry_failed: bool = False, show_progress: bool = True,
              connect_timeout: float = CONNECT_TIMEOUT,
              work: Callable[..., dict[str, Any]] = run_variant) -> dict[str, Any]:
    """Run the variants not yet finished in folder ``out`` and return the index.

    Parameters
    ----------
    scene : Scene
        The base scene; each variant is ``scene.replace(params)``.
    analysis : str
        One of :data:`ANALYSES`; ``options`` holds its settings (``until`` s for "run", ``speeds`` for "campbell").
    engine : str
        "local" (a process pool of ``workers``, default the CPU count) or "dask" (a LocalCluster of ``workers``,
        or the scheduler at address ``scheduler``, waited for ``connect_timeout`` s).
    files : bool
        Keep each variant's results file (``variants/<id>.h5`` or ``.json``); False keeps only the summaries
        in the index (a cluster whose workers do not share the folder).
    retry_failed : bool
        Rerun the variants that failed (numerical or input failure) in an earlier sweep into this folder.
    work : callable
        The work function, :func:`run_variant` (tests wrap it).
    """
    from cvtfem.io.progress import progress
    from cvtfem.io.results import RunLock

    if analysis not in ANALYSES:
        raise InputError("--analysis", analysis, f"must be one of {', '.join(ANALYSES)}")
    if engine not in ENGINES:
        raise InputError("--engine", engine, f"must be one of {', '.join(ENGINES)}")
    if workers is not None and not 1 <= workers <= 1024:
        raise InputError("--workers", workers, "must be a whole number in 1..1024")
    if scheduler and engine != "dask":
        raise InputError("--scheduler", scheduler, "needs --engine dask")
    options = dict(options or {})
    if analysis == "campbell" and not options.get("speeds"):
        raise InputError("--speeds", None, "is required by --analysis campbell (START:STOP<unit>:COUNT)")
    scenes = variant_scenes(scene, variants)
    folder = Path(out).resolve()
    lock = RunLock(folder / INDEX, "--out")
    try:
        base = {"format": FORMAT, "scene": scene.source, "analysis": analysis, "options": options,
                "base_sha1": hashlib.sha1(scene.to_toml().encode()).hexdigest()}
        index = _open_index(folder, base)
        entries = {e["id"]: e for e in index["variants"]}
        ext = ".h5" if analysis == "run" else ".json"
        for v in variants:
            if v.id not in entries:
                entries[v.id] = {"id": v.id, "params": v.params, "results": f"variants/{v.id}{ext}" if files else "",
                                 "status": "pending", "attempts": 0, "wall_s": None, "error": "", "summary": {}}
                index["variants"].append(entries[v.id])
        done = ("finished",) if retry_failed else ("finished", "failed")
        todo = [v for v in variants if entries[v.id]["status"] not in done]
        jobs = [(v.id, (analysis, scenes[v.id], f"{scene.source} [{v.id}]",
                        str(folder / entries[v.id]["results"]) if files else None, options)) for v in todo]
        client = bar = None
        try:
            if engine == "dask" and jobs:   # connect first: an unreachable scheduler leaves the folder as it was
                client = dask_client(workers, scheduler, connect_timeout)
            if files:   # the folder itself exists: RunLock made it
                (folder / "variants").mkdir(exist_ok=True)
            _atomic_write(folder / INDEX, json.dumps(index, indent=1))
            bar = progress(len(jobs), "variant", f"sweep {analysis}") if show_progress else None
            if client is not None:
                outcomes = _dask(work, jobs, client, retries)
            else:
                outcomes = _local(work, jobs, workers or os.cpu_count() or 1, retries)
            for vid, outcome, attempts in outcomes:
                entry = entries[vid]
                entry["attempts"] += attempts
                if isinstance(outcome, BaseException):
                    entry.update(status="crashed", error=f"{type(outcome).__name__}: {outcome}")
                else:
                    entry.update(outcome)
                _atomic_write(folder / INDEX, json.dumps(index, indent=1))
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
            if client is not None:
                cluster = client.cluster
                client.close()
                if cluster is not None:
                    cluster.close()
    finally:
        lock.release()
    return index


def _open_index(folder: Path, base: dict[str, Any]) -> dict[str, Any]:
    """The folder's index (a new one if none); InputError if it holds a sweep of another scene or analysis."""
    if not (folder / INDEX).exists():
        return {**base, "variants": []}
    index = read_index(folder)
    for key in ("analysis", "options", "base_sha1"):
        if index.get(key) != base[key]:
            what = {"base_sha1": "base scene"}.get(key, key)
            raise InputError("--out", str(folder), f"must be a new folder or hold a sweep of the same base scene, "
                             f"analysis and options (its {what} differs)", "use another --out folder")
    return index
