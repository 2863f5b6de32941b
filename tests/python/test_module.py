"""The Python module afmkit against the command line it shares its code with: the same keys, the same numbers,
the same messages (docs/python.md)."""
import inspect
import json
import math
import os
import subprocess

import numpy as np
import pytest

import afmkit
import afmkit.spectroscopy_reconstruct

CLI = os.environ["AFMKIT_CLI"]


def cli(*args, cwd=None):
    return subprocess.run([CLI, *args], capture_output=True, text=True, cwd=cwd)


def cli_table(*args):
    """The table of `afmkit <args> --json --output ""`: columns and rows, as the command line prints them."""
    r = cli(*args, "--json", "--output", "")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    return doc


def test_every_command_of_the_program_is_a_function_with_its_toml_keys():
    from afmkit import _afmkit

    paths = {s["path"] for s in _afmkit.commands()}
    functions = {"impact": afmkit.impact, "scan": afmkit.scan, "demo": afmkit.demo,
                 "tapping orbit": afmkit.tapping.orbit, "tapping hb": afmkit.tapping.hb,
                 "tapping sweep": afmkit.tapping.sweep, "tapping fm": afmkit.tapping.fm,
                 "tapping image": afmkit.tapping.image,
                 "tapping modes": afmkit.tapping.modes,
                 "control tf": afmkit.control.tf,
                 "control roots": afmkit.control.roots, "control margin": afmkit.control.margin,
                 "control chart": afmkit.control.chart, "control tune": afmkit.control.tune,
                 "control simulate": afmkit.control.simulate, "control export": afmkit.control.export,
                 "spectroscopy prepare": afmkit.spectroscopy.prepare_file,
                 "spectroscopy reconstruct": afmkit.spectroscopy.reconstruct}
    # `report` is afmkit.report.build, `study run` afmkit.study.run, `tapping grid` a study: not command functions;
    # `spectroscopy fit` is afmkit.spectroscopy_fit.run (and .fit on arrays)
    assert paths - {"spectroscopy fit"} == set(functions)
    for path, fn in functions.items():
        help_text = cli(*path.split(), "--help").stdout + cli(*path.split(), "--units", "physical", "--help").stdout
        help_text += cli(*path.split(), "--units", "normalised", "--help").stdout  # tapping image: physical by default
        keys = [p for p in inspect.signature(fn).parameters if p != "config"]
        for key in keys:  # every keyword is an option of the command line (key with '-' for '_')
            assert "--" + key.replace("_", "-") in help_text, (path, key)
        assert fn.__doc__ and "quality_factor" in afmkit.tapping.hb.__doc__


@pytest.mark.parametrize("command,args", [
    ("tapping hb", {"quality_factor": 150.0, "points": 300}),
    ("control tf", {"harmonics": 4, "points": 200}),
    ("tapping sweep", {"points": 15}),
    ("tapping fm", {"points": 9}),
    ("impact", {"restitution": 0.7, "points": 300}),
    ("tapping orbit", {"quality_factor": 2.0, "separation": 5.0}),
])
def test_result_equals_the_command_lines_table_bit_for_bit(command, args):
    module, _, name = command.rpartition(" ")
    fn = getattr(getattr(afmkit, module) if module else afmkit, name)
    r = fn(**args)
    flags = [x for k, v in args.items() for x in ("--" + k.replace("_", "-"), repr(v) if isinstance(v, float) else str(v))]
    doc = cli_table(*command.split(), *flags)["table"]
    names = [c["name"] if isinstance(c, dict) else c for c in doc["columns"]]
    assert names == r.columns
    rows = doc["rows"]
    assert len(rows) == len(r) > 0
    for i, col in enumerate(names):
        cells = [row[i] for row in rows]
        if r[col].dtype.kind == "f":
            want = np.array([math.nan if c is None else float(c) for c in cells])
            np.testing.assert_array_equal(r[col], want, err_msg=col)
        elif r[col].dtype.kind == "b":  # a flag: true/false (or 0/1) in the document
            assert r.units[col].startswith("boolean") and all(c in (0, 1) for c in cells), col
            assert list(r[col]) == [c == 1 for c in cells], col
        else:  # text: the array numpy.array(list of str, "str") makes (dtype '<U' of the longest)
            want = np.array([str(c) for c in cells], "str")
            assert r[col].dtype == want.dtype and list(r[col]) == list(want), col
        assert r.units[col] == doc["columns"][i]["unit"] and r.meaning[col] == doc["columns"][i]["description"]


