"""afmkit.spectroscopy_fit on NumPy arrays (SI units): synthetic DMT + vdW data made by afmkit's own forward model
with known parameters and noise (fixed seed) are fitted back within their standard errors; a parameter the data
do not depend on is reported; bad input raises InvalidParameter naming the parameter; the plot is a PNG."""
import inspect
import os
import re
import subprocess

import numpy as np
import pytest

import afmkit
from afmkit import spectroscopy_fit as sf

SETTINGS = dict(spring_constant=40.0, resonance_frequency=300e3, quality_factor=400.0, free_amplitude=20e-9)
TRUTH = {"hamaker": 1e-19, "effective_modulus": 1e9, "distance_offset": 0.7e-9}
SIGMA_A, SIGMA_P = 0.003, 0.005


def synthetic(z, seed):
    p = sf.predict(z, values={"effective_modulus": TRUTH["effective_modulus"], "tip_radius": 10e-9,
                              "hamaker": TRUTH["hamaker"]},
                   calibration={"distance_offset": TRUTH["distance_offset"]}, **SETTINGS)
    rng = np.random.default_rng(seed)
    return (p["amplitude"] + SIGMA_A * SETTINGS["free_amplitude"] * rng.standard_normal(z.size),
            p["phase"] + SIGMA_P * rng.standard_normal(z.size))


def test_the_forward_model_is_the_tapping_sweep():
    # the same approach through afmkit.tapping.sweep (the command, physical units: nm, kHz, GPa)
    z = np.linspace(22e-9, 12e-9, 11)
    p = sf.predict(z, values={"effective_modulus": 1e9, "tip_radius": 10e-9, "hamaker": 1e-19},
                   **dict(SETTINGS, quality_factor=100.0))
    r = afmkit.tapping.sweep(units="physical", law="dmt", spring_constant=40.0, resonance_frequency=300.0,
                             quality_factor=100.0, free_amplitude=20.0, effective_modulus=1.0, tip_radius=10.0,
                             hamaker=1e-19, separations=list(z * 1e9), quiet=True)
    approach = np.asarray(r["direction"]) == "approach"
    sep = np.asarray(r["separation"])[approach]
    amp = np.asarray(r["amplitude"])[approach]
    for zi, ai in zip(z, p["amplitude"]):
        k = np.argmin(abs(sep - zi * 1e9))
        assert ai * 1e9 == pytest.approx(amp[k], abs=1e-6)  # nm: the fit's looser tolerances


def test_dmt_parameters_come_back_within_their_standard_errors(tmp_path):
    z = np.linspace(21e-9, 4e-9, 60)
    a, ph = synthetic(z, 1)
    r = sf.fit(z, a, ph, parameters=["hamaker", "effective_modulus", "distance_offset", "phase_offset"],
               initial={"hamaker": 1.3e-19, "effective_modulus": 0.7e9, "distance_offset": 0.4e-9},
               fixed={"tip_radius": 10e-9}, amplitude_noise=SIGMA_A, phase_noise=SIGMA_P, **SETTINGS)
    assert r.status == "ok", r.solver_status
    truth = dict(TRUTH, phase_offset=0.0)
    for name in r.names:
        assert abs(r.estimates[name] - truth[name]) < 3 * r.standard_errors[name], (name, r)
    assert r.units["effective_modulus"] == "Pa" and r.units["distance_offset"] == "m"
    assert r.correlation.shape == (4, 4) and np.allclose(np.diag(r.correlation), 1.0)
    assert np.allclose(r.correlation, r.correlation.T)
    assert r.rms_amplitude == pytest.approx(SIGMA_A, rel=0.3)
    assert np.degrees(r.rms_phase) == pytest.approx(np.degrees(SIGMA_P), rel=0.3)
    assert r.orbit_evaluations > 0 and r.curve_evaluations > 4 and r.seconds > 0
    assert r.fitted_amplitude.shape == z.shape and r.law_values["tip_radius"] == 10e-9
    png = r.plot(str(tmp_path / "fit.png"))
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_a_modulus_the_tip_never_feels_is_not_identifiable():
    z = np.linspace(28e-9, 21.5e-9, 25)  # separations >= 22.2 nm > A0: never in contact
    a, ph = synthetic(z, 3)
    r = sf.fit(z, a, ph, parameters=["hamaker", "effective_modulus"],
               initial={"hamaker": 1.3e-19, "effective_modulus": 0.7e9, "distance_offset": 0.7e-9},
               fixed={"tip_radius": 10e-9}, **SETTINGS)
    assert not r.contact.any()
    assert r.identifiable["effective_modulus"] is False
    assert np.isinf(r.standard_errors["effective_modulus"])
    assert any("effective_modulus is not identifiable" in w for w in r.warnings)


