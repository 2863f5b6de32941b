"""The example notebooks (examples/notebooks/) run from start to end in a Jupyter kernel, as a reader runs them.

Each notebook is executed by nbclient (Debian's python3-nbconvert + python3-ipykernel) with the interpreter of this
test; a cell that raises fails the test, naming the cell. The notebooks write only into the kernel's temporary
folder (TMPDIR, here the test's tmp_path) and the executed copy goes there too: the notebooks in the repository
stay as committed, without outputs.
"""
import json
import os
import sys
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("AFMKIT_SOURCE_DIR", Path(__file__).resolve().parents[2]))
FOLDER = SOURCE / "examples" / "notebooks"
NOTEBOOKS = sorted(FOLDER.glob("*.ipynb"))


def _jupyter():
    try:
        import ipykernel  # noqa: F401  (the kernel the client starts)
        import nbclient
        import nbformat
    except ImportError as e:  # the test command's packages (scripts/bootstrap.sh --all): a failure, not a skip
        pytest.fail(f"the notebooks need Debian's python3-nbconvert and python3-ipykernel "
                    f"(scripts/bootstrap.sh --all): {e}")
    return nbclient, nbformat


def test_the_four_notebooks_are_there_and_committed_without_outputs():
    assert {p.stem for p in NOTEBOOKS} >= {"tapping_bistability", "controller_to_c_header", "parameter_study",
                                          "virtual_scan"}
    for path in NOTEBOOKS:
        nb = json.loads(path.read_text())
        for cell in nb["cells"]:
            if cell["cell_type"] == "code":
                assert cell["outputs"] == [] and cell["execution_count"] is None, (path.name, cell.get("id"))


@pytest.fixture
def kernel(tmp_path, monkeypatch):
    """A kernel spec for this interpreter (the one the package was built for), the package on its path, and TMPDIR
    in tmp_path."""
    spec = tmp_path / "jupyter" / "kernels" / "afmkit-test"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "afmkit test", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    import afmkit  # the package under test, found by the kernel wherever it runs
    package = str(Path(os.path.abspath(afmkit.__file__)).parents[1])  # not resolved: the build links its files
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([package, *filter(None, [os.environ.get("PYTHONPATH")])]))
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.setenv("TMPDIR", str(work))
    monkeypatch.setenv("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # the debugger's frozen-modules warning
    # the kernel's own files (connection file, IPython profile) in tmp_path too, not in $HOME,
    # and no user configuration of Jupyter or IPython changes the run
    for variable, folder in (("JUPYTER_RUNTIME_DIR", "runtime"), ("JUPYTER_CONFIG_DIR", "config"),
                             ("JUPYTER_DATA_DIR", "data"), ("IPYTHONDIR", "ipython")):
        (tmp_path / "home" / folder).mkdir(parents=True)
        monkeypatch.setenv(variable, str(tmp_path / "home" / folder))
    return "afmkit-test", work


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_a_notebook_runs_to_the_end_without_a_cell_error(path, kernel, tmp_path):
    nbclient, nbformat = _jupyter()
    name, work = kernel
    before = sorted(p.name for p in FOLDER.iterdir())
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=120, kernel_name=name, resources={"metadata": {"path": str(work)}})
    client.execute()  # CellExecutionError (naming the cell and its traceback) on any error
    nbformat.write(nb, tmp_path / path.name)
    assert sorted(p.name for p in FOLDER.iterdir()) == before  # nothing written beside the notebooks
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert errors == []
    if path.stem == "parameter_study":  # progress of a long run is shown under its cell (standard error)
        stderr = "".join(o.get("text", "") for c in nb.cells for o in c.get("outputs", []) if o.get("name") == "stderr")
        assert "afmkit study: " in stderr and " chunks " in stderr


def test_the_progress_of_a_command_goes_to_pythons_stderr_which_jupyter_shows(capfd):
    """A command's progress lines (C++ io::Progress, at most one a second) are written to sys.stderr as it is at
    the time (ipykernel's stream: shown under the cell), not to file descriptor 2 (not shown everywhere)."""
    import contextlib
    import io
    import math
    import time

    import afmkit

    n = 150
    for _ in range(4):  # a chart of just over a second (the first line comes after one second), whatever the machine
        caught = io.StringIO()
        start = time.perf_counter()
        with contextlib.redirect_stderr(caught):
            afmkit.control.chart(x_points=n, y_points=n, boundaries_output="")
        elapsed = time.perf_counter() - start
        if elapsed > 1.1:
            break
        n = int(n * math.sqrt(1.4 / elapsed)) + 1
    assert elapsed > 1.1
    assert "control chart (grid points): " in caught.getvalue() and " done, " in caught.getvalue()
    assert "control chart" not in capfd.readouterr().err  # nothing on descriptor 2


def test_a_commands_warning_goes_to_pythons_stderr_too(capfd):
    """A command's warning (here: the scan's loop is unstable at its delay) goes where its progress goes."""
    import contextlib
    import io

    import afmkit

    caught = io.StringIO()
    with contextlib.redirect_stderr(caught):
        r = afmkit.scan(end_radius=0.0005, radial_speed=0.0005, image_resolution=64, delay=0.015)
    assert r.results.loop_spectral_abscissa >= 0  # unstable: the warning is due
    assert "afmkit scan: warning: the loop is unstable at the nominal delay" in caught.getvalue()
    assert "warning" not in capfd.readouterr().err
