"""Worker processes forked from a fork server that has imported the workers' modules once (the report's figures, the
study's local pool): a worker starts in milliseconds instead of starting Python and importing NumPy, Matplotlib and
afmkit again (spawn), and with a clean OpenMP runtime (fork of a process that has run OpenMP code is not safe)."""
from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor

from ._parent import die_with_fork_server


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
