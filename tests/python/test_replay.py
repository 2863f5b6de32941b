"""Every command replays from its own record (issue 26 §2): `f(**r.params)` gives the same table bit for bit, and
`afmkit <command> --config <sidecar>` writes the same CSV byte for byte. The record lists only the parameters that
applied (the unit system and the force law in use). Small problems: each run takes well under a second."""
import json
import os
import subprocess

import numpy as np
import pytest

from afmkit import _afmkit
from afmkit._commands import make_command

CLI = os.environ.get("AFMKIT_CLI", "")
SOURCE = os.path.abspath(os.environ.get("AFMKIT_SOURCE_DIR", "."))
CONFIGS = os.path.join(SOURCE, "examples", "configs")

AM_CURVE = ("distance (nm), amplitude (nm), phase (deg)\n40, 10, 90.1\n38, 10, 90.3\n36, 10, 89.9\n"
            "34, 10, 90.2\n")


def _am_file(d):
    (d / "am.csv").write_text(AM_CURVE)
    return str(d / "am.csv")


# Small problems per command (the keyword arguments, TOML keys); `d`: the test's folder. Physical units and a law
# other than the default where a command has them, so that the record's choice of keys is exercised.
CASES = {
    "demo": lambda d: dict(points=5, output_dir=str(d / "demo")),
    "impact": lambda d: dict(law="dmt", hamaker=1e-19, mass1=1e-11, mass2=1.0, velocity=1e6, gap=2.0, points=50),
    "tapping orbit": lambda d: dict(units="physical", law="dmt", separation=15.0, free_amplitude=10.0),
    "tapping hb": lambda d: dict(points=50, law="attractive", approach_adhesion=0.5, departure_adhesion=1.0),
    "tapping sweep": lambda d: dict(separation_min=7.0, separation_max=9.0, points=3, mode="instrument", quiet=True),
    "tapping fm": lambda d: dict(separation_min=7.0, separation_max=9.0, points=3, quiet=True),
    "tapping image": lambda d: dict(pixels=8, lines=4, map_points=40, sample="steps", image_output="", quiet=True),
    "tapping modes": lambda d: dict(units="physical", law="dmt", quality_factor=20.0, separation_min=16.0,
                                    separation_max=18.0, points=2, settle_periods=20, lockin_periods=4, quiet=True),
    "control tf": lambda d: dict(harmonics=3, points=20, plant_rate=7.0),
    "control roots": lambda d: dict(harmonics=3),
    "control margin": lambda d: dict(harmonics=3, controller="smith"),
    "control chart": lambda d: dict(harmonics=2, x_points=6, y_points=5, delays=[0.1, 0.2],
                                    boundaries_output=str(d / "boundaries.csv"), progress=False),
    "control tune": lambda d: dict(harmonics=2, coarse_points=6, progress=False),
    "control simulate": lambda d: dict(harmonics=2, periods=3, steps_per_period=64),  # random phases: recorded
    "control export": lambda d: dict(harmonics=3, sample_rate=1000.0, output=str(d / "filter.h")),
    "scan": lambda d: dict(end_radius=2e-4, sample_resolution=64, image_resolution=32, sample_rate=5e3,
                           spindle_frequency=50.0, radial_speed=5e-4, harmonics=2, image_output=""),
    "spectroscopy prepare": lambda d: dict(
        input=os.path.join(SOURCE, "examples", "force_curves", "raw_hertz_curve.txt"), segment_column="segment",
        spring_constant=0.1, invols=50.0, contact_method="hertz", tip_radius=2000.0, poisson_ratio=0.5,
        allow_energy_gain=True),
    "spectroscopy reconstruct": lambda d: dict(input=os.path.join(CONFIGS, "fm_curve_dmt.csv"),
                                               method="sader_jarvis", tail="zero", spring_constant=40.0,
                                               resonance_frequency=300.0, amplitude=2.0, law_output=""),
    "spectroscopy fit": lambda d: dict(file=_am_file(d), spring_constant=40.0, resonance_frequency=300.0,
                                       quality_factor=100.0, free_amplitude=10.0, parameters="phase_offset"),
}
PATHS = [s["path"] for s in _afmkit.commands()]