def test_orbit_results_equal_the_command_lines_document():
    # the summary reaches Python through the C API (records of an array share their key objects): the same document
    # as the command line's --json, value for value (the search's own duration aside)
    args = {"quality_factor": 2.0, "separation": 5.0}
    r = afmkit.tapping.orbit(**args)
    doc = cli_table("tapping", "orbit", *[x for k, v in args.items() for x in ("--" + k.replace("_", "-"), repr(v))])
    del doc["table"]
    got = json.loads(json.dumps(r.results))
    for d in (doc, got):
        d["search"]["seconds"] = 0.0
    assert got == doc
    assert len(got["search"]["seeds"]) > 10 and {"kind", "orbits"} <= set(got["search"]["seeds"][-1])
    assert got["units"]["search"]["seeds"]["initial_position"] == "L"


def test_numpy_scalars_are_accepted():
    a = afmkit.tapping.hb(quality_factor=np.float64(150), points=np.int64(300))
    b = afmkit.tapping.hb(quality_factor=150.0, points=300)
    np.testing.assert_array_equal(a["amplitude"], b["amplitude"])


@pytest.mark.parametrize("call,argument,exc", [
    (lambda: afmkit.tapping.hb(quality_factor="high"), "quality_factor", TypeError),
    (lambda: afmkit.tapping.hb(points=2.5), "points", TypeError),
    (lambda: afmkit.tapping.hb(points=True), "points", TypeError),
    (lambda: afmkit.tapping.hb(quality_factor=-1.0), "quality_factor", ValueError),
    (lambda: afmkit.tapping.hb(quality_factor=math.nan), "quality_factor", ValueError),
    (lambda: afmkit.tapping.hb(qualityfactor=100.0), "qualityfactor", TypeError),
    (lambda: afmkit.control.tf(harmonics=0), "harmonics", ValueError),
    (lambda: afmkit.tapping.hb(law="no-such-law"), "law", ValueError),
    (lambda: afmkit.tapping.hb(points=10**30), "points", ValueError),          # beyond any C integer
    (lambda: afmkit.tapping.hb(quality_factor=10**400), "quality_factor", ValueError),  # beyond double
    (lambda: afmkit.tapping.hb(quality_factor=np.array([3.0])), "quality_factor", TypeError),  # an array
    (lambda: afmkit.tapping.sweep(separations=np.ones((2, 2))), "separations", TypeError),
    (lambda: afmkit.tapping.sweep(separations="10,9"), "separations", TypeError),
    (lambda: afmkit.tapping.sweep(separations=[10.0, math.nan]), "separations", ValueError),
    (lambda: afmkit.tapping.hb(json=False), "json", TypeError),                # not a keyword from Python
    (lambda: afmkit.tapping.hb(config=3), "config", TypeError),
])
def test_bad_arguments_raise_naming_the_argument(call, argument, exc):
    with pytest.raises(exc) as e:
        call()
    assert argument in str(e.value)


def test_value_errors_carry_the_command_lines_message():
    for kwargs, flags in [({"quality_factor": -1.0}, ["--quality-factor", "-1"]),
                          ({"approach_stiffness": 1.0, "departure_stiffness": 2.0},
                           ["--approach-stiffness", "1", "--departure-stiffness", "2"])]:
        with pytest.raises(ValueError) as e:
            afmkit.tapping.hb(**kwargs)
        r = cli("tapping", "hb", *flags, "--output", "")
        assert r.returncode == 2
        assert str(e.value) in r.stderr, (str(e.value), r.stderr)
        assert isinstance(e.value, afmkit.InvalidParameter)
        assert e.value.parameter in kwargs


def test_lists_take_numpy_arrays():
    a = afmkit.tapping.sweep(separations=np.array([10.0, 9.0, 8.0]))
    b = afmkit.tapping.sweep(separations=[10, 9, 8])
    assert len(a) == len(b) > 0
    for c in a.columns:
        np.testing.assert_array_equal(a[c], b[c])


