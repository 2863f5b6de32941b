"""Parameter studies (afmkit.study, docs/study.md): the same numbers serially and on a Dask LocalCluster with two
worker processes (loopback only), a worker killed mid-study, an interrupted study resumed, and bad input."""
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
import xarray as xr
import zarr

import afmkit
from afmkit.study import Study, StudyError, run

distributed = pytest.importorskip("distributed")

ORBIT = dict(computation="tapping.orbit",
             axes={"separation": {"start": 8.5, "stop": 10.5, "points": 9}, "frequency_ratio": [0.99, 1.0, 1.005]},
             outputs=["max(amplitude | stable)", "min(amplitude | stable)", "count(amplitude | stable)",
                      "free_amplitude"],
             parameters={"law": "attractive", "approach_adhesion": 0.5, "departure_adhesion": 1.0})


def orbit_study(**changes):
    return Study.make(**{**ORBIT, **changes})


@pytest.fixture(scope="module")
def cluster():
    c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                 host="127.0.0.1", env={"OMP_NUM_THREADS": "1"})
    client = distributed.Client(c)
    yield client
    client.close()
    c.close()


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    path = tmp_path_factory.mktemp("serial") / "s.zarr"
    return run(orbit_study(), path, scheduler="serial", chunk_points=4, progress=False).load()


def same(a: xr.Dataset, b: xr.Dataset):
    assert list(a.data_vars) == list(b.data_vars)
    for v in a.data_vars:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)  # bit for bit (NaN where NaN)


def test_results_are_labelled_arrays_with_units(serial):
    assert serial.sizes == {"separation": 9, "frequency_ratio": 3}
    assert serial["separation"].attrs["units"] == "L"  # normalised units (docs/units.md)
    assert orbit_study(parameters={"units": "physical"}).units() == {"separation": "nm", "frequency_ratio":
                                                                     "dimensionless"}
    assert serial["max_amplitude_stable"].attrs["selector"] == "max(amplitude | stable)"
    assert serial["max_amplitude_stable"].attrs["units"]
    assert serial["count_amplitude_stable"].attrs["units"] == "count"
    assert serial.attrs["failed_points"] == 0
    # independent check of one point: the orbit command itself at that point
    r = afmkit.tapping.orbit(separation=9.5, frequency_ratio=1.0, **ORBIT["parameters"])
    stable = r["stable"] == 1
    point = serial.sel(separation=9.5, frequency_ratio=1.0)
    assert float(point["max_amplitude_stable"]) == r["amplitude"][stable].max()
    assert float(point["min_amplitude_stable"]) == r["amplitude"][stable].min()
    assert int(point["count_amplitude_stable"]) == stable.sum()


def test_a_study_point_replays_from_its_keywords_and_its_toml_bit_for_bit(serial, tmp_path):
    """Issue 26 §2: the point's keywords (Study.point) and its TOML (Study.point_toml, read by the program's
    --config) reproduce what the study stored at that point, bit for bit; reductions recomputed here."""
    import csv
    study = orbit_study()
    for index in [(0, 0), (4, 1), (8, 2)]:
        point = study.point(index)
        assert point == {**ORBIT["parameters"], "separation": study.axes[0].values[index[0]],
                         "frequency_ratio": study.axes[1].values[index[1]]}
        stored = serial.isel(separation=index[0], frequency_ratio=index[1])
        r = afmkit.tapping.orbit(**point)
        stable = np.asarray(r["stable"], dtype=bool)
        if stable.any():
            assert float(stored["max_amplitude_stable"]) == r["amplitude"][stable].max()
        assert int(stored["count_amplitude_stable"]) == stable.sum()
        # the same point from the command line: the CSV's amplitudes (printed to round trip) equal the Python run's
        (tmp_path / "p.toml").write_text(study.point_toml(index))
        out = tmp_path / "p.csv"
        subprocess.run([os.environ["AFMKIT_CLI"], "tapping", "orbit", "--config", str(tmp_path / "p.toml"),
                        "--output", str(out)], check=True, capture_output=True)
        with open(out) as f:
            rows = list(csv.DictReader(f))
        key = next(k for k in rows[0] if k.startswith("amplitude"))
        np.testing.assert_array_equal([float(row[key]) for row in rows], r["amplitude"])
    with pytest.raises(StudyError, match="index"):
        study.point((9, 0))
    with pytest.raises(StudyError, match="2 axes"):
        study.point(0)


