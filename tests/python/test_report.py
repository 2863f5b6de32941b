"""`afmkit report` on bad input and when interrupted (the whole report, in a browser: test_report_browser.py)."""
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from afmkit.report import figure_ids

CLI = os.environ["AFMKIT_CLI"]
QUICK = "seed000-fig3,beyond-impact"  # two figures of a few seconds


def report(*args, cwd):
    return subprocess.run([CLI, "report", *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def leftovers(folder: Path):
    return [p.name for p in folder.iterdir() if p.name.startswith(".")] if folder.exists() else []


def test_figure_ids_are_unique_and_cover_both_papers_and_beyond():
    ids = figure_ids()
    assert len(ids) == len(set(ids))
    for wanted in ["seed000-fig3", "seed000-fig4", "seed000-attractive", "seed003-fig2", "seed003-fig3",
                   "seed003-fig4", "seed003-fig5", "seed003-fig7", "beyond-hb-vs-orbits", "beyond-chart-spotchecks",
                   "beyond-tuning", "beyond-scan-images"]:
        assert wanted in ids


def test_the_report_lists_its_figures_as_the_modules_do_without_importing_matplotlib():
    """Listing and selecting figures (the report's parent process) imports neither Matplotlib nor the figure modules
    (issue 28 §5: their import is paid once, just before the workers are forked): REPORT_FIGURES is the modules'
    FIGURES, in report order."""
    import importlib
    import sys

    from afmkit.report.build import FIGURE_MODULES, REPORT_FIGURES

    code = ("import sys, afmkit.report as r; print(','.join(r.figure_ids())); "
            "print(sorted(m for m in ('matplotlib', 'afmkit.figures.seed000', 'afmkit.figures.seed003', "
            "'afmkit.figures.scan') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))).stdout.splitlines()
    assert out[1] == "[]"
    expected = [(m, fn.__name__, fn.figure_id) for m in FIGURE_MODULES
                for fn in importlib.import_module(f"afmkit.figures.{m}").FIGURES]
    assert [f[:3] for f in REPORT_FIGURES] == expected
    assert out[0].split(",") == [e[2] for e in expected]
    assert all(cost > 0 for *_, cost in REPORT_FIGURES)


def test_the_longest_figures_are_started_first():
    from afmkit.report.build import REPORT_FIGURES, _figure_list, _longest_first

    cost = {figure_id: c for _, _, figure_id, c in REPORT_FIGURES}
    order = _longest_first(_figure_list())
    assert sorted(order) == sorted(_figure_list())
    assert [cost[t[2]] for t in order] == sorted(cost.values(), reverse=True)


def test_a_selection_writes_a_page_with_just_those_figures(tmp_path):
    r = report("--output-dir", "rep", "--figures", QUICK, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "[ 1/2]" in r.stderr and "[ 2/2]" in r.stderr  # progress, one line per figure
    page = (tmp_path / "rep" / "index.html").read_text()
    assert page.count("<img ") == 2
    for fid in QUICK.split(","):
        assert f'id="{fid}"' in page
        assert (tmp_path / "rep" / "figures" / f"{fid}.png").stat().st_size > 1000
    assert "restitution" in page  # the impact figure's key number
    assert "MS/s" in page and "harmonic-balance curve" in page  # the speed rows (measured in a forked child)
    # the figures first, the key numbers after them; no citation of a file outside the repository
    assert page.rindex("<figure>") < page.index('<h2 id="numbers">')
    for outside in ("MATH.md", "shared/", "/work/", "seeds/"):
        assert outside not in page
    assert leftovers(tmp_path / "rep") == []


@pytest.mark.parametrize("args,names", [
    (["--output-dir", "file/sub"], "output_dir"),          # below a regular file: cannot be created
    (["--output-dir", "file"], "output_dir"),              # a regular file, not a folder
    (["--figures", "seed000-fig3,no-such-figure"], "figures"),
    (["--figures", ""], "figures"),
    (["--jobs", "0"], "jobs"),
    (["--jobs", "nan"], "jobs"),
])
def test_bad_input_is_refused_before_anything_is_computed(tmp_path, args, names):
    (tmp_path / "file").write_text("not a folder")
    start = time.monotonic()
    r = report(*args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert names in r.stderr
    assert "figures with" not in r.stderr  # no figure was started
    assert time.monotonic() - start < 30
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_an_interrupted_report_leaves_the_old_page_and_no_temporary(tmp_path, sig):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "index.html").write_text("the previous report")
    proc = subprocess.Popen([CLI, "report", "--output-dir", str(out), "--figures", QUICK + ",seed003-fig4"],
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    first = proc.stderr.readline()  # "afmkit report: 3 figures with 2 process(es) …": computing has started
    assert "figures with" in first
    time.sleep(1.0)
    os.killpg(proc.pid, sig)
    rest = proc.communicate(timeout=60)[1]
    assert proc.returncode != 0
    assert "index.html was not changed" in rest
    assert (out / "index.html").read_text() == "the previous report"
    assert leftovers(out) == []


def test_a_killed_runs_staging_folder_is_removed_by_the_next_run(tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    dead = subprocess.Popen(["true"])
    dead.wait()  # a process id that no longer exists
    stale = out / f".staging-{dead.pid}-abc"
    stale.mkdir()
    (stale / "seed000-fig3.png").write_bytes(b"half")
    r = report("--output-dir", str(out), "--figures", "beyond-impact", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert leftovers(out) == []


def test_no_text_the_page_is_made_of_cites_a_file_outside_the_repository():
    """Every string of the report's code (page, captions, key numbers and how each was obtained: afmkit.report and
    afmkit.figures), read from the source without computing a figure: the whole page's text, cheaply (the browser
    test reads the rendered page of every figure)."""
    import ast

    import afmkit.figures
    import afmkit.report

    files = [f for pkg in (afmkit.report, afmkit.figures) for f in Path(pkg.__file__).resolve().parent.glob("*.py")]
    assert len(files) >= 6
    found = []
    for f in files:
        for node in ast.walk(ast.parse(f.read_text(), str(f))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                found += [(f.name, node.lineno, o) for o in ("MATH.md", "shared/", "/work/", "seeds/", "../")
                          if o in node.value]
    assert found == []


def test_workers_forked_by_the_report_process_run_cores_over_jobs_openmp_threads():
    """`afmkit report` forks its workers from itself (no fork server: afmkit._pool.forked_pool): OMP_NUM_THREADS was
    read by the OpenMP runtime when the report process loaded afmkit, so each worker sets its own threads
    (_pool._forked_init); the report process keeps its own. The workers inherit the objects frozen before the fork
    (gc.freeze) and run the report's garbage-collector thresholds."""
    import ctypes
    import sys

    import afmkit  # noqa: F401  (loads the module's OpenMP runtime)

    try:
        ctypes.CDLL("libgomp.so.1", mode=os.RTLD_NOLOAD | os.RTLD_LAZY)
    except OSError:
        pytest.skip("afmkit's module is not built with GNU OpenMP here")
    code = ("import ctypes, os, afmkit\n"
            "from afmkit.report.build import _figure_pool\n"
            "def probe():\n"
            "    g = ctypes.CDLL('libgomp.so.1', mode=os.RTLD_NOLOAD | os.RTLD_LAZY)\n"
            "    import gc\n"
            "    return g.omp_get_max_threads(), os.getppid(), gc.get_threshold()[0], gc.get_freeze_count() > 0\n"
            "if __name__ == '__main__':\n"
            "    with _figure_pool(1, 1) as pool:\n"
            "        threads, parent, gc0, frozen = pool.submit(probe).result()\n"
            "    g = ctypes.CDLL('libgomp.so.1', mode=os.RTLD_NOLOAD | os.RTLD_LAZY)\n"
            "    print(threads, parent == os.getpid(), g.omp_get_max_threads(), gc0, frozen)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), OMP_NUM_THREADS="3"))
    assert out.returncode == 0, out.stderr
    from afmkit.report.build import _WORKER_GC_THRESHOLDS

    assert out.stdout.split() == ["1", "True", "3", str(_WORKER_GC_THRESHOLDS[0]), "True"]


def test_the_speed_numbers_are_measured_in_a_child_while_the_report_process_imports():
    """The page's speed rows are measured in a child forked before the report process imports Matplotlib (on the
    idle core, not after the figures): the child's rows arrive through its pipe, as speed_numbers() gives them."""
    import sys

    code = ("import os\n"
            "from afmkit.report.build import _SpeedAhead\n"
            "ahead = _SpeedAhead.start()\n"
            "import matplotlib.pyplot\n"
            "rows = ahead.result()\n"
            "print(ahead.pid != os.getpid(), len(rows), all(len(r) == 3 for r in rows), rows[0][1].endswith('MS/s'),"
            " rows[1][1].endswith(' ms'))\n")
    if not sys.platform.startswith("linux"):
        pytest.skip("fork: Linux")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "2", "True", "True", "True"]
