"""Worker processes tied to their parent: a worker ends when the process that started it ends, even by SIGKILL, so
that no orphan keeps computing (issue 24 §3). Used by the report's figure workers and the study's Dask workers."""
import os
import sys
import time

#: The environment variable that hands a Dask worker the pid of the study process (see dask_setup below).
PARENT_VARIABLE = "AFMKIT_PARENT_PID"


def die_with_parent(parent: int) -> None:
    """In a worker: end when `parent` ends, even by SIGKILL: the kernel sends SIGKILL on the parent's death (Linux
    prctl PR_SET_PDEATHSIG); elsewhere, or if the parent is already gone, a watchdog thread polls the parent's pid."""
    import ctypes
    import signal
    import threading

    armed = False
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)
    if not armed:
        def watch():
            while os.getppid() == parent:
                time.sleep(0.5)
            os._exit(1)

        threading.Thread(target=watch, daemon=True).start()


def dask_setup(worker=None) -> None:
    """Dask worker preload (`preload=["afmkit._parent"]`): ties the worker process to the study process whose pid
    is in AFMKIT_PARENT_PID (set in the workers' environment by the study). A worker started by anything else (no
    such variable) is left alone."""
    text = os.environ.get(PARENT_VARIABLE, "")
    if not text.isdigit():
        return
    parent = int(text)
    if os.getppid() == parent:  # started by the study process itself (a LocalCluster's nanny runs in it)
        die_with_parent(parent)
        return
    import threading  # started by a helper process: watch the study process's pid

    def alive() -> bool:
        try:
            os.kill(parent, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True

    if not alive():
        os._exit(1)

    def watch():
        while alive():
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


class TiedToParent:
    """A Dask worker plugin (client.register_worker_plugin) that ties each worker process, including workers
    restarted later, to the process `parent` (dask_setup). Needs no Dask import to be defined."""

    name = "afmkit-tied-to-parent"

    def __init__(self, parent: int):
        self.parent = parent

    def setup(self, worker=None) -> None:
        os.environ[PARENT_VARIABLE] = str(self.parent)
        dask_setup(worker)

    def teardown(self, worker=None) -> None:
        pass

    def transition(self, key, start, finish, **kwargs) -> None:
        pass

    def release_key(self, key, state, cause, reason, report) -> None:
        pass


def die_with_fork_server(owner: int) -> None:
    """In a worker forked by a multiprocessing fork server (the report's figure workers, the study's local pool):
    end when the fork server ends, which it does as soon as `owner` (the process that started it) ends, even by
    SIGKILL (its pipe from the owner reaches end of file); a worker whose owner is already gone ends at once."""
    try:
        from multiprocessing import forkserver
    except ImportError:  # no fork server here (Windows): a spawned worker, whose parent is the owner
        forkserver = None

    # a forked worker inherits the write end of the pipe whose end of file tells the fork server that its owner and
    # every worker are gone: closed here, the server ends with its owner (and the workers with the server)
    server = getattr(forkserver, "_forkserver", None)
    if getattr(server, "_forkserver_alive_fd", None) is not None:
        os.close(server._forkserver_alive_fd)
        server._forkserver_alive_fd = None
    die_with_parent(os.getppid())
    try:
        os.kill(owner, 0)
    except ProcessLookupError:
        os._exit(1)
    except PermissionError:
        pass
