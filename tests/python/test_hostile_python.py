"""The Python side under hostile use (issue 24 §3): objects made without __init__, filters shared by threads or
given overlapping buffers or forged states, Ctrl-C during long computations, text that is not Unicode, study
definitions and run settings that are wrong in kind, reports killed outright. Each case ends in a clear error of
the right class (ValueError: the caller's; RuntimeError: a failure) or in the right result — never a crash, a
traceback, a hang or a silent wrong answer."""
import contextlib
import errno
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import afmkit

FILTER = dict(rotation_frequency=2 * np.pi * 50.0, harmonics=4, sample_rate=20000.0)


def python(code: str, **kw):
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, **kw)


# ---- RealtimeFilter --------------------------------------------------------------------------------------------

def test_a_filter_made_without_init_raises_instead_of_crashing():
    # in a child process: before the fix this was a SIGSEGV
    code = """
import numpy as np, afmkit
F = afmkit.control.RealtimeFilter
calls = [lambda f: f.step(1.0), lambda f: f.step_block(np.ones(4)), lambda f: f.reset(),
         lambda f: f.save_state(), lambda f: f.restore_state(np.zeros(20)), lambda f: f.skipped_samples,
         lambda f: f.uses_wide_vectors]
for call in calls:
    f = F.__new__(F)
    try:
        call(f)
    except TypeError as e:
        assert "not initialised" in str(e), e
    else:
        raise SystemExit("no error")
print("ok")
"""
    r = python(code)
    assert r.returncode == 0 and r.stdout.strip() == "ok", (r.returncode, r.stderr)


def test_a_filter_shared_by_two_threads_processes_whole_blocks_one_after_the_other():
    # Both threads give the same block, so whatever order they take the lock in, the filter must see 2k copies
    # of it in a row: the outputs of each call are one of the sequential blocks and the final state is theirs.
    rng = np.random.default_rng(3)
    block = rng.standard_normal(200_000)
    k = 4
    reference = afmkit.control.RealtimeFilter(**FILTER)
    expected = [reference.step_block(block) for _ in range(2 * k)]
    shared = afmkit.control.RealtimeFilter(**FILTER)
    outputs = []

    def work():
        for _ in range(k):
            outputs.append(shared.step_block(block))

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    np.testing.assert_array_equal(shared.save_state(), reference.save_state())
    remaining = list(expected)
    for out in outputs:  # each output block is one of the sequential ones (each used once)
        match = next(i for i, e in enumerate(remaining) if np.array_equal(e, out))
        remaining.pop(match)
    # step() from threads while another thread runs blocks: serialised as well
    a = afmkit.control.RealtimeFilter(**FILTER)
    t = threading.Thread(target=lambda: a.step_block(block))
    t.start()
    singles = [a.step(x) for x in block[:1000]]
    t.join()
    assert all(np.isfinite(singles))
    assert a.save_state()[8] == len(block) + 1000  # no lost update of the sample counter


def test_step_block_with_out_overlapping_measured_reads_the_original_samples():
    x = np.random.default_rng(5).standard_normal(10_001)
    expected = afmkit.control.RealtimeFilter(**FILTER).step_block(x[:-1].copy())
    f = afmkit.control.RealtimeFilter(**FILTER)
    out = f.step_block(x[:-1], out=x[1:])  # out starts one sample after measured, in the same memory
    assert np.shares_memory(out, x)
    np.testing.assert_array_equal(out, expected)
    y = np.random.default_rng(6).standard_normal(10_001)
    expected = afmkit.control.RealtimeFilter(**FILTER).step_block(y[1:].copy())
    afmkit.control.RealtimeFilter(**FILTER).step_block(y[1:], out=y[:-1])  # the other way round
    np.testing.assert_array_equal(y[:-1], expected)
    z = np.random.default_rng(7).standard_normal(5000)  # in place (the very same memory) stays allowed
    expected = afmkit.control.RealtimeFilter(**FILTER).step_block(z.copy())
    afmkit.control.RealtimeFilter(**FILTER).step_block(z, out=z)
    np.testing.assert_array_equal(z, expected)


