"""Assembles the report: computes every figure (in parallel processes), then writes index.html atomically."""
from __future__ import annotations

import concurrent.futures as futures
import importlib
import os
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

from .._files import unique_temporary

#: Figure modules (python/afmkit/figures/<name>.py), in report order; each lists its figures in FIGURES.
FIGURE_MODULES = ["seed000", "seed003", "scan"]

#: Every figure of the report, in report order: (module, function, id, cost). The same list as the modules' FIGURES
#: (a test checks it), written out so that listing or selecting figures imports neither Matplotlib nor the figure
#: modules. cost: the figure's CPU time in seconds (one core, one OpenMP thread; bench/report_speed.py --imports
#: prints it), to start the longest first so that the processes finish together.
REPORT_FIGURES = [
    ("seed000", "fig3", "seed000-fig3", 0.10),
    ("seed000", "fig4", "seed000-fig4", 0.09),
    ("seed000", "fig_attractive", "seed000-attractive", 0.30),
    ("seed000", "fig_hb_vs_orbits", "beyond-hb-vs-orbits", 0.30),
    ("seed000", "fig_impact", "beyond-impact", 0.14),
    ("seed003", "fig2", "seed003-fig2", 0.60),
    ("seed003", "fig3", "seed003-fig3", 0.33),
    ("seed003", "fig4", "seed003-fig4", 1.19),
    ("seed003", "fig5", "seed003-fig5", 0.27),
    ("seed003", "fig7", "seed003-fig7", 0.53),
    ("seed003", "spotchecks", "beyond-chart-spotchecks", 0.49),
    ("seed003", "tuning", "beyond-tuning", 0.73),
    ("scan", "scan_images", "beyond-scan-images", 0.85),
]

#: What the figure workers import once, before they are forked (by the report process, or by the fork server of
#: afmkit._pool).
_PRELOAD = ["afmkit.report.build", *(f"afmkit.figures.{m}" for m in FIGURE_MODULES)]


class ReportError(ValueError):
    """A report that cannot be made as asked: bad input (an argument out of range, an output folder that cannot be
    written). A ValueError, like afmkit.InvalidParameter and afmkit.InputError; `status` is the exit status (2)."""

    status = 2

    def __init__(self, message: str, status: int = 2):
        super().__init__(message)
        self.status = status


class ReportFailure(RuntimeError):
    """A figure whose computation failed (not the caller's error: exit status 1), like afmkit.NumericalFailure."""

    status = 1


def _check_writable(out: Path) -> None:
    """Refuse an output folder that cannot be written, before any computation."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out, prefix=".write-test-"):
            pass
    except OSError as e:
        raise ReportError(f"output_dir '{out}' cannot be written: {e.strerror or e}: must be a writable folder"
                          ) from None


def figure_ids() -> list:
    """The id of every figure of the report, in report order."""
    return [figure_id for _, _, figure_id in _figure_list()]


def _remove_stale_staging(out: Path) -> None:
    """Removes the staging folders of earlier runs that were killed outright (SIGKILL, power loss): those whose
    process no longer exists (a run still going on keeps its own)."""
    for folder in out.glob(".staging-*-*"):
        try:
            pid = int(folder.name.split("-")[1])
            os.kill(pid, 0)
        except ProcessLookupError:
            shutil.rmtree(folder, ignore_errors=True)
        except (ValueError, PermissionError):
            pass


def _figure_list():
    return [(module, name, figure_id) for module, name, figure_id, _ in REPORT_FIGURES]


def _longest_first(tasks) -> list:
    """The tasks in the order they are started: the most costly first (REPORT_FIGURES), so that no process is left
    with a long figure when the others are done."""
    cost = {figure_id: c for _, _, figure_id, c in REPORT_FIGURES}
    return sorted(tasks, key=lambda t: -cost.get(t[2], 0.0))


def _select(tasks, figures: str):
    """The tasks named by `figures` ("all" or comma-separated figure ids), in report order."""
    if figures.strip() == "all":
        return tasks
    wanted = [w.strip() for w in figures.split(",") if w.strip()]
    known = [t[2] for t in tasks]
    unknown = [w for w in wanted if w not in known]
    if unknown or not wanted:
        raise ReportError(f"figures = '{figures}' is not allowed: must be 'all' or a comma-separated list of "
                          f"figure ids from: {', '.join(known)}")
    return [t for t in tasks if t[2] in wanted]


def _run_figure(module: str, name: str, staging: str):
    """In a worker process: one figure function with its defaults, timed; writes the PNG into `staging` and returns
    the figure's report entry (caption, key numbers, file name)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fn = getattr(importlib.import_module(f"afmkit.figures.{module}"), name)
    start = time.perf_counter()
    fig = fn(Path(staging))
    entry = fig.report
    plt.close(fig)
    entry.seconds = time.perf_counter() - start
    return entry


