"""Running a study: serially, on worker processes of this machine (one per core, when the study is long enough for
them to pay), or on a Dask cluster.

The grid is cut into chunks of about `chunk_seconds` of computation (measured on a pilot point); each chunk is
computed in C++ in one call (`_afmkit.evaluate_points`) and written to its own part of the Zarr store, then marked
done. Running the same study on the same store again computes only the chunks not marked done.
"""
from __future__ import annotations

import errno
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .._files import unique_temporary
from . import store as zstore
from .definition import Study, StudyError, parameters_of, require_memory


class StudyFailure(RuntimeError):
    """A study stopped by a failure that is not the caller's (an I/O error of the machine, a worker lost for good);
    `field` names what was being written. The command line's exit status 1 (StudyError, bad input: 2)."""

    def __init__(self, field_name: str, message: str):
        super().__init__(message)
        self.field = field_name


#: Write errors that come from where the caller asked to write (a full or read-only file system, no permission, a
#: folder that went away): bad input as for the commands (exit 2). Any other OSError is a failure (exit 1).
_CALLERS_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOENT, errno.ENOTDIR,
                   errno.EISDIR, errno.EEXIST, errno.ENAMETOOLONG, errno.ELOOP, errno.EFBIG, errno.ENOTEMPTY}


def write_error(field_name: str, target, e: OSError) -> Exception:
    """The StudyError (or StudyFailure) for OSError `e` while writing `target` (the store or the NetCDF file)."""
    inner = f" ({e.filename})" if e.filename and os.fspath(e.filename) != os.fspath(target) else ""
    message = f"{field_name} '{target}' cannot be written{inner}: {e.strerror or e}"
    if e.errno in _CALLERS_ERRNOS:
        return StudyError(field_name, message + (" (finished chunks are kept: run again to resume)"
                                                 if field_name == "store" else ""))
    return StudyFailure(field_name, message)


def _path(field_name: str, value) -> Path:
    """A path argument (str or os.PathLike): refused (naming the field) when it is another type, not encodable as a
    file name (a lone surrogate) or contains NUL."""
    if not isinstance(value, (str, bytes, os.PathLike)):
        raise StudyError(field_name, f"{field_name} = {value!r} is not allowed: must be a path (str or os.PathLike), "
                                     f"not {type(value).__name__}")
    text = os.fspath(value)
    try:
        raw = os.fsencode(text)
    except UnicodeEncodeError:
        raise StudyError(field_name, f"{field_name} = {text!r} is not valid text: it cannot be encoded as a file "
                                     f"name") from None
    if b"\0" in raw:
        raise StudyError(field_name, f"{field_name} contains a NUL character: must be a path")
    return Path(os.fsdecode(raw))


def _writable_folder(field_name: str, target: Path) -> None:
    """The folder `target` goes to exists and can be written, or can be created (its nearest existing ancestor is a
    writable folder; the missing folders are made when the study writes): a temporary file is created and removed."""
    folder = target.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise StudyError(field_name, f"{field_name} '{target}': '{folder}' is not a folder, so the folder of "
                                     f"'{target.name}' cannot be created")
    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".afmkit-write-test-"):
            pass
    except OSError as e:
        raise StudyError(field_name, f"{field_name} '{target}': folder '{folder}' cannot be written: "
                                     f"{e.strerror or e}") from None


def check_store(store) -> Path:
    """The store's path, checked before anything runs: a folder (an existing one is opened later, a new one is
    created in a writable folder), never a file."""
    path = _path("store", store)
    if path.exists() and not path.is_dir():
        raise StudyError("store", f"store '{path}' exists and is not a folder: a store is a folder (choose another "
                                  f"path)")
    if str(path) in ("", ".") or path.name in ("", ".", ".."):
        raise StudyError("store", f"store = '{path}': must name the store's own folder (e.g. out/study.zarr)")
    if not path.exists():
        _writable_folder("store", path)
    return path


def check_netcdf(netcdf) -> Path:
    """The NetCDF file's path, checked before anything runs: names a file in a writable folder."""
    path = _path("netcdf", netcdf)
    if str(path) in ("", ".") or path.name in ("", ".", ".."):
        raise StudyError("netcdf", f"netcdf = '{os.fspath(netcdf)}': must name a file (e.g. out/study.nc)")
    if path.is_dir():
        raise StudyError("netcdf", f"netcdf '{path}' is a folder: must name a file")
    _writable_folder("netcdf", path)
    return path