@pytest.mark.parametrize("index,value,names", [
    (10, 1e308, "coordinates"),      # a coordinate near DBL_MAX
    (6, -1e300, "held output"),
    (8, 1e300, "counter"),           # beyond 2^64: the float -> uint64 conversion would be undefined
    (7, 2.0 ** 64, "counter"),
    (8, 12.5, "counter"),            # fractional
    (2, 1e300, "N must be"),
    (4, -3.0, "fingerprint"),
])
def test_restore_state_refuses_a_state_no_filter_saved_and_keeps_its_own(index, value, names):
    f = afmkit.control.RealtimeFilter(**FILTER)
    m = np.sin(np.linspace(0, 30, 3000))
    f.step_block(m[:1500])
    good = f.save_state()
    bad = good.copy()
    bad[index] = value
    with pytest.raises(afmkit.InvalidParameter, match=names) as e:
        f.restore_state(bad)
    assert e.value.parameter == "state"
    assert isinstance(e.value, ValueError)
    np.testing.assert_array_equal(f.save_state(), good)  # unchanged


# ---- Ctrl-C during long computations ---------------------------------------------------------------------------

def test_a_ctrl_c_whose_handler_runs_inside_a_progress_line_stops_the_computation():
    # Python runs a signal handler inside whatever Python code the main thread runs next: here the progress line
    # written to sys.stderr, where its KeyboardInterrupt must stop the computation, not be dropped with the line
    class InterruptedStderr:
        def write(self, text):
            raise KeyboardInterrupt

        def flush(self):
            pass

    t = time.monotonic()
    with contextlib.redirect_stderr(InterruptedStderr()), pytest.raises(KeyboardInterrupt):
        afmkit.scan(sample_rate=1e6, radial_speed=2e-5, image_output="", output="")  # 2e8 samples: about 20 s
    assert time.monotonic() - t < 10.0  # stopped after the first progress line (about a second in)


@pytest.mark.parametrize("call", [
    "afmkit.control.chart(x_points=1500, y_points=1500)",                      # about a minute
    "afmkit.control.tune(coarse_points=400, delay_max=0.2)",
    "afmkit.tapping.sweep(points=20000, separation_min=5, separation_max=25)",
    "afmkit.tapping.sweep(points=20, mode='continuation', max_continuation_points=200000, "
    "separation_min=10, separation_max=40, max_arclength_step=1e-4)",      # 20000 points take 5 s
    "afmkit.scan(sample_rate=1e6, radial_speed=2e-5)",                        # 2e8 samples: about 20 s
    "afmkit.tapping.hb(law='dmt', units='physical', points=3000000)",          # about 50 s
])
def test_ctrl_c_stops_a_long_computation_within_a_second_with_keyboard_interrupt(call):
    code = f"""
import sys, time, afmkit
print("start", flush=True)
t = time.monotonic()
try:
    {call}
except KeyboardInterrupt:
    print(f"interrupted after {{time.monotonic() - t:.2f}} s", flush=True)
    sys.exit(3)
print("finished", flush=True)
"""
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "start"
    time.sleep(1.0)  # well inside the computation
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    waited = time.monotonic() - sent
    assert proc.returncode == 3, (out, err)
    assert "interrupted" in out
    assert waited < 2.0, f"stopped {waited:.2f} s after Ctrl-C"


# ---- text that is not Unicode ----------------------------------------------------------------------------------

def test_a_lone_surrogate_is_the_callers_error_naming_the_keyword():
    with pytest.raises(afmkit.InvalidParameter, match="law .*not valid Unicode") as e:
        afmkit.tapping.hb(law="attr\ud800active")
    assert e.value.parameter == "law" and isinstance(e.value, ValueError)
    with pytest.raises(afmkit.InvalidParameter, match="force_curve") as e:
        afmkit.tapping.hb(law="table", force_curve="curve\udcff.csv")
    assert not isinstance(e.value, RuntimeError)
    with pytest.raises(afmkit.InvalidParameter, match="config"):
        afmkit.tapping.hb(config="\ud800.toml")


# ---- studies ---------------------------------------------------------------------------------------------------

pytest.importorskip("zarr")
from afmkit.study import Study, StudyError, run  # noqa: E402
from afmkit.study.run import StudyFailure, write_error  # noqa: E402

BASE = dict(computation="tapping.hb", outputs=["free_amplitude"], parameters={"points": 50})


