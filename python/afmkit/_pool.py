"""The project's worker pools: processes that start with the workers' modules already imported, in milliseconds
instead of starting Python and importing NumPy, Matplotlib and afmkit again (spawn).

* pool(): workers forked from a fork server that has imported them (the study's local pool, the report's figures
  when built from a Python session): a clean OpenMP runtime whatever the calling process has run.
* forked_pool(): workers forked from the calling process itself once it has imported them (`afmkit report`): no
  second interpreter to start, but only for a process that has run no OpenMP parallel region yet."""
from __future__ import annotations

import gc
import importlib
import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor

from ._parent import die_with_fork_server, die_with_parent


def _init(owner: int) -> None:
    die_with_fork_server(owner)


def start_fork_server(preload: list, threads: int) -> multiprocessing.context.BaseContext:
    """Starts this process's fork server (once per process: it then serves every pool) importing the modules
    `preload`, with OMP_NUM_THREADS = `threads` (read by the OpenMP runtime when afmkit's module is loaded there);
    returns at once: the imports go on in the server while this process continues. Where there is no fork server
    (Windows), a spawn context: each worker imports what it needs."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(list(preload))
    old = os.environ.get("OMP_NUM_THREADS")
    os.environ["OMP_NUM_THREADS"] = str(threads)
    try:
        from multiprocessing import forkserver

        forkserver.ensure_running()
    finally:
        if old is None:
            del os.environ["OMP_NUM_THREADS"]
        else:
            os.environ["OMP_NUM_THREADS"] = old
    return ctx


def pool(workers: int, preload: list, threads: int) -> ProcessPoolExecutor:
    """A pool of `workers` processes forked from the fork server (start_fork_server), each ending with this process
    (afmkit._parent.die_with_fork_server)."""
    return ProcessPoolExecutor(max_workers=workers, mp_context=start_fork_server(preload, threads),
                               initializer=_init, initargs=(os.getpid(),))


def forked_pool(workers: int, preload: list, threads: int, *, prepare=None,
                gc_thresholds: tuple | None = None) -> ProcessPoolExecutor:
    """A pool of `workers` processes forked from this process once it has imported the modules `preload` and run
    `prepare()` (if given): a fork server (pool) would start another interpreter and import afmkit, NumPy and
    Matplotlib again (issue 28 §5: ~0.2 s more on the way to the first figure). The imported modules' objects are
    frozen (gc.freeze) before the fork: the workers' collections never traverse them (nor copy their pages on
    write). Each worker ends with this process (even by SIGKILL), ends on SIGTERM, runs `threads` OpenMP threads
    (_forked_init) and, if given, the garbage-collector thresholds `gc_thresholds`.

    Constraint: this process must have run no OpenMP parallel region before the call (a fork after one is not safe:
    the child's OpenMP threads would be missing). A process that may have run one (a Python session) uses pool().
    Where there is no fork (Windows, macOS' default), pool(workers, preload, threads): a fork server or spawn."""
    if "fork" not in multiprocessing.get_all_start_methods() or not sys.platform.startswith("linux"):
        return pool(workers, preload, threads)
    for module in preload:
        importlib.import_module(module)
    if prepare is not None:
        prepare()
    gc.freeze()
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"),
                               initializer=_forked_init, initargs=(os.getpid(), threads, gc_thresholds))


def _forked_init(parent: int, threads: int, gc_thresholds) -> None:
    """In a worker of forked_pool: ends with `parent` (even by SIGKILL), SIGTERM ends it (the parent's handler,
    inherited, would turn it into KeyboardInterrupt), and the OpenMP runtime that afmkit's module loaded runs
    `threads` threads (OMP_NUM_THREADS was read when the module was loaded, before the fork); its garbage collector's
    thresholds are `gc_thresholds` if given."""
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    die_with_parent(parent)
    set_openmp_threads(threads)
    if gc_thresholds is not None:
        gc.set_threshold(*gc_thresholds)


def set_openmp_threads(threads: int) -> None:
    """omp_set_num_threads(threads) in the OpenMP runtime already loaded in this process (GNU libgomp, LLVM libomp,
    Intel libiomp); nothing if none is loaded."""
    import ctypes

    for name in ("libgomp.so.1", "libomp.so", "libomp.so.5", "libiomp5.so"):
        try:
            lib = ctypes.CDLL(name, mode=os.RTLD_NOLOAD | os.RTLD_LAZY)
        except OSError:
            continue
        lib.omp_set_num_threads(ctypes.c_int(threads))