def speed_numbers() -> list:
    """The speed figures of the report, measured now on this machine."""
    import numpy as np

    from .. import control, tapping

    rows = []
    f = control.RealtimeFilter(rotation_frequency=2 * np.pi * 50, harmonics=10, sample_rate=20000.0)
    x = np.sin(np.linspace(0, 2 * np.pi * 200, 1 << 16))
    y = np.empty_like(x)
    f.step_block(x, y)  # warm up

    def blocks():
        for _ in range(16):
            f.step_block(x, y)

    best = min(_timed(blocks) for _ in range(3))
    rows.append(("real-time filter, N = 10, vectorised block (one core)", f"{16 * len(x) / best / 1e6:.0f} MS/s",
                 "RealtimeFilter.step_block from Python, 16 blocks of 65536 samples into a preallocated array, best "
                 "of 3"))
    start = time.perf_counter()
    r = tapping.hb(points=2000)
    rows.append(("harmonic-balance curve, 2000 points (seed 1, eqs. 17-18)", f"{(time.perf_counter() - start) * 1e3:.0f} ms",
                 f"afmkit.tapping.hb with its defaults ({len(r)} rows)"))
    return rows


class _SpeedAhead:
    """speed_numbers() measured in a child forked before the report process imports Matplotlib: it runs on the core
    that import leaves idle instead of after the figures (issue 28 §5). Forked while this process has run no OpenMP
    parallel region (as the workers, _figure_pool); the child ends with this process. Where there is no fork, or the
    child fails, result() measures here."""

    def __init__(self, pid: int, fd: int):
        self.pid, self.fd = pid, fd

    @classmethod
    def start(cls):
        if not hasattr(os, "fork") or not sys.platform.startswith("linux"):
            return None
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: measure, send, leave without running the parent's exit handlers
            code = 1
            try:
                import pickle
                import signal

                from .._parent import die_with_parent

                os.close(read)
                signal.signal(signal.SIGTERM, signal.SIG_DFL)
                signal.signal(signal.SIGINT, signal.SIG_DFL)
                die_with_parent(os.getppid())
                with os.fdopen(write, "wb") as f:
                    f.write(pickle.dumps(speed_numbers()))
                code = 0
            finally:
                os._exit(code)
        os.close(write)
        return cls(pid, read)

    def result(self) -> list:
        import pickle

        with os.fdopen(self.fd, "rb") as f:
            data = f.read()
        _, status = os.waitpid(self.pid, 0)
        if status != 0 or not data:
            return speed_numbers()
        return pickle.loads(data)