def check_scheduler(scheduler) -> None:
    """serial, local (or None), an address scheme://host[:port], or a distributed.Client."""
    if scheduler is None or (isinstance(scheduler, str) and (
            scheduler in ("serial", "local") or (0 < scheduler.find("://") < len(scheduler) - 3))):
        return
    try:
        import distributed

        if isinstance(scheduler, distributed.Client):
            return
    except ImportError:
        pass
    raise StudyError("scheduler", f"scheduler = {scheduler!r} is not allowed: must be 'serial', 'local', an address "
                                  f"such as tcp://host:8786, or a distributed.Client")


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
    try:
        root = zarr.open_group(store_path, mode="r+")
    except ValueError as e:  # removed or replaced while the study runs (Zarr's own text can be a bare template)
        raise StudyError("store", f"store '{store_path}' is no longer a study store ({type(e).__name__}): it was "
                                  f"removed or replaced while the study ran") from None
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
    """Runs the first point: checks parameters and outputs, finds the units, and (measure) the cost of a point:
    (wall s per point, the outputs' units, CPU s per point). The CPU time decides whether local workers pay (the
    machine's load does not make a short study look long)."""
    from .. import _afmkit
    from .._commands import Result

    params = parameters_of(study.command)
    first = {a.name: int(a.values[0]) if params[a.name]["kind"] == "integer" else a.values[0] for a in study.axes}
    _afmkit.run(study.command, {**study.parameters, **first}, Result)  # the parameters checked, errors naming them
    # the first ≤ 64 points of the grid, for up to 0.3 s (only the first when the cost is not wanted): checks
    # the output selectors and measures the cost of a point
    points = _points(study, zstore.chunk_slices(study.shape, zstore.chunk_shape(study.shape, 64 if measure else 1), 0))
    start, cpu_start = time.perf_counter(), time.process_time()
    n = 0
    while n < len(points):
        _afmkit.evaluate_points(study.command, dict(study.parameters), [a.name for a in study.axes],
                                points[n:n + 1], list(study.outputs))
        n += 1
        if time.perf_counter() - start > 0.3:
            break
    cost = (time.perf_counter() - start) / n
    cpu_cost = (time.process_time() - cpu_start) / n
    # the unit of each output as the selector resolves it (docs/study.md#outputs): count, a column's unit, or the
    # command's "units" entry for a results path
    out_units = list(_afmkit.output_units(study.command, dict(study.parameters), [a.name for a in study.axes],
                                          points[:n], list(study.outputs)))
    return cost, out_units, cpu_cost


#: A local study (scheduler "local") is computed by worker processes only when the computation left is at least
#: this long (s of CPU time, estimated from the pilot points or the first chunk) and there are 2 workers or more:
#: below it, the pool's start (a fork server importing NumPy, Zarr and afmkit, then a fork per worker: about 0.3 s
#: of one core) would cost more than it saves, and the chunks are computed in this process
#: (docs/study.md#running-it).
LOCAL_POOL_SECONDS = 1.5

#: What the local workers import once, in the fork server they are forked from (afmkit._pool).
_PRELOAD = ["zarr", "afmkit.study.run"]

#: Times a local study starts its worker processes again after losing one (killed, out of memory) before it gives up.
LOCAL_RETRIES = 3


def _local_workers(workers: int | None) -> int:
    return workers or os.cpu_count() or 1


def _client(scheduler, workers: int | None):
    """(client, cluster or None, whether the client is ours to close): the distributed.Client given, or one at an
    address (checked within a few seconds)."""
    import distributed

    if isinstance(scheduler, distributed.Client):
        return scheduler, None, False
    try:
        return distributed.Client(scheduler, timeout="5s"), None, True
    except (OSError, TimeoutError) as e:
        raise StudyError("scheduler", f"scheduler '{scheduler}' does not answer within 5 s: {e}") from None