@pytest.mark.parametrize("axis,names", [
    ([True, False], "boolean"),
    ([1.0, [2.0, 3.0]], "nested"),
    (np.array([[1.0, 2.0], [3.0, 4.0]]), "2-D"),
    (np.array([True, False]), "bool"),
    (["1.0", "2.0"], "real number"),
    ([1.0, 2 + 3j], "real number"),
    ("1.0, 2.0", "list of numbers"),
])
def test_study_axes_are_refused_not_coerced(axis, names):
    with pytest.raises(StudyError, match=names) as e:
        Study.make(axes={"quality_factor": axis}, **BASE)
    assert e.value.field == "axes.quality_factor"


def test_a_huge_axis_is_refused_before_it_is_allocated(monkeypatch):
    monkeypatch.setenv("AFMKIT_MEMORY_LIMIT", "4G")  # as on a shared node (the machine's memory may be larger)
    start = time.monotonic()
    with pytest.raises(StudyError, match="axes.quality_factor") as e:
        Study.make(axes={"quality_factor": {"start": 1, "stop": 2, "points": 10 ** 9}}, **BASE)
    assert e.value.field == "axes.quality_factor" and "memory" in str(e.value).lower()
    assert time.monotonic() - start < 5


def test_every_run_argument_is_checked_before_anything_is_created(tmp_path):
    study = Study.make(axes={"quality_factor": [50.0, 100.0]}, **BASE)
    (tmp_path / "file").write_text("a file, not a folder")
    cases = [
        (dict(scheduler="sometimes"), "scheduler"),
        (dict(scheduler=5), "scheduler"),
        (dict(workers=True), "workers"),
        (dict(netcdf=tmp_path / "file" / "r.nc"), "netcdf"),   # below a regular file
        (dict(netcdf=tmp_path), "netcdf"),                     # a folder
        (dict(netcdf="."), "netcdf"),                          # no name (was: an error after the whole study)
        (dict(netcdf=7), "netcdf"),
    ]
    for kwargs, field in cases:
        with pytest.raises(StudyError) as e:
            run(study, tmp_path / "s.zarr", progress=False, **{"scheduler": "serial", **kwargs})
        assert e.value.field == field, (kwargs, e.value)
        assert not (tmp_path / "s.zarr").exists(), kwargs
    for store, what in [(tmp_path / "file", "not a folder"), (tmp_path / "file" / "s.zarr", "not a folder"),
                        (5, "must be a path")]:
        with pytest.raises(StudyError, match=what) as e:
            run(study, store, scheduler="serial", progress=False)
        assert e.value.field == "store"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_write_failures_name_the_store_and_say_whose_they_are(tmp_path, monkeypatch):
    full = write_error("store", tmp_path / "s.zarr", OSError(errno.ENOSPC, "No space left on device", "x/0.0"))
    assert isinstance(full, StudyError) and "No space left" in str(full) and "s.zarr" in str(full)
    read_only = write_error("netcdf", tmp_path / "r.nc", OSError(errno.EROFS, "Read-only file system"))
    assert isinstance(read_only, StudyError) and read_only.field == "netcdf"
    broken = write_error("store", tmp_path / "s.zarr", OSError(errno.EIO, "Input/output error"))
    assert isinstance(broken, StudyFailure) and isinstance(broken, RuntimeError)
    # a chunk whose write fails (as on a full disk) ends the run with that message, naming the store
    runner = sys.modules["afmkit.study.run"]  # the module (afmkit.study.run is also the function's name)

    def no_space(*args):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "s.zarr" / "free_amplitude" / "0"))

    monkeypatch.setattr(runner, "compute_chunk", no_space)
    study = Study.make(axes={"quality_factor": [50.0, 100.0]}, **BASE)
    with pytest.raises(StudyError, match="store '.*s.zarr' cannot be written .*No space left on device") as e:
        run(study, tmp_path / "s.zarr", scheduler="serial", progress=False)
    assert e.value.field == "store"


STUDY_FILE = """computation = "tapping.hb"
outputs = ["free_amplitude"]
[parameters]
points = 50
[axes]
quality_factor = [50.0, 100.0]
"""