def _timed(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def _progress(done: int, total: int, fig, started: float) -> None:
    print(f"[{done:2d}/{total}] {fig.id}: {fig.seconds:5.1f} s  (elapsed {time.perf_counter() - started:5.1f} s)",
          file=sys.stderr, flush=True)


def _accept(fig, module: str, name: str, figure_id: str, done: dict, tasks, started) -> None:
    if fig.id != figure_id:
        raise ReportFailure(f"figure function {module}.{name} returned id {fig.id}, marked {figure_id}")
    done[figure_id] = fig
    _progress(len(done), len(tasks), fig, started)


def _in_process(order, staging, done, tasks, started) -> None:
    """One process (jobs = 1, or a single figure) in `afmkit report`: a pool would only add its start-up. Not from
    a caller's Python session (build()), whose Matplotlib backend the figures' Agg would replace."""
    for m, n, figure_id in order:
        try:
            fig = _run_figure(m, n, str(staging))
        except Exception as e:  # a figure that fails fails the report (index.html unchanged)
            detail = "".join(traceback.format_exception(e))
            raise ReportFailure(f"figure {figure_id} ({m}.{n}) failed:\n{detail}") from None
        _accept(fig, m, n, figure_id, done, tasks, started)


def _in_pool(order, staging, done, tasks, started, jobs: int, forked: bool) -> None:
    """`jobs` worker processes, each with cores / jobs OpenMP threads, that have Matplotlib, NumPy, afmkit and the
    figure modules imported before they start; the longest figures are started first.

    ``forked`` (`afmkit report` itself): this process imports them and forks the workers (_figure_pool). Otherwise
    (build() called from a Python session, which may have run OpenMP code) the workers are forked from a fork
    server that imports them (afmkit._pool)."""
    from concurrent.futures.process import BrokenProcessPool

    threads = max(1, (os.cpu_count() or 1) // jobs)
    workers = min(jobs, len(order))
    if forked:
        pool_cm = _figure_pool(workers, threads)
    else:
        from .. import _pool

        pool_cm = _pool.pool(workers, _PRELOAD, threads)
    with pool_cm as pool:
        pending = {}
        try:
            for m, n, i in order:
                pending[pool.submit(_run_figure, m, n, str(staging))] = (m, n, i)
            for fut in futures.as_completed(pending):
                m, n, figure_id = pending[fut]
                try:
                    fig = fut.result()
                except BrokenProcessPool:
                    raise
                except Exception as e:  # a figure that fails fails the report (index.html unchanged)
                    detail = "".join(traceback.format_exception(e))
                    raise ReportFailure(f"figure {figure_id} ({m}.{n}) failed:\n{detail}") from None
                _accept(fig, m, n, figure_id, done, tasks, started)
        except BrokenProcessPool:  # a worker killed (out of memory, a signal) before its figure
            raise ReportFailure("a figure worker process was lost (killed, or out of memory): the report is "
                                "incomplete") from None
        except BaseException:
            for fut in pending:
                fut.cancel()
            raise


def _figure_pool(workers: int, threads: int):
    """The figure workers of `afmkit report`: forked from this process (afmkit._pool.forked_pool) once it has imported
    what the figures need (_PRELOAD) and Matplotlib with its Agg backend, each with `threads` OpenMP threads and
    the garbage-collector thresholds _WORKER_GC_THRESHOLDS. Safe because this process has run no OpenMP parallel
    region yet (forked_pool's constraint)."""
    from .. import _pool

    return _pool.forked_pool(workers, _PRELOAD, threads, prepare=_matplotlib_agg, gc_thresholds=_WORKER_GC_THRESHOLDS)


def _matplotlib_agg() -> None:
    """Matplotlib with the Agg backend and pyplot (what _run_figure imports), imported before the workers fork."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401


#: The cyclic garbage collector of a figure worker: Matplotlib allocates many short-lived objects, and Python's
#: default thresholds (700, 10, 10) ran ~430 young, 40 middle and 3 full collections (60-80 ms each) over the 13
#: figures, ~0.33 s or 6 % of their CPU; these ~30, 1 and 0 (~0.2 s), for ~10 MB more memory per worker (the cycles
#: of finished figures are freed later).
_WORKER_GC_THRESHOLDS = (10_000, 20, 100)


def build(output_dir="out/report", jobs: int = 2, figures: str = "all", *, _own_process: bool = False) -> Path:
    """Computes the figures and writes ``<output_dir>/index.html`` (replaced only when complete); returns its path.

    ``figures`` is "all" or a comma-separated list of figure ids (:func:`figure_ids`).
    """
    from .. import __version__
    from . import page

    if not isinstance(jobs, int) or isinstance(jobs, bool) or not 1 <= jobs <= 64:
        raise ReportError(f"jobs = {jobs!r} is out of range: must be an integer in [1, 64]")
    if not isinstance(figures, str):
        raise ReportError(f"figures = {figures!r} is not allowed: must be a str, 'all' or a comma-separated list of "
                          f"figure ids")
    if not isinstance(output_dir, (str, os.PathLike)):
        raise ReportError(f"output_dir = {output_dir!r} is not allowed: must be a path (str or os.PathLike)")
    try:
        os.fsencode(output_dir)
    except UnicodeEncodeError:
        raise ReportError(f"output_dir = {output_dir!r} is not valid text: it cannot be encoded as a file name"
                          ) from None
    path = os.fspath(output_dir)
    if (b"\0" if isinstance(path, bytes) else "\0") in path:
        raise ReportError("output_dir contains a NUL character: must be a path")
    tasks = _select(_figure_list(), figures)
    out = Path(output_dir)
    _check_writable(out)
    started = time.perf_counter()
    _remove_stale_staging(out)
    staging = Path(tempfile.mkdtemp(prefix=f".staging-{os.getpid()}-", dir=out))
    try:
        print(f"afmkit report: {len(tasks)} figures with {jobs} process(es) into {out}/", file=sys.stderr, flush=True)
        done = {}
        ahead = None
        order = _longest_first(tasks)
        if _own_process and (jobs == 1 or len(tasks) == 1):  # no pool: the figures in this process
            _in_process(order, staging, done, tasks, started)
        else:
            ahead = _SpeedAhead.start() if _own_process else None
            _in_pool(order, staging, done, tasks, started, jobs, forked=_own_process)
        speed = ahead.result() if ahead is not None else speed_numbers()
        ordered = [done[t[2]] for t in tasks]
        for fig in ordered:
            if not (staging / fig.filename).is_file():
                raise ReportFailure(f"figure {fig.id} did not write its file {fig.filename}")
        # Move the figures in, then the page last (atomic rename): an interrupted run never leaves a page that
        # points at missing or half-written images.
        total = time.perf_counter() - started
        tmp = None
        try:
            tmp = unique_temporary(out / "index.html")
            (out / "figures").mkdir(exist_ok=True)
            for fig in ordered:
                os.replace(staging / fig.filename, out / "figures" / fig.filename)
                fig.filename = f"figures/{fig.filename}"
            text = page.render(ordered, speed, version=__version__, seconds=total, jobs=jobs)
            tmp.write_text(text, encoding="utf-8")
            os.replace(tmp, out / "index.html")
        except OSError as e:  # a full disk, a folder made read-only or removed meanwhile: say which file and why
            if tmp is not None:
                tmp.unlink(missing_ok=True)
            raise ReportError(f"cannot write '{e.filename or out / 'index.html'}': {e.strerror or e}") from None
        print(f"afmkit report: {len(ordered)} figures in {total:.1f} s", file=sys.stderr, flush=True)
        return out / "index.html"
    finally:
        shutil.rmtree(staging, ignore_errors=True)