def test_every_command_has_a_case():
    assert set(CASES) == set(PATHS), "add a small case for every command of afmkit.commands()"


def same_table(a, b):
    assert a.columns == b.columns
    for c in a.columns:
        x, y = a[c], b[c]
        assert x.dtype == y.dtype and x.shape == y.shape, c
        if x.dtype.kind in "fb":
            assert x.tobytes() == y.tobytes(), c  # bit for bit (NaN included)
        else:
            assert list(x) == list(y), c


@pytest.mark.parametrize("path", PATHS)
def test_python_replays_from_its_record(path, tmp_path):
    f = make_command(path)
    r = f(**CASES[path](tmp_path))
    again = f(**r.params)  # the record as it is: nothing to leave out
    assert again.params == r.params
    same_table(r, again)
    assert len(r) > 0 or path in ("control export", "demo")  # these write files only


CONTROLLER_KEYS = {"single": {"a", "b"}, "bank": {"alpha", "beta", "rejected"}, "infinite": {"alpha", "beta"}}
SMITH_KEYS = {"smith_bank", "smith_structure", "model_plant", "model_rate", "model_delay"}


@pytest.mark.parametrize("path", ["control tf", "control margin", "control simulate", "control tune"])
@pytest.mark.parametrize("kind", ["single", "bank", "infinite", "smith"])
def test_a_control_record_holds_only_the_controller_in_use_and_replays(path, kind, tmp_path):
    if (path, kind) == ("control simulate", "smith"):
        pytest.skip("the Smith predictor is not simulated in the time domain (refused as bad input)")
    f = make_command(path)
    r = f(**{**CASES[path](tmp_path), "controller": kind})
    inner = "bank" if kind == "smith" else kind  # smith_bank's default
    keys = set(r.params)
    every = set().union(*CONTROLLER_KEYS.values())
    assert CONTROLLER_KEYS[inner] <= keys and not (every - CONTROLLER_KEYS[inner]) & keys, sorted(keys)
    assert (SMITH_KEYS <= keys) if kind == "smith" else not SMITH_KEYS & keys, sorted(keys)
    again = f(**r.params)
    assert again.params == r.params
    same_table(r, again)


def test_an_fm_fit_records_the_parameters_it_fitted(tmp_path):
    # the FM default of `parameters` differs from the declared (AM) default: the record names what was fitted
    fit = make_command("spectroscopy fit")
    r = fit(file=os.path.join(CONFIGS, "fm_fit_curve_dmt.csv"), spring_constant=40.0, resonance_frequency=300.0,
            quality_factor=400.0, amplitude=5.0, max_evaluations=2)
    assert r.params["parameters"] == "hamaker,effective_modulus,distance_offset"
    same_table(r, fit(**r.params))


def test_the_record_holds_only_the_unit_system_and_law_in_use(tmp_path):
    orbit = make_command("tapping orbit")(**CASES["tapping orbit"](tmp_path)).params
    assert {"spring_constant", "resonance_frequency", "hamaker", "departure_hamaker", "tip_radius"} <= set(orbit)
    assert orbit["departure_hamaker"] == orbit["hamaker"]  # follows hamaker: the value used
    assert not {"natural_frequency", "drive_amplitude", "approach_stiffness", "sample_stiffness_approach",
                "force_curve", "viscosity", "adhesion_energy"} & set(orbit)
    hb = make_command("tapping hb")(**CASES["tapping hb"](tmp_path)).params
    assert {"natural_frequency", "approach_stiffness", "approach_adhesion"} <= set(hb)
    assert not {"spring_constant", "sample_stiffness_approach", "adhesion_approach", "hamaker", "tip_radius",
                "force_curve"} & set(hb)
    impact = make_command("impact")(**CASES["impact"](tmp_path)).params
    assert "hamaker" in impact and not {"approach_stiffness", "restitution", "viscosity"} & set(impact)


def _toml(kwargs):
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(repr(float(x)) for x in v) + "]"
        return json.dumps(v) if isinstance(v, str) else repr(v)
    return "".join(f"{k} = {value(v)}\n" for k, v in kwargs.items())