def test_local_cluster_gives_the_serial_numbers_bit_for_bit(cluster, serial, tmp_path, capsys):
    ds = run(orbit_study(), tmp_path / "d.zarr", scheduler=cluster, chunk_points=2, progress="dask")
    same(ds.load(), serial)
    assert "100% Completed" in capsys.readouterr().out  # Dask's progress bar (text, outside a notebook)


def test_a_worker_killed_mid_study_and_the_study_still_completes(cluster, serial, tmp_path):
    path = tmp_path / "k.zarr"
    pids = list(cluster.run(os.getpid).values())
    killed = []

    def kill_when_started():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            try:
                done = zarr.open_group(str(path), mode="r")["chunk_done"][:]
            except Exception:  # noqa: BLE001 - the store is not created yet
                time.sleep(0.02)
                continue
            if 2 <= done.sum() < len(done):
                os.kill(pids[0], signal.SIGKILL)  # the worker process ends; its chunks go to the other
                killed.append(int(done.sum()))
                return
            time.sleep(0.005)

    watcher = threading.Thread(target=kill_when_started)
    watcher.start()
    ds = run(orbit_study(), path, scheduler=cluster, chunk_points=1, progress=False)
    watcher.join()
    assert killed, "the study ended before a worker could be killed"
    same(ds.load(), serial)
    cluster.wait_for_workers(2, timeout=60)  # the nanny restarted it


def _spy_local_pool(monkeypatch):
    """Counts the local pools the study starts (afmkit._pool.pool, as afmkit.study.run calls it)."""
    from afmkit import _pool
    started = []
    real = _pool.pool

    def counted(*args, **kwargs):
        started.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(_pool, "pool", counted)
    return started


def test_a_short_local_study_runs_in_this_process(serial, tmp_path, monkeypatch):
    """Issue 28 §5: a study whose computation is shorter than LOCAL_POOL_SECONDS (this one: 27 orbits, about
    0.4 s) starts no worker processes; its numbers are the serial run's."""
    started = _spy_local_pool(monkeypatch)
    runner = sys.modules["afmkit.study.run"]
    assert runner.LOCAL_POOL_SECONDS >= 1.0
    ds = run(orbit_study(), tmp_path / "short.zarr", scheduler="local", workers=2, chunk_points=4, progress=False)
    assert started == []
    same(ds.load(), serial)


def test_the_local_pool_gives_the_serial_numbers_bit_for_bit_and_survives_a_killed_worker(serial, tmp_path,
                                                                                         monkeypatch):
    """The local pool (2 processes forked from a fork server), forced by LOCAL_POOL_SECONDS = 0: one of its workers
    killed as soon as it exists, the chunks not done go to a new pool, the numbers are the serial run's."""
    import multiprocessing.forkserver as mpfs
    runner = sys.modules["afmkit.study.run"]
    monkeypatch.setattr(runner, "LOCAL_POOL_SECONDS", 0.0)
    started = _spy_local_pool(monkeypatch)
    killed = []
    stop = threading.Event()

    def kill_first_worker():
        while not stop.is_set():
            server = getattr(mpfs._forkserver, "_forkserver_pid", None)
            kids = []
            if server:
                for entry in os.listdir("/proc"):
                    try:
                        with open(f"/proc/{entry}/stat") as f:
                            fields = f.read().rsplit(")", 1)[1].split()
                    except (OSError, IndexError):
                        continue
                    if int(fields[1]) == server and fields[0] != "Z":
                        kids.append(int(entry))
            if kids:
                os.kill(kids[0], signal.SIGKILL)
                killed.append(kids[0])
                return
            time.sleep(0.002)

    watcher = threading.Thread(target=kill_first_worker)
    watcher.start()
    try:
        ds = run(orbit_study(), tmp_path / "pool.zarr", scheduler="local", workers=2, chunk_points=1,
                 progress=False)
    finally:
        stop.set()
        watcher.join()
    assert killed, "no worker was seen"
    assert len(started) >= 2 and started[0][0] == 2  # the pool of 2 workers, and another after the kill
    same(ds.load(), serial)


