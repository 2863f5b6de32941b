"""Timing whole processes as users run them, for the bench scripts (report_speed.py, study_scaling.py): the CPU of
a process and of every descendant (orphans included: this process becomes their subreaper), and the package of an
older commit beside this build's compiled module, to time both in the same run."""
import ctypes
import glob
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def subreaper() -> None:
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(36, 1, 0, 0, 0) != 0:  # PR_SET_CHILD_SUBREAPER
        sys.exit("cannot become a child subreaper (Linux prctl): the CPU time of orphans would be missed")


def children_cpu() -> float:
    t = os.times()
    return t.children_user + t.children_system


def run(argv, env, cwd) -> tuple:
    """(wall s, CPU s of the process and all its descendants, load average at the end, stderr text)."""
    cpu0 = children_cpu()
    start = time.perf_counter()
    p = subprocess.Popen(argv, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    err = p.communicate()[1]
    while True:  # the orphans it left (a fork server ends when its owner does): reaped here, counted in the CPU
        try:
            os.waitpid(-1, 0)
        except ChildProcessError:
            break
    wall = time.perf_counter() - start
    if p.returncode != 0:
        sys.exit(f"{' '.join(argv)} exited {p.returncode}:\n{err}")
    return wall, children_cpu() - cpu0, os.getloadavg()[0], err


def old_tree(ref: str, build: Path, into: Path) -> Path:
    """The package afmkit of commit `ref` with this build's compiled module, in `into`/python."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", ref, "python/afmkit"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    for so in glob.glob(str(build / "python" / "afmkit" / "_afmkit*.so")):
        shutil.copy(so, into / "python" / "afmkit")
    return into / "python"
