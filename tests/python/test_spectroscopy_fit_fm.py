"""afmkit.spectroscopy.fit_fm on NumPy arrays (SI units): the FM forward model is the command `afmkit tapping fm`;
synthetic DMT + vdW frequency-shift data made by it with known parameters and noise (fixed seed) are fitted back
within 3 standard errors, the residuals are data − fit, plot_fit draws the FM curve; bad input raises
InvalidParameter naming the parameter; the command reads an FM file by its columns and draws its plot."""
import os
import subprocess

import numpy as np
import pytest

import afmkit
from afmkit import spectroscopy as sp

SETTINGS = dict(spring_constant=40.0, resonance_frequency=300e3, quality_factor=400.0, amplitude=5e-9)
LAW = {"effective_modulus": 1e9, "tip_radius": 10e-9, "hamaker": 1e-19}


def test_the_forward_model_is_the_tapping_fm_command():
    # the same approach through afmkit.tapping.fm (the command, physical units: nm, kHz, Hz)
    z = np.linspace(9e-9, 4e-9, 6)
    p = sp.predict_fm(z, values=LAW, **SETTINGS)
    r = afmkit.tapping.fm(units="physical", law="dmt", spring_constant=40.0, resonance_frequency=300.0,
                          quality_factor=400.0, amplitude=5.0, effective_modulus=1.0, tip_radius=10.0,
                          hamaker=1e-19, separation_min=4.0, separation_max=9.0, points=6, quiet=True)
    sep = np.asarray(r["separation"])
    df = np.asarray(r["frequency_shift"])
    for zi, fi in zip(z, p["frequency_shift"]):
        k = np.argmin(abs(sep - zi * 1e9))
        assert fi == pytest.approx(df[k], rel=1e-5, abs=1e-3)  # Hz: the fit's looser orbit tolerances


def test_dmt_parameters_come_back_within_their_standard_errors(tmp_path):
    z = np.linspace(10e-9, 3.5e-9, 50)
    p = sp.predict_fm(z, values=LAW, calibration={"distance_offset": 0.5e-9}, **SETTINGS)
    df = p["frequency_shift"] + 1.0 * np.random.default_rng(3).standard_normal(z.size)
    r = sp.fit_fm(z, df, parameters=["hamaker", "distance_offset"],
                  initial={"hamaker": 1.3e-19, "distance_offset": 0.2e-9},
                  fixed={"tip_radius": 10e-9, "effective_modulus": 1e9}, frequency_shift_noise=1.0, **SETTINGS)
    assert r.status == "ok" and r.mode == "fm", r.solver_status
    truth = {"hamaker": 1e-19, "distance_offset": 0.5e-9}
    for name in r.names:
        assert abs(r.estimates[name] - truth[name]) < 3 * r.standard_errors[name], (name, r)
    assert r.units == {"hamaker": "J", "distance_offset": "m"}
    assert r.correlation.shape == (2, 2) and np.allclose(np.diag(r.correlation), 1.0)
    assert r.rms_frequency_shift == pytest.approx(1.0, rel=0.3)
    assert r.dissipation is None and r.amplitude is None
    res = r.residuals()["frequency_shift"]
    order = np.argsort(-z)  # the result is in the sweep's order (approach: distance decreasing)
    assert np.allclose(r.distance, z[order]) and np.allclose(res, df[order] - r.fitted_frequency_shift)
    assert np.sqrt(np.mean(res ** 2)) == pytest.approx(r.rms_frequency_shift)
    png = sp.plot_fit(r, str(tmp_path / "fm.png"))
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_bad_input_names_the_parameter():
    z = np.linspace(30e-9, 20e-9, 5)
    df = np.full(5, -1.0)
    with pytest.raises(afmkit.InvalidParameter, match="amplitude"):
        sp.fit_fm(z, df, **dict(SETTINGS, amplitude=0.0))
    with pytest.raises(afmkit.InvalidParameter, match="frequency_shift has 4 values"):
        sp.fit_fm(z, df[:4], **SETTINGS)
    with pytest.raises(afmkit.InvalidParameter, match=r"dissipation\[1\]"):
        sp.fit_fm(z, df, np.array([0.0, np.nan, 0, 0, 0]), **SETTINGS)
    with pytest.raises(afmkit.InvalidParameter, match="not a calibration parameter of an FM curve"):
        sp.fit_fm(z, df, parameters=["phase_offset"], **SETTINGS)


def test_the_command_fits_an_fm_file_and_draws_it(tmp_path):
    cli = os.environ.get("AFMKIT_CLI")
    if not cli:
        pytest.skip("AFMKIT_CLI not set")
    z = np.linspace(9e-9, 4e-9, 12)
    p = sp.predict_fm(z, values=LAW, calibration={"frequency_shift_offset": 2.0}, **SETTINGS)
    with open(tmp_path / "df.csv", "w") as f:
        f.write("distance (nm), frequency shift (Hz)\n")
        f.writelines(f"{a * 1e9:.6f}, {b:.6f}\n" for a, b in zip(z, p["frequency_shift"]))
    out = subprocess.run([cli, "spectroscopy", "fit", "df.csv", "--spring-constant", "40", "--resonance-frequency",
                          "300", "--quality-factor", "400", "--amplitude", "5", "--hamaker", "1e-19", "--parameters",
                          "frequency_shift_offset", "--output", "fit.csv", "--plot", "fit.png"],
                         capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "Warning" not in out.stderr, out.stderr  # the plot's interpreter runs its module once (no runpy warning)
    assert "FM-AFM frequency shift" in out.stdout and "frequency_shift_offset = " in out.stdout
    import json
    with open(tmp_path / "fit.csv.json") as f:
        results = json.load(f)["results"]
    assert results["mode"] == "fm"
    assert results["estimates"]["frequency_shift_offset"]["value"] == pytest.approx(2.0, abs=1e-3)
    with open(tmp_path / "fit.png", "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