def run(study: Study, store, *, scheduler=None, workers: int | None = None, chunk_seconds: float = 1.0,
        chunk_points: int | None = None, progress: bool | str = True, netcdf=None):
    """Computes `study` into the Zarr store `store` and returns its results as an xarray Dataset.

    scheduler: "serial" (this process), None or "local" (`workers` processes of this machine, default one per
    core, when the computation left is at least LOCAL_POOL_SECONDS long; else this process), an address
    "tcp://host:8786" of a running Dask scheduler, or a distributed.Client (a distributed.LocalCluster's for Dask
    on this machine). chunk_seconds: the computation per chunk (measured on the pilot points), or chunk_points
    points per chunk. progress: True (a line per second on standard error), False, or "dask" (Dask's progress
    bar: a widget in a notebook, a text bar in a terminal; lines when not on Dask). A store that exists must
    hold this study (resumed: only chunks not done are computed); netcdf: also write the results there.
    """
    path, failed = compute(study, store, scheduler=scheduler, workers=workers, chunk_seconds=chunk_seconds,
                           chunk_points=chunk_points, progress=progress, netcdf=netcdf)
    return results(path, failed, netcdf)


def compute(study: Study, store, *, scheduler=None, workers: int | None = None, chunk_seconds: float = 1.0,
            chunk_points: int | None = None, progress: bool | str = True, netcdf=None) -> tuple:
    """What run does but open the results: computes `study` into `store` (the arguments of run; `netcdf` is only
    checked); returns (the store's path, the number of points that failed numerically). `afmkit study run` calls it
    without importing xarray."""
    from .. import __version__

    if chunk_points is not None and (not isinstance(chunk_points, int) or isinstance(chunk_points, bool)
                                     or chunk_points < 1):
        raise StudyError("chunk_points", f"chunk_points = {chunk_points!r} is out of range: must be an integer >= 1")
    if not (isinstance(chunk_seconds, (int, float)) and math.isfinite(chunk_seconds) and chunk_seconds > 0):
        raise StudyError("chunk_seconds", f"chunk_seconds = {chunk_seconds!r} is out of range: must be > 0 and "
                                          f"finite")
    if workers is not None and (not isinstance(workers, int) or isinstance(workers, bool) or workers < 1):
        raise StudyError("workers", f"workers = {workers!r} is out of range: must be an integer >= 1")
    if progress not in (True, False, "dask"):
        raise StudyError("progress", f"progress = {progress!r} is not allowed: must be True, False or 'dask'")
    # Everything that can be checked is checked before anything runs or is created (a refused study leaves nothing)
    check_scheduler(scheduler)
    path = check_store(store)
    if netcdf is not None:
        netcdf = check_netcdf(netcdf)
        # the NetCDF file is written from memory: every output and coordinate of every point
        require_memory("netcdf", study.size, 8 * (len(study.outputs) + 1))
    client = None
    cost = None  # CPU time of one point (s), when the pilot measured it
    local = scheduler in (None, "local")
    try:
        try:
            if path.exists():
                root, chunks = zstore.open_existing(path, study)
            else:
                measure = chunk_points is None or (local and _local_workers(workers) > 1)
                wall, units, cpu = _pilot(study, measure=measure)
                cost = cpu if measure else None
                target = chunk_points or max(1, round(chunk_seconds / max(wall, 1e-9)))
                chunks = zstore.chunk_shape(study.shape, target)
                # the chunk bookkeeping (done flags, the list of pending chunks) is held in memory
                require_memory("axes", math.prod(zstore.chunk_grid(study.shape, chunks)), 64)
                if scheduler != "serial" and not local:
                    client = _client(scheduler, workers)  # an unreachable scheduler is refused before the store
                path.parent.mkdir(parents=True, exist_ok=True)
                zstore.create(path, study, chunks, units, __version__)
                root, chunks = zstore.open_existing(path, study)
        except OSError as e:
            raise write_error("store", path, e) from None
        _compute(study, path, root, chunks, scheduler, workers, progress, client, cost)
    finally:
        if client is not None:
            _close(client)
    return path, int(root["chunk_failed"][:].sum())  # read here: not a Dask computation on the study's cluster