@pytest.mark.parametrize("extra,names,status", [
    ("[run]\nstore = 5\n", "run.store = 5", 2),
    ("[run]\nnetcdf = 3\n", "run.netcdf = 3", 2),
    ("[run]\nworkers = true\n", "run.workers", 2),
    ("[run]\nscheduler = \"nowhere\"\nstore = \"s.zarr\"\n", "scheduler", 2),
    ("[run]\nstore = \"file/s.zarr\"\n", "store", 2),
    ("[run]\nnetcdf = \"file/r.nc\"\nstore = \"s.zarr\"\n", "netcdf", 2),
])
def test_the_study_command_names_file_and_key_and_leaves_nothing(tmp_path, extra, names, status):
    (tmp_path / "file").write_text("a file")
    study = tmp_path / "bad.toml"
    study.write_text(STUDY_FILE + extra)
    r = subprocess.run([sys.executable, "-m", "afmkit.study", "run", str(study), "--quiet"], capture_output=True,
                       text=True, timeout=120, cwd=tmp_path)
    assert r.returncode == status, r.stderr
    assert "Traceback" not in r.stderr
    assert names in r.stderr and "bad.toml" in r.stderr, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "file"]


def test_a_study_file_that_is_not_utf8_is_named(tmp_path):
    study = tmp_path / "latin1.toml"
    study.write_bytes(STUDY_FILE.encode() + "# r\xe9sum\xe9\n".encode("latin-1"))
    r = subprocess.run([sys.executable, "-m", "afmkit.study", "run", str(study)], capture_output=True, text=True,
                       timeout=60, cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "latin1.toml" in r.stderr and "not UTF-8" in r.stderr and "line 7" in r.stderr, r.stderr


def test_a_store_that_is_another_kind_of_zarr_is_refused_without_zarrs_template(tmp_path):
    import zarr

    zarr.open_array(str(tmp_path / "a.zarr"), mode="w", shape=(2,), dtype="f8")
    study = Study.make(axes={"quality_factor": [50.0, 100.0]}, **BASE)
    with pytest.raises(StudyError, match="not an afmkit study store") as e:
        run(study, tmp_path / "a.zarr", scheduler="serial", progress=False)
    assert "%r" not in str(e.value)


# ---- the report ------------------------------------------------------------------------------------------------

def test_report_errors_are_value_errors_and_failures_runtime_errors(tmp_path):
    from afmkit.report import ReportError, ReportFailure, build

    assert issubclass(ReportError, ValueError) and issubclass(ReportFailure, RuntimeError)
    for kwargs in (dict(jobs=0), dict(figures=5), dict(output_dir=5), dict(output_dir=str(tmp_path / "a\0b")),
                   dict(output_dir="\ud800")):
        with pytest.raises(ValueError) as e:
            build(**{"output_dir": str(tmp_path / "r"), **kwargs})
        assert isinstance(e.value, ReportError), kwargs
    assert not (tmp_path / "r").exists()


def _children(pid: int) -> list:
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out.append(int(entry.name))
    return out


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _descendants(pid: int) -> list:
    out, todo = [], [pid]
    while todo:
        kids = _children(todo.pop())
        out += kids
        todo += kids
    return out


def _figure_workers(pid: int) -> list:
    """The report's figure workers among the descendants of `pid`: the processes that have Matplotlib loaded (the
    workers are forked by the report process after it imported Matplotlib, or by a fork server; the child that
    measures the speed numbers is forked before the import)."""
    out = []
    for p in _descendants(pid):
        try:
            maps = Path(f"/proc/{p}/maps").read_text()
        except OSError:
            continue
        if "ft2font" in maps and _alive(p):
            out.append(p)
    return out


def test_a_report_killed_outright_takes_its_workers_with_it(tmp_path):
    """The figure workers (forked by the report process itself, or by a fork server where the report is built from a
    Python session) end with the report process killed by SIGKILL."""
    cli = os.environ["AFMKIT_CLI"]
    proc = subprocess.Popen([cli, "report", "--output-dir", str(tmp_path / "rep"), "--jobs", "2", "--figures",
                             "seed003-fig4,seed003-fig2"], stderr=subprocess.PIPE, text=True)
    assert "figures with" in proc.stderr.readline()
    deadline = time.monotonic() + 30
    workers = []
    while time.monotonic() < deadline and len(workers) < 2:  # its 2 figure workers
        workers = _figure_workers(proc.pid)
        time.sleep(0.1)
    assert len(workers) >= 2, "the workers did not start"
    time.sleep(1.0)  # the workers are computing their figures
    workers = _descendants(proc.pid)
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.1)
    left = [p for p in workers if _alive(p)]
    for p in left:  # do not leave them to the rest of the test run
        os.kill(p, signal.SIGKILL)
    assert left == [], "workers outlived the report process"