# the CSV tables a command writes: (key of its path, file name)
TABLES = {"demo": [("output_dir", "demo_sweep.csv"), ("output_dir", "demo_hb.csv")]}
NO_SIDECAR = {"control export": "the C header has no sidecar: its record is r.params (Python) and the header's "
                                "own comment"}


@pytest.mark.skipif(not CLI, reason="AFMKIT_CLI not set")
@pytest.mark.parametrize("path", [p for p in PATHS if p not in NO_SIDECAR])
def test_the_command_line_replays_from_its_sidecar(path, tmp_path):
    first, second = tmp_path / "first", tmp_path / "second"
    first.mkdir()
    second.mkdir()
    kwargs = CASES[path](first)
    if path in TABLES:
        kwargs[TABLES[path][0][0]] = str(first / "out")
    else:
        kwargs["output"] = str(first / "table.csv")
    (first / "case.toml").write_text(_toml(kwargs))
    run = subprocess.run([CLI, *path.split(), "--config", str(first / "case.toml")], capture_output=True, text=True,
                         cwd=first)
    assert run.returncode == 0, run.stderr
    if path in TABLES:
        key, names = TABLES[path][0][0], [n for _, n in TABLES[path]]
        sidecar = first / "out" / (names[0] + ".json")
        flag = ["--" + key.replace("_", "-"), str(second / "out")]
        pairs = [(first / "out" / n, second / "out" / n) for n in names]
    else:
        sidecar = first / "table.csv.json"
        flag = ["--output", str(second / "table.csv")]
        pairs = [(first / "table.csv", second / "table.csv")]
    recorded = json.loads(sidecar.read_text())["parameters"]
    # other outputs of the record go to the second folder (the replay must not depend on where they are)
    for k, v in recorded.items():
        if isinstance(v, str) and v.startswith(str(first)) and "--" + k.replace("_", "-") not in flag and k != "input" \
                and k != "file":
            flag += ["--" + k.replace("_", "-"), v.replace(str(first), str(second))]
    again = subprocess.run([CLI, *path.split(), "--config", str(sidecar), *flag], capture_output=True, text=True,
                           cwd=second)
    assert again.returncode == 0, again.stderr
    for a, b in pairs:
        assert a.read_bytes() == b.read_bytes(), f"{path}: {b.name} differs from the recorded run's"
    replayed = json.loads((pairs[0][1].parent / (pairs[0][1].name + ".json")).read_text())["parameters"]
    assert set(replayed) == set(recorded)


def test_an_explicit_list_of_separations_is_recorded_instead_of_the_grid(tmp_path):
    for path in ("tapping sweep", "tapping fm"):
        f = make_command(path)
        r = f(separations=[9.0, 8.0, 7.5], quiet=True)
        assert r.params["separations"] == [9.0, 8.0, 7.5]
        assert not {"separation_min", "separation_max", "points", "separations_file"} & set(r.params), path
        again = f(**r.params)
        same_table(r, again)
        assert sorted(set(r["separation"])) == [7.5, 8.0, 9.0]  # the list, not the declared grid


def test_a_recorded_scan_records_no_key_of_the_simulated_instrument_and_replays(tmp_path):
    recorded = os.path.join(SOURCE, "examples", "recorded", "spiral.csv")
    f = make_command("scan")
    r = f(recorded=recorded, image_resolution=100, image_output="")
    assert r.params["recorded"] == recorded
    # refused when given with recorded (simulation_only_keys): so never in its record
    assert not {"sample", "sample_file", "spindle_frequency", "bandwidth", "gain", "delay", "control"} & set(r.params)
    same_table(r, f(**r.params))
    if CLI:
        out = tmp_path / "turns.csv"
        run = subprocess.run([CLI, "scan", "--recorded", recorded, "--image-resolution", "100", "--image-output", "",
                              "--output", str(out)], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        again = subprocess.run([CLI, "scan", "--config", str(out) + ".json", "--output", str(tmp_path / "again.csv")],
                               capture_output=True, text=True)
        assert again.returncode == 0, again.stderr
        assert (tmp_path / "again.csv").read_bytes() == out.read_bytes()
