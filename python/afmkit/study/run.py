"""Running a study: serially, on a local Dask cluster (one worker process per core), or on an existing cluster.

The grid is cut into chunks of about `chunk_seconds` of computation (measured on a pilot point); each chunk is
computed in C++ in one call (`_afmkit.evaluate_points`) and written to its own part of the Zarr store, then marked
done. Running the same study on the same store again computes only the chunks not marked done.
"""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from . import store as zstore
from .definition import Study, StudyError, parameters_of


def _points(study: Study, slices: tuple) -> np.ndarray:
    """The points of one chunk as rows (C order), columns = axes."""
    grids = np.meshgrid(*[np.asarray(a.values)[s] for a, s in zip(study.axes, slices)], indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1) if grids else np.zeros((1, 0))


def compute_chunk(store_path: str, definition: dict, index: int):
    """Computes chunk `index` of the study `definition` into the store (in a Dask worker or in-process)."""
    import zarr

    from .. import _afmkit

    study = Study.make(definition["computation"], {n: v for n, v in definition["axes"]}, definition["outputs"],
                       definition["parameters"])
    root = zarr.open_group(store_path, mode="r+")
    names = zstore.output_names(study.outputs)
    chunks = tuple(root[names[0]].chunks)
    slices = zstore.chunk_slices(study.shape, chunks, index)
    start = time.perf_counter()
    values, failed = _afmkit.evaluate_points(study.command, dict(study.parameters), [a.name for a in study.axes],
                                             _points(study, slices), list(study.outputs))
    seconds = time.perf_counter() - start
    block_shape = tuple(s.stop - s.start for s in slices)
    for k, name in enumerate(names):
        root[name][slices] = values[:, k].reshape(block_shape)
    root["chunk_failed"][index] = failed
    root["chunk_done"][index] = 1  # last: a chunk is done only when all of it is written
    return index, int(failed), seconds


class _Progress:
    """A line at most once per second on standard error: chunks done, points, elapsed, estimate."""

    def __init__(self, total: int, points_per_chunk: int, points: int, enabled: bool):
        self.total, self.ppc, self.points, self.enabled = total, points_per_chunk, points, enabled
        self.done, self.started, self.last, self.shown = 0, time.monotonic(), 0.0, -1

    def step(self, final: bool = False) -> None:
        if not self.enabled or (final and self.shown == self.done):
            return
        now = time.monotonic()
        if not final and now - self.last < 1.0:
            return
        self.last, self.shown = now, self.done
        elapsed = now - self.started
        left = elapsed / self.done * (self.total - self.done) if self.done else math.nan
        eta = f", about {left:.0f} s left" if 0 < self.done < self.total else ""
        print(f"afmkit study: {self.done}/{self.total} chunks (~{min(self.done * self.ppc, self.points)} points), "
              f"{elapsed:.1f} s{eta}", file=sys.stderr, flush=True)


def _pilot(study: Study, measure: bool = True):
    """Runs the first point: checks parameters and outputs, finds the units, and (measure) the cost of a point."""
    from .. import _afmkit

    params = parameters_of(study.command)
    first = {a.name: int(a.values[0]) if params[a.name]["kind"] == "integer" else a.values[0] for a in study.axes}
    _afmkit.run(study.command, {**study.parameters, **first})  # the parameters checked, errors naming them
    # the first ≤ 64 points of the grid, for up to 0.3 s (only the first when the cost is not wanted): checks
    # the output selectors and measures the cost of a point
    points = _points(study, zstore.chunk_slices(study.shape, zstore.chunk_shape(study.shape, 64 if measure else 1), 0))
    start = time.perf_counter()
    n = 0
    while n < len(points):
        _afmkit.evaluate_points(study.command, dict(study.parameters), [a.name for a in study.axes],
                                points[n:n + 1], list(study.outputs))
        n += 1
        if time.perf_counter() - start > 0.3:
            break
    cost = (time.perf_counter() - start) / n
    # the unit of each output as the selector resolves it (docs/study.md#outputs): count, a column's unit, or the
    # command's "units" entry for a results path
    out_units = list(_afmkit.output_units(study.command, dict(study.parameters), [a.name for a in study.axes],
                                          points[:n], list(study.outputs)))
    return cost, out_units