def test_bad_input_names_the_parameter():
    z = np.linspace(30e-9, 20e-9, 5)
    a = np.full(5, 10e-9)
    with pytest.raises(afmkit.InvalidParameter, match="spring_constant"):
        sf.fit(z, a, None, **dict(SETTINGS, spring_constant=-1.0))
    with pytest.raises(afmkit.InvalidParameter, match="amplitude has 4 values"):
        sf.fit(z, a[:4], None, **SETTINGS)
    with pytest.raises(afmkit.InvalidParameter, match=r"amplitude\[2\]"):
        sf.fit(z, np.where(np.arange(5) == 2, np.nan, a), None, **SETTINGS)
    with pytest.raises(afmkit.InvalidParameter, match="is not a parameter of law = dmt"):
        sf.fit(z, a, None, parameters=["viscosity"], **SETTINGS)
    with pytest.raises(afmkit.InvalidParameter, match="direction"):
        sf.fit(z, a, None, direction="sideways", **SETTINGS)


def test_the_solver_settings_are_declared_once():
    # the NumPy function and the command take the solver's settings and defaults from spectroscopy::FitOptions
    defaults = sf._SOLVER_DEFAULTS
    assert set(defaults) == {"huber", "fd_step", "max_evaluations", "tolerance", "integrator_tolerance",
                             "shooting_tolerance", "correlation_limit", "condition_limit", "flat_column"}
    signature = inspect.signature(sf.run).parameters  # the command `afmkit spectroscopy fit`
    for key, value in defaults.items():
        assert signature[key].default == value, key
    assert isinstance(defaults["max_evaluations"], int)
    # the library checks the declared range, naming the key
    z = np.linspace(30e-9, 20e-9, 5)
    a = np.full(5, 10e-9)
    with pytest.raises(afmkit.InvalidParameter, match=r"huber = -1 is out of range: must be >= 0"):
        sf.fit(z, a, None, huber=-1, **SETTINGS)
    with pytest.raises(afmkit.InvalidParameter, match=r"max_evaluations = 1 is out of range"):
        sf.fit(z, a, None, max_evaluations=1.0, **SETTINGS)
    with pytest.raises(TypeError, match="unexpected keyword argument 'hubert'"):
        sf.fit(z, a, None, hubert=1.0, **SETTINGS)