def results(path: Path, failed: int, netcdf=None):
    """The study's results in the store `path` as an xarray Dataset (and written to `netcdf` when given)."""
    import xarray as xr

    ds = xr.open_zarr(str(path), consolidated=True)
    ds = ds.drop_vars(["chunk_done", "chunk_failed"])
    ds.attrs["failed_points"] = failed
    if netcdf is not None:
        out = Path(netcdf)
        tmp = None
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            tmp = unique_temporary(out)
            ds.load().to_netcdf(tmp)
            os.replace(tmp, out)
        except OSError as e:
            raise write_error("netcdf", out, e) from None
        finally:
            if tmp is not None:
                tmp.unlink(missing_ok=True)
    return ds


def _compute(study, path, root, chunks, scheduler, workers, progress, client, cost=None) -> None:
    """Computes the chunks of the store not done yet: serially, on local worker processes when they pay, or on the
    Dask cluster of `client` (or of the address `scheduler`)."""
    done = root["chunk_done"][:]
    pending = [int(i) for i in np.flatnonzero(done == 0)]
    total = len(done)
    local = scheduler in (None, "local")
    bar = _Progress(total, int(np.prod(chunks)), study.size, progress is True or
                    (progress == "dask" and (scheduler == "serial" or local)))
    bar.done = total - len(pending)
    definition = study.definition()
    try:
        if pending:
            if scheduler == "serial" or local:
                n = _local_workers(workers) if local else 1
                if n > 1 and len(pending) > 1 and cost is None:  # a resumed store: the first chunk measures the cost
                    start = time.process_time()
                    compute_chunk(str(path), definition, pending.pop(0))
                    bar.done += 1
                    bar.step()
                    cost = (time.process_time() - start) / int(np.prod(chunks))
                left = 0.0 if cost is None else cost * int(np.prod(chunks)) * len(pending)
                if n > 1 and len(pending) > 1 and left >= LOCAL_POOL_SECONDS:
                    _run_local(path, definition, pending, n, bar)
                else:
                    for i in pending:
                        compute_chunk(str(path), definition, i)
                        bar.done += 1
                        bar.step()
            else:
                own = client is None  # resuming a store: the cluster is opened only when chunks are pending
                if own:
                    client = _client(scheduler, workers)
                try:
                    _run_dask(study, path, definition, pending, client[0], bar, dask_bar=progress == "dask")
                finally:
                    if own:
                        _close(client)
    except OSError as e:  # writing a chunk: a full or read-only file system, the store removed meanwhile
        raise write_error("store", path, e) from None
    bar.step(final=True)


def _run_local(path, definition, pending, n, bar) -> None:
    """The chunks `pending` on `n` worker processes of this machine, forked from a fork server that has imported
    NumPy, Zarr and afmkit once (afmkit._pool), one OpenMP thread each. A worker lost (killed, out of memory) breaks
    the pool: the chunks not done are given to a new one, up to LOCAL_RETRIES times (a chunk's writes are
    idempotent); a chunk that raises stops the study."""
    from concurrent.futures import as_completed
    from concurrent.futures.process import BrokenProcessPool

    from .. import _pool

    left = list(pending)
    target = str(path.resolve())
    for attempt in range(LOCAL_RETRIES + 1):
        with _pool.pool(min(n, len(left)), _PRELOAD, 1) as workers:
            futures = {}
            try:
                for i in left:  # a worker lost meanwhile breaks the pool here already
                    futures[workers.submit(compute_chunk, target, definition, i)] = i
                for f in as_completed(futures):
                    f.result()
                    left.remove(futures[f])
                    bar.done += 1
                    bar.step()
                return
            except BrokenProcessPool:
                if attempt == LOCAL_RETRIES:
                    raise StudyFailure("workers", f"a worker process of the local pool was lost {attempt + 1} times "
                                                  f"(killed, or out of memory); {len(left)} chunks are not done: "
                                                  f"finished chunks are kept, run again to resume") from None
            except BaseException:
                for f in futures:
                    f.cancel()
                raise


def _close(client) -> None:
    """Closes what _client opened (a Client the caller gave stays open)."""
    connection, cluster, owned = client
    if owned:
        connection.close()
    if cluster is not None:
        cluster.close()


def _run_dask(study, path, definition, pending, client, bar, dask_bar=False) -> None:
    import distributed

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