def _client(scheduler, workers: int | None):
    """A distributed.Client: given, at an address (checked within a few seconds), or a new LocalCluster."""
    import distributed

    if isinstance(scheduler, distributed.Client):
        return scheduler, None
    if scheduler in (None, "local"):
        n = workers or os.cpu_count() or 1
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                           host="127.0.0.1",
                                           env={"OMP_NUM_THREADS": "1"})
        return distributed.Client(cluster), cluster
    if not isinstance(scheduler, str) or "://" not in scheduler:
        raise StudyError("scheduler", f"scheduler = {scheduler!r} is not allowed: must be 'serial', 'local', an "
                                      f"address such as tcp://host:8786, or a distributed.Client")
    try:
        return distributed.Client(scheduler, timeout="5s"), None
    except (OSError, TimeoutError) as e:
        raise StudyError("scheduler", f"scheduler '{scheduler}' does not answer within 5 s: {e}") from None


def run(study: Study, store, *, scheduler=None, workers: int | None = None, chunk_seconds: float = 1.0,
        chunk_points: int | None = None, progress: bool | str = True, netcdf=None):
    """Computes `study` into the Zarr store `store` and returns its results as an xarray Dataset.

    scheduler: "serial" (this process), None or "local" (a LocalCluster, `workers` processes, default one per
    core), an address "tcp://host:8786" of a running Dask scheduler, or a distributed.Client. chunk_seconds: the
    computation per chunk (measured on a pilot point), or chunk_points points per chunk. progress: True (a line
    per second on standard error), False, or "dask" (Dask's progress bar: a widget in a notebook, a text bar in a
    terminal; lines when serial). A store that exists must
    hold this study (resumed: only chunks not done are computed); netcdf: also write the results there.
    """
    import xarray as xr

    from .. import __version__

    if chunk_points is not None and (not isinstance(chunk_points, int) or isinstance(chunk_points, bool)
                                     or chunk_points < 1):
        raise StudyError("chunk_points", f"chunk_points = {chunk_points!r} is out of range: must be an integer >= 1")
    if not (isinstance(chunk_seconds, (int, float)) and math.isfinite(chunk_seconds) and chunk_seconds > 0):
        raise StudyError("chunk_seconds", f"chunk_seconds = {chunk_seconds!r} is out of range: must be > 0 and "
                                          f"finite")
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise StudyError("workers", f"workers = {workers!r} is out of range: must be an integer >= 1")
    if progress not in (True, False, "dask"):
        raise StudyError("progress", f"progress = {progress!r} is not allowed: must be True, False or 'dask'")
    path = Path(store)
    if path.exists():
        root, chunks = zstore.open_existing(path, study)
    else:
        if not path.parent.is_dir():
            raise StudyError("store", f"store '{path}': folder '{path.parent}' does not exist")
        cost, units = _pilot(study, measure=chunk_points is None)
        target = chunk_points or max(1, round(chunk_seconds / max(cost, 1e-9)))
        chunks = zstore.chunk_shape(study.shape, target)
        zstore.create(path, study, chunks, units, __version__)
        root, chunks = zstore.open_existing(path, study)
    done = root["chunk_done"][:]
    pending = [int(i) for i in np.flatnonzero(done == 0)]
    total = len(done)
    bar = _Progress(total, int(np.prod(chunks)), study.size, progress is True or
                    (progress == "dask" and scheduler == "serial"))
    bar.done = total - len(pending)
    definition = study.definition()
    if pending:
        if scheduler == "serial":
            for i in pending:
                compute_chunk(str(path), definition, i)
                bar.done += 1
                bar.step()
        else:
            _run_dask(study, path, definition, pending, scheduler, workers, bar, dask_bar=progress == "dask")
    bar.step(final=True)
    failed = int(root["chunk_failed"][:].sum())  # read here: not a Dask computation on the study's cluster
    ds = xr.open_zarr(str(path), consolidated=True)
    ds = ds.drop_vars(["chunk_done", "chunk_failed"])
    ds.attrs["failed_points"] = failed
    if netcdf is not None:
        out = Path(netcdf)
        tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
        try:
            ds.load().to_netcdf(tmp)
            os.replace(tmp, out)
        finally:
            tmp.unlink(missing_ok=True)
    return ds


def _run_dask(study, path, definition, pending, scheduler, workers, bar, dask_bar=False) -> None:
    import distributed

    client, cluster = _client(scheduler, workers)
    try:
        key = f"afmkit-study-{study.fingerprint()[:12]}"
        futures = [client.submit(compute_chunk, str(path.resolve()), definition, i, key=f"{key}-{i}", pure=False,
                                 retries=3) for i in pending]
        try:
            if dask_bar:
                distributed.progress(futures)  # a notebook widget (returns at once), or a text bar until done
            for f in distributed.as_completed(futures):
                f.result()  # a chunk that failed (not a lost worker: those are retried) stops the study
                bar.done += 1
                bar.step()
        except BaseException:
            client.cancel(futures)
            raise
    finally:
        if cluster is not None:
            client.close()
            cluster.close()