def test_python_calls_write_no_file_unless_asked(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for fn in [afmkit.tapping.hb, afmkit.control.chart, afmkit.control.tf]:
        sig = inspect.signature(fn).parameters
        assert "json" not in sig
        for key, p in sig.items():
            if key == "output" or key.endswith("_output"):
                assert p.default == "", (fn.__name__, key)
    afmkit.control.chart(x_points=6, y_points=5, progress=False)
    afmkit.tapping.hb(points=50)
    assert list(tmp_path.iterdir()) == []
    r = afmkit.tapping.hb(points=50, output="hb.csv")  # asked: the CSV and its sidecar, as the command line writes
    assert (tmp_path / "hb.csv").is_file() and (tmp_path / "hb.csv.json").is_file()
    header = (tmp_path / "hb.csv").read_text().splitlines()[0].split(",")
    assert header == r.columns


def test_config_file_then_keywords(tmp_path):
    cfg = tmp_path / "run.toml"
    cfg.write_text("quality_factor = 250.0\npoints = 120\n")
    r = afmkit.tapping.hb(config=str(cfg))
    assert r.params["quality_factor"] == 250.0 and len(r) > 0
    r2 = afmkit.tapping.hb(config=cfg, points=80)  # os.PathLike, and a keyword over the file
    assert r2.params["points"] == 80 and r2.params["quality_factor"] == 250.0
    bad = tmp_path / "bad.toml"
    bad.write_text("quality_factor = [1, 2]\n")
    with pytest.raises(ValueError) as e:
        afmkit.tapping.hb(config=str(bad))
    assert "quality_factor" in str(e.value)


def test_result_describes_its_columns():
    r = afmkit.tapping.hb(points=100)
    assert "amplitude" in r and r.units["amplitude"] and r.meaning["amplitude"]
    assert r["amplitude"].dtype == np.float64
    with pytest.raises(KeyError, match="no column 'nope'"):
        r["nope"]
    assert "afmkit.Result of tapping hb" in repr(r)


def test_realtime_filter_block_equals_sample_loop():
    kw = dict(rotation_frequency=2 * np.pi * 50.0, harmonics=4, sample_rate=20000.0)
    m = np.random.default_rng(7).standard_normal(5001)
    block = afmkit.control.RealtimeFilter(**kw)
    u_block = block.step_block(m)
    loop = afmkit.control.RealtimeFilter(**kw)
    np.testing.assert_array_equal(u_block, [loop.step(x) for x in m])
    out = np.empty_like(m)
    again = afmkit.control.RealtimeFilter(**kw)
    assert again.step_block(m, out) is out
    np.testing.assert_array_equal(out, u_block)
    with pytest.raises(ValueError, match="out must be"):
        again.step_block(m, np.empty(len(m), dtype=np.float32))  # never a silently converted copy
    with pytest.raises(ValueError, match="out must be"):
        again.step_block(m, np.empty(len(m) - 1))


def test_realtime_filter_in_a_closed_loop_removes_the_first_harmonic_and_keeps_the_third():
    # the loop of docs/embedding.md: static plant with one sample of latency, m_n = d_n + u_{n-1}/K, K = gain * Omega
    omega, rate, gain = 2 * np.pi * 50.0, 20000.0, 20.0
    f = afmkit.control.RealtimeFilter(rotation_frequency=omega, harmonics=4, sample_rate=rate, gain=gain)
    t = np.arange(40000) / rate
    d = 1.0 * np.sin(omega * t + 0.3) + 0.4 * np.cos(3 * omega * t)  # tilt + a third harmonic
    m = np.empty_like(d)
    u = 0.0
    for i in range(len(d)):
        m[i] = d[i] + u / (gain * omega)
        u = f.step(m[i])
    # independent check: a direct Fourier projection over the last 20 whole turns
    y, tt = m[-8000:], t[-8000:]
    first = abs(2 / len(y) * np.sum(y * np.exp(-1j * omega * tt)))
    third = abs(2 / len(y) * np.sum(y * np.exp(-3j * omega * tt)))
    assert first < 1e-9
    assert third == pytest.approx(0.4, rel=1e-4)


def test_realtime_filter_bad_arguments():
    omega = 2 * np.pi * 50.0
    with pytest.raises(ValueError, match="sample_rate"):
        afmkit.control.RealtimeFilter(rotation_frequency=omega, harmonics=4)
    with pytest.raises(ValueError, match="sample_rate"):
        afmkit.control.RealtimeFilter(rotation_frequency=omega, harmonics=4, sample_rate=-1.0)
    with pytest.raises(TypeError, match="output"):
        afmkit.control.RealtimeFilter(rotation_frequency=omega, harmonics=4, sample_rate=1e4, output="x.h")
    with pytest.raises(TypeError, match="harmonics"):
        afmkit.control.RealtimeFilter(rotation_frequency=omega, harmonics="ten", sample_rate=1e4)


def test_realtime_filter_state_round_trip():
    kw = dict(rotation_frequency=2 * np.pi * 50.0, harmonics=3, sample_rate=10000.0)
    m = np.sin(np.linspace(0, 60, 5000))
    a = afmkit.control.RealtimeFilter(**kw)
    a.step_block(m[:2500])
    saved = a.save_state()
    rest = a.step_block(m[2500:])
    b = afmkit.control.RealtimeFilter(**kw)
    b.restore_state(saved)
    np.testing.assert_array_equal(b.step_block(m[2500:]), rest)


def test_solver_runs_release_the_interpreter():
    import threading

    results = []
    threads = [threading.Thread(target=lambda: results.append(len(afmkit.tapping.hb(points=500)))) for _ in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert len(results) == 2 and results[0] == results[1] > 0