def test_a_figure_worker_killed_fails_the_report_with_status_1_and_keeps_the_page(tmp_path):
    """A figure worker lost (killed, out of memory) is the machine's failure, not the caller's: exit 1 naming it,
    the previous page untouched (a worker lost while figures were still being handed out raised a bare
    BrokenProcessPool traceback)."""
    cli = os.environ["AFMKIT_CLI"]
    out = tmp_path / "rep"
    out.mkdir()
    (out / "index.html").write_text("the previous report")
    proc = subprocess.Popen([cli, "report", "--output-dir", str(out), "--jobs", "2", "--figures",
                             "seed003-fig4,seed003-fig2,seed003-fig3"], stderr=subprocess.PIPE, text=True)
    assert "figures with" in proc.stderr.readline()
    deadline = time.monotonic() + 30
    workers = []
    while time.monotonic() < deadline and not workers:
        workers = _figure_workers(proc.pid)
        time.sleep(0.01)
    assert workers, "no worker started"
    os.kill(workers[0], signal.SIGKILL)
    err = proc.communicate(timeout=120)[1]
    assert proc.returncode == 1, err
    assert "a figure worker process was lost" in err and "Traceback" not in err, err
    assert (out / "index.html").read_text() == "the previous report"


def test_a_study_killed_outright_takes_its_local_workers_with_it(tmp_path):
    """The study's local pool (afmkit._pool, as afmkit.study.run uses it), its process killed by SIGKILL while a
    worker is busy in code that holds the GIL (as a computation without a GIL release does): the worker ends with
    it at once (issue 24 §3), through the kernel (PR_SET_PDEATHSIG on the fork server, which ends with its owner)."""
    (tmp_path / "hostile_busy.py").write_text(
        "import ctypes\n"
        "def busy():\n"
        "    ctypes.PyDLL(None).sleep(60)  # a C call that keeps the GIL (PyDLL does not release it)\n")
    script = tmp_path / "study_parent.py"
    script.write_text(
        "import os, time\n"
        "from afmkit import _pool\n"
        "import hostile_busy\n"
        "if __name__ == '__main__':\n"
        "    workers = _pool.pool(1, ['afmkit.study.run'], 1)\n"
        "    future = workers.submit(hostile_busy.busy)\n"
        "    time.sleep(1.5)  # the task has started\n"
        "    print(' '.join(map(str, workers._processes)), flush=True)\n"
        "    time.sleep(120)\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), *sys.path]))
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            text=True, env=env)
    import select
    ready, _, _ = select.select([proc.stdout], [], [], 60)
    workers = [int(p) for p in proc.stdout.readline().split()] if ready else []
    if len(workers) != 1:
        proc.kill()
    assert len(workers) == 1 and _alive(workers[0]), "the worker did not start"
    workers += _descendants(proc.pid)  # and the fork server
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.1)
    left = [p for p in workers if _alive(p)]
    for p in left:  # do not leave them to the rest of the test run
        os.kill(p, signal.SIGKILL)
    assert left == [], "a worker outlived the study process"


def test_a_store_removed_while_the_study_runs_is_named_without_zarrs_template(tmp_path):
    runner = sys.modules["afmkit.study.run"]
    study = Study.make(axes={"quality_factor": [50.0, 100.0]}, **BASE)
    with pytest.raises(StudyError, match="no longer a study store") as e:
        runner.compute_chunk(str(tmp_path / "gone.zarr"), study.definition(), 0)
    assert e.value.field == "store" and "%r" not in str(e.value)


def test_every_python_writer_has_its_own_temporary(tmp_path):
    """Two writers of one target (two threads of one process too) never share a temporary (issue 24 §3): each gets
    a new file in the target's folder with the permissions a new file gets."""
    import threading
    from afmkit._files import unique_temporary
    target = tmp_path / "index.html"
    names = []

    def take():
        names.append(unique_temporary(target))

    threads = [threading.Thread(target=take) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(set(names)) == 8
    mask = os.umask(0o022)
    os.umask(mask)
    for n in names:
        assert n.parent == tmp_path and n.name.startswith(".index.html.tmp-") and n.stat().st_size == 0
        assert (n.stat().st_mode & 0o777) == (0o666 & ~mask)