def test_an_interrupted_study_resumes_and_recomputes_only_missing_chunks(serial, tmp_path, monkeypatch):
    """Resumed on local workers (LOCAL_POOL_SECONDS = 0: the first pending chunk, in this process, measures the
    cost; the pool computes the rest)."""
    path = tmp_path / "r.zarr"
    code = ("import sys; from afmkit.study import Study, run; "
            f"s = Study.make(**{ORBIT!r}); "
            f"run(s, {str(path)!r}, scheduler='serial', chunk_points=1, progress=False)")
    proc = subprocess.Popen([sys.executable, "-c", code], env=os.environ.copy())
    deadline = time.monotonic() + 60
    done = None
    while time.monotonic() < deadline:
        if path.exists():
            done = zarr.open_group(str(path), mode="r")["chunk_done"][:]
            if done.sum() >= 3:
                break
        time.sleep(0.01)
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=60)
    done = zarr.open_group(str(path), mode="r")["chunk_done"][:]
    assert 3 <= done.sum() < len(done), done
    # the files of finished chunks must not be written again; a chunk interrupted between its output
    # writes and its chunk_done mark may have a partial file, and is rightly recomputed
    name = "max_amplitude_stable"
    array = zarr.open_group(str(path), mode="r")[name]
    grid = tuple(-(-n // c) for n, c in zip(array.shape, array.chunks))
    finished = [".".join(map(str, np.unravel_index(i, grid))) for i in np.flatnonzero(done)]
    stamps = {path / name / key: (path / name / key).stat().st_mtime_ns for key in finished}
    before = int(done.sum())
    monkeypatch.setattr(sys.modules["afmkit.study.run"], "LOCAL_POOL_SECONDS", 0.0)
    started = _spy_local_pool(monkeypatch)
    ds = run(orbit_study(), path, scheduler="local", workers=2, progress=False)
    assert len(started) == 1
    same(ds.load(), serial)
    rewritten = [p for p, t in stamps.items() if p.stat().st_mtime_ns != t]
    assert rewritten == [], f"finished chunks were recomputed: {rewritten}"
    after = zarr.open_group(str(path), mode="r")["chunk_done"][:]
    assert after.all() and before < len(after)


def test_a_store_of_another_study_is_refused(serial, tmp_path):
    path = tmp_path / "o.zarr"
    run(orbit_study(), path, scheduler="serial", chunk_points=30, progress=False)
    other = orbit_study(parameters={**ORBIT["parameters"], "quality_factor": 200.0})
    with pytest.raises(StudyError, match="different study .*parameters") as e:
        run(other, path, scheduler="serial", progress=False)
    assert e.value.field == "store"


@pytest.mark.parametrize("make,field", [
    (lambda: orbit_study(axes={"separatoin": [1.0, 2.0]}), "axes.separatoin"),
    (lambda: orbit_study(axes={"separation": []}), "axes.separation"),
    (lambda: orbit_study(axes={"separation": [1.0, float("nan")]}), "axes.separation"),
    (lambda: orbit_study(axes={"separation": [1.0, float("inf")]}), "axes.separation"),
    (lambda: orbit_study(axes={"law": [1.0]}), "axes.law"),
    (lambda: orbit_study(axes={}), "axes"),
    (lambda: orbit_study(outputs=[]), "outputs"),
    (lambda: orbit_study(computation="tapping.orbits"), "computation"),
    (lambda: orbit_study(parameters={"qualityfactor": 3.0}), "parameters.qualityfactor"),
])
def test_bad_definitions_name_the_field(make, field):
    with pytest.raises(StudyError) as e:
        make()
    assert e.value.field == field
    assert field.split(".")[-1] in str(e.value)


def test_bad_run_arguments_name_the_field(tmp_path):
    with pytest.raises(StudyError, match="chunk_points = 0") as e:
        run(orbit_study(), tmp_path / "z.zarr", scheduler="serial", chunk_points=0)
    assert e.value.field == "chunk_points"
    with pytest.raises(StudyError, match="progress = 'yes' is not allowed") as e:
        run(orbit_study(), tmp_path / "z.zarr", scheduler="serial", progress="yes")
    assert e.value.field == "progress"
    with pytest.raises(ValueError, match="outputs: 'max\\(amplitde \\| stable\\)': the table has no column 'amplitde'"):
        run(orbit_study(outputs=["max(amplitde | stable)"]), tmp_path / "y.zarr", scheduler="serial")
    with pytest.raises(ValueError, match="the command reports no 'critical_delay'"):
        run(orbit_study(outputs=["critical_delay"]), tmp_path / "x.zarr", scheduler="serial")
    assert not any(tmp_path.iterdir())  # nothing created for a study that cannot run


def test_a_scheduler_that_does_not_answer_is_an_error_within_seconds(tmp_path):
    start = time.monotonic()
    with pytest.raises(StudyError, match="scheduler 'tcp://127.0.0.1:9' does not answer") as e:
        run(orbit_study(), tmp_path / "w.zarr", scheduler="tcp://127.0.0.1:9", progress=False)
    assert e.value.field == "scheduler"
    assert time.monotonic() - start < 20


def test_netcdf_on_request(serial, tmp_path):
    ds = run(orbit_study(), tmp_path / "n.zarr", scheduler="serial", chunk_points=30, progress=False,
             netcdf=tmp_path / "n.nc")
    back = xr.open_dataset(tmp_path / "n.nc")
    same(back, serial)
    assert back["separation"].attrs["units"] == ds["separation"].attrs["units"]


def test_the_example_study_runs_from_the_command_line_and_finds_the_hb_hysteresis_bands(tmp_path):
    source = os.environ["AFMKIT_SOURCE_DIR"]
    store = tmp_path / "jumps.zarr"
    r = subprocess.run([sys.executable, "-X", "importtime", "-m", "afmkit.study", "run",
                        f"{source}/examples/studies/attractive_jumps.toml", "--store", str(store), "--workers", "2"],
                       capture_output=True, text=True, timeout=300)  # local
    assert r.returncode == 0, r.stderr
    assert "chunks" in r.stderr  # progress lines
    # issue 28 §5: the command imports neither Dask nor xarray (half a second each; the results are not opened)
    imported = {line.rsplit("|", 1)[1].strip() for line in r.stderr.splitlines() if line.startswith("import time:")}
    assert "zarr" in imported and not imported & {"xarray", "distributed", "dask"}
    ds = xr.open_zarr(store)
    assert ds.attrs["study_name"] == "attractive_jumps"
    # independent check: two stable orbits coexist exactly between the HB curve's jump points — the free
    # amplitude (the grazing separation, where the free oscillation starts to touch) and the fold of largest l
    parameters = {"law": "attractive", "quality_factor": 100.0, "approach_adhesion": 0.5, "departure_adhesion": 1.0}
    for ratio in (0.99, 0.995):
        hb = afmkit.tapping.hb(frequency_ratio=ratio, **parameters)
        upper = max(f["separation"] for f in hb.results["folds"])
        lower = hb.results["free_amplitude"]
        l = ds["separation"].values
        two = ds["count_amplitude_stable"].sel(frequency_ratio=ratio).values > 1
        inside = (l > lower + 0.05) & (l < upper - 0.05)  # a margin for HB's error against exact orbits (< 1 %)
        outside = (l < lower - 0.2) | (l > upper + 0.2)
        assert two[inside].all(), (ratio, l[inside], two[inside])
        assert not two[outside].any(), (ratio, l[outside][two[outside]])


def test_the_command_line_names_the_field_of_a_bad_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('computation = "tapping.orbit"\noutputs = ["free_amplitude"]\n[axes]\nseparation = []\n')
    r = subprocess.run([sys.executable, "-m", "afmkit.study", "run", str(bad), "--store", str(tmp_path / "s.zarr")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert "axes.separation is empty" in r.stderr
    bad.write_text('computation = "tapping.orbit"\noutputs = ["free_amplitude"]\ncolour = 3\n[axes]\nseparation = [1]\n')
    r = subprocess.run([sys.executable, "-m", "afmkit.study", "run", str(bad)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 2 and "unknown field 'colour'" in r.stderr


def test_afmkit_study_run_is_a_command_of_the_program_with_exact_coordinates(tmp_path):
    source = os.environ["AFMKIT_SOURCE_DIR"]
    store = tmp_path / "margin.zarr"
    r = subprocess.run([os.environ["AFMKIT_CLI"], "study", "run", f"{source}/examples/studies/delay_margin.toml",
                        "--store", str(store), "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""  # --quiet: no progress lines
    ds = xr.open_zarr(store)
    # coordinates read back exactly, 0.0 included (not taken for a fill value)
    np.testing.assert_array_equal(ds["beta"].values, np.linspace(-0.4, 0.0, 9))
    np.testing.assert_array_equal(ds["alpha"].values, np.linspace(0.05, 0.4, 8))
    assert ds["critical_delay"].attrs["units"] == "T"
    # independent check of two points, one on beta = 0: the margin command itself there
    for i, j in ((1, 8), (6, 3)):
        point = ds.isel(alpha=i, beta=j)
        m = afmkit.control.margin(alpha=float(point["alpha"]), beta=float(point["beta"]), harmonics=10, gain=20.0)
        assert float(point["critical_delay"]) == m.results["critical_delay"]
    # the options the program checks itself: exit 2 naming the parameter, before Python starts
    for args, name in ((["study", "run"], "file"), (["study", "run", str(tmp_path / "none.toml")], "file"),
                       (["study", "run", f"{source}/examples/studies/delay_margin.toml", "--scheduler", "8786"],
                        "scheduler"),
                       (["study", "run", f"{source}/examples/studies/delay_margin.toml", "--chunk-points", "0"],
                        "chunk_points")):
        r = subprocess.run([os.environ["AFMKIT_CLI"], *args], capture_output=True, text=True, timeout=60)
        assert r.returncode == 2 and name in r.stderr, (args, r.stderr)


def test_tapping_grid_writes_the_layout_of_the_equivalent_study_with_the_same_numbers(tmp_path):
    """`afmkit tapping grid` (C++, OpenMP, no Python) against the study runner over the same axis: the same arrays,
    coordinates and numbers bit for bit, opened by xarray; the store is replaced only when it is afmkit's."""
    parameters = {"law": "attractive", "quality_factor": 100.0, "approach_adhesion": 0.5, "departure_adhesion": 1.0,
                  "frequency_ratio": 0.99}
    store = tmp_path / "grid.zarr"
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in parameters.items()]
    r = subprocess.run([os.environ["AFMKIT_CLI"], "tapping", "grid", *flags, "--separation-min", "8",
                        "--separation-max", "16", "--points", "17", "--store", str(store), "--quiet"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    grid = xr.open_zarr(store).load()
    study = Study.make("tapping.orbit", axes={"separation": {"start": 8.0, "stop": 16.0, "points": 17}},
                       outputs=["max(amplitude | stable)", "min(amplitude | stable)", "count(amplitude | stable)",
                                "count(amplitude)"], parameters=parameters)
    ref = run(study, tmp_path / "study.zarr", scheduler="serial", chunk_points=5, progress=False).load()
    np.testing.assert_array_equal(grid["separation"].values, ref["separation"].values)
    for name in ref.data_vars:
        np.testing.assert_array_equal(grid[name].values, ref[name].values, err_msg=name)
        assert grid[name].attrs["selector"] == ref[name].attrs["selector"]
        assert grid[name].attrs["units"] == ref[name].attrs["units"]
    assert grid["separation"].attrs["units"] == ref["separation"].attrs["units"] == "L"
    assert (grid["count_amplitude_stable"] == 2).any()  # the hysteresis band is inside the grid
    assert grid.attrs["command"] == "afmkit tapping grid" and grid["chunk_done"].values.all()
    # the study runner does not take a grid's store for its own study
    with pytest.raises(StudyError) as e:
        run(study, store, scheduler="serial", progress=False)
    assert e.value.field == "store"
    # written again: replaced (an afmkit store); a folder that is not one is refused, untouched
    r = subprocess.run([os.environ["AFMKIT_CLI"], "tapping", "grid", "--points", "3", "--store", str(store),
                        "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert xr.open_zarr(store).sizes["separation"] == 3
    other = tmp_path / "photos"
    other.mkdir()
    (other / "a.jpg").write_bytes(b"x")
    r = subprocess.run([os.environ["AFMKIT_CLI"], "tapping", "grid", "--points", "3", "--store", str(other)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "store" in r.stderr and "not an afmkit store" in r.stderr
    assert sorted(p.name for p in other.iterdir()) == ["a.jpg"]
    assert not [p for p in tmp_path.iterdir() if ".tmp." in p.name or ".old." in p.name]


def test_dask_xarray_and_netcdf4_are_needed_only_where_they_are_used(tmp_path):
    # the machine without python3-distributed, python3-xarray and python3-netcdf4 (find_spec answers None for them):
    # a serial or local study runs; a scheduler address or a NetCDF file names the missing Debian packages (exit 1)
    study = tmp_path / "s.toml"
    study.write_text('computation = "tapping.hb"\noutputs = ["free_amplitude"]\n[axes]\nquality_factor = [50.0, 60.0]\n')
    code = ("import importlib.util as u, sys\nreal = u.find_spec\n"
            "u.find_spec = lambda name, *a: None if name in ('distributed', 'xarray', 'netCDF4') else real(name, *a)\n"
            "from afmkit.study.__main__ import main\nsys.exit(main(sys.argv[1:]))\n")

    def study_run(*extra):
        return subprocess.run([sys.executable, "-c", code, "run", str(study), "--quiet", *extra], capture_output=True,
                              text=True, timeout=120)

    ok = study_run("--store", str(tmp_path / "a.zarr"))
    assert ok.returncode == 0, ok.stderr
    address = study_run("--store", str(tmp_path / "b.zarr"), "--scheduler", "tcp://127.0.0.1:1")
    assert address.returncode == 1 and "needs the Debian packages python3-distributed" in address.stderr
    assert not (tmp_path / "b.zarr").exists()
    netcdf = study_run("--store", str(tmp_path / "c.zarr"), "--netcdf", str(tmp_path / "c.nc"))
    assert netcdf.returncode == 1 and "python3-xarray python3-netcdf4" in netcdf.stderr