def test_the_command_line_plot_is_drawn_by_matplotlib(tmp_path):
    cli = os.environ.get("AFMKIT_CLI")
    source = os.path.abspath(os.environ.get("AFMKIT_SOURCE_DIR", ""))
    if not cli or not os.environ.get("AFMKIT_SOURCE_DIR"):
        pytest.skip("AFMKIT_CLI / AFMKIT_SOURCE_DIR not set")
    config = os.path.join(source, "examples", "configs", "spectroscopy_fit.toml")
    out = subprocess.run([cli, "spectroscopy", "fit", "--config", config, "--file",
                          os.path.join(source, "examples", "configs", "am_curve_dmt.csv"), "--output",
                          str(tmp_path / "fit.csv"), "--plot", str(tmp_path / "fit.png")],
                         capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "hamaker = " in out.stdout and "wrote the plot" in out.stdout
    with open(tmp_path / "fit.png", "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_a_law_object_stands_for_its_name_and_its_values_in_si():
    # afmkit.laws.DMT takes the units of docs/force-laws.md (GPa, nm, J); the fit's values are SI, written here by hand
    z = np.linspace(22e-9, 14e-9, 5)
    law = afmkit.laws.DMT(effective_modulus=2.0, tip_radius=8.0, hamaker=1e-19)
    by_object = sf.predict(z, law=law, **SETTINGS)
    by_hand = sf.predict(z, law="dmt", values={"effective_modulus": 2e9, "tip_radius": 8e-9, "hamaker": 1e-19},
                         **SETTINGS)
    default = sf.predict(z, law="dmt", **SETTINGS)
    np.testing.assert_array_equal(by_object["amplitude"], by_hand["amplitude"])
    np.testing.assert_array_equal(by_object["phase"], by_hand["phase"])
    assert not np.array_equal(by_object["amplitude"], default["amplitude"])  # the values were used
    with pytest.raises(ValueError, match="tip_radius is given both in the law"):
        sf.predict(z, law=law, values={"tip_radius": 8e-9}, **SETTINGS)
    with pytest.raises(ValueError, match="tip_radius is given both in the law"):
        sf.fit(z, by_hand["amplitude"], law=law, fixed={"tip_radius": 8e-9}, **SETTINGS)
    with pytest.raises(TypeError, match="law: a law written in Python"):
        sf.fit(z, by_hand["amplitude"], law=afmkit.laws.Python(approach=lambda d: 0 * d), **SETTINGS)


def _command_line_upper_si(key):
    """The upper end of `key`'s range as `afmkit spectroscopy fit --help` states it, in SI (its unit: kHz, nm)."""
    out = subprocess.run([os.environ.get("AFMKIT_CLI", "afmkit"), "spectroscopy", "fit", "--help"],
                         capture_output=True, text=True, check=True).stdout
    line = next(l for l in out.splitlines() if l.strip().startswith("--" + key.replace("_", "-") + " "))
    unit = re.search(r"unit: ([^;\]]+)", line).group(1).strip()
    upper = float(re.search(r"in \[0, ([^\]]+)\]", line).group(1))
    return upper * {"N/m": 1.0, "kHz": 1e3, "dimensionless": 1.0, "nm": 1e-9}[unit]


@pytest.mark.parametrize("fm", [False, True])
def test_every_cantilever_setting_out_of_its_range_is_refused_like_the_command_line(fm):
    # the Python (SI) path and the command line (kHz, nm) take one declaration of the ranges: a value just above the
    # command line's bound, in SI, is refused naming the key and the range; the bound itself is the command line's
    z = np.linspace(30e-9, 20e-9, 5)
    length = "amplitude" if fm else "free_amplitude"
    settings = dict(spring_constant=40.0, resonance_frequency=300e3, quality_factor=400.0)
    settings[length] = 5e-9 if fm else 20e-9
    expected_unit = {"spring_constant": " N/m", "resonance_frequency": " Hz", "quality_factor": "", length: " m"}
    for key, unit in expected_unit.items():
        upper = _command_line_upper_si(key)
        assert upper == pytest.approx({"spring_constant": 1e6, "resonance_frequency": 1e10, "quality_factor": 1e9,
                                       length: 1e-3}[key], rel=1e-12)
        for bad in (upper * 1.001, 1e300, float("inf"), float("nan"), 0.0, -1.0):
            message = rf"{key} = \S+{unit} is out of range: must be > 0 and <= {re.escape(f'{upper:g}')}{unit}$"
            with pytest.raises(afmkit.InvalidParameter, match=message):
                if fm:
                    sf.fit_fm(z, np.full(5, -1.0), **dict(settings, **{key: bad}))
                else:
                    sf.fit(z, np.full(5, 10e-9), None, **dict(settings, **{key: bad}))
    if not fm:  # the forward model takes the same settings
        with pytest.raises(afmkit.InvalidParameter, match=r"quality_factor = 2000000000 is out of range"):
            sf.predict(z, **dict(settings, quality_factor=2e9))
        with pytest.raises(afmkit.InvalidParameter, match=r"drive_frequency = 20000000000 Hz is out of range"):
            sf.fit(z, np.full(5, 10e-9), None, drive_frequency=2e10, **settings)
