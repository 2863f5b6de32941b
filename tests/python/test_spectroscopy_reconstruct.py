"""afmkit.spectroscopy_reconstruct: force reconstruction on NumPy arrays (docs/reconstruction.md)."""
import math
import os
import re
import subprocess

import numpy as np
import pytest

import afmkit
from afmkit import spectroscopy_reconstruct as sr

K, F0_HZ, FORCE0, LAM = 1800.0, 25e3, 1e-9, 0.1e-9


def _bessel_i1(x):
    return sum((x / 2) ** (2 * m + 1) / (math.factorial(m) * math.factorial(m + 1)) for m in range(60))


def _exponential_curve(a, n=300):
    z = np.linspace(0.05e-9, 2.05e-9, n)
    df = -(F0_HZ * FORCE0 / (K * a)) * np.exp(-(z + a) / LAM) * _bessel_i1(a / LAM)  # closed form, first order
    return z, df


@pytest.mark.parametrize("method", ["sader_jarvis", "matrix"])
def test_fm_recovers_the_exponential_force_with_units_and_round_trip(method):
    a = 0.5e-9
    z, df = _exponential_curve(a)
    r = sr.reconstruct_fm(z, df, spring_constant=K, resonance_frequency=F0_HZ, amplitude=a, method=method)
    truth = -FORCE0 * np.exp(-r.distance / LAM)
    assert np.max(np.abs(r.force - truth)) < 0.02 * FORCE0
    assert r.units["force"] == "N" and r.units["distance"] == "m" and r.units["residual"] == "Hz"
    assert r.residual_rms < 0.01 * np.max(np.abs(df))
    assert "exact FM orbits" in r.round_trip_model
    assert set(r.law) == {"distance", "approach_force", "retract_force"}
    np.testing.assert_allclose(r.law["approach_force"], r.force)


def test_fm_noise_is_reported_with_a_fixed_seed():
    a = 1e-9
    z, df = _exponential_curve(a, 400)
    rng = np.random.default_rng(5)
    noisy = df + rng.normal(0.0, 0.02 * np.max(np.abs(df)), df.size)
    r1 = sr.reconstruct_fm(z, noisy, spring_constant=K, resonance_frequency=F0_HZ, amplitude=a)
    r2 = sr.reconstruct_fm(z, noisy, spring_constant=K, resonance_frequency=F0_HZ, amplitude=a)
    np.testing.assert_array_equal(r1.force_uncertainty, r2.force_uncertainty)  # fixed seed
    assert r1.noise > 0.5 * 0.02 * np.max(np.abs(df))  # the estimate finds the noise added
    truth = -FORCE0 * np.exp(-r1.distance / LAM)
    # the error stays within 4 sigma of the reported uncertainty (plus the formula's own 5 %)
    near = r1.distance < 1e-9
    assert np.all(np.abs(r1.force - truth)[near] < 4 * r1.force_uncertainty[near] + 0.05 * FORCE0)


def test_fm_bad_input_names_the_parameter():
    z, df = _exponential_curve(1e-9, 20)
    bad = df.copy()
    bad[-3:] = np.nan
    with pytest.raises(afmkit.InvalidParameter, match=r"frequency_shift\[17\] = nan"):
        sr.reconstruct_fm(z, bad, spring_constant=K, resonance_frequency=F0_HZ, amplitude=1e-9)
    with pytest.raises(afmkit.InvalidParameter, match="amplitude"):
        sr.reconstruct_fm(z, df, spring_constant=K, resonance_frequency=F0_HZ, amplitude=0.0)
    zz = z.copy()
    zz[5] = zz[3]
    with pytest.raises(afmkit.InvalidParameter, match="not strictly monotone"):
        sr.reconstruct_fm(zz, df, spring_constant=K, resonance_frequency=F0_HZ, amplitude=1e-9)
    with pytest.raises(afmkit.InvalidParameter, match="method"):
        sr.reconstruct_fm(z, df, spring_constant=K, resonance_frequency=F0_HZ, amplitude=1e-9, method="payam")


def test_am_round_trip_on_an_exact_orbit_curve(tmp_path):
    # the synthetic curve: afmkit's own exact orbits (tapping sweep, approach) of a DMT + vdW law
    sweep = afmkit.tapping.sweep(units="physical", law="dmt", spring_constant=40.0, resonance_frequency=300.0,
                                 quality_factor=400.0, free_amplitude=10.0, separation_min=6.0,
                                 separation_max=12.0, points=30, output="")
    rows = [i for i, d in enumerate(sweep["direction"]) if d == "approach"]
    l = np.asarray(sweep["separation"])[rows] * 1e-9
    a = np.asarray(sweep["amplitude"])[rows] * 1e-9
    phi = np.asarray(sweep["phase"])[rows]
    r = sr.reconstruct_am(l, a, phi, spring_constant=40.0, resonance_frequency=300e3, quality_factor=400.0,
                          free_amplitude=10e-9, round_trip_points=15)
    assert r.units["force"] == "N" and r.units["dissipation"] == "J"
    assert r.rms_amplitude_ratio < 0.01 and r.rms_phase < 0.02
    path = r.write_law(str(tmp_path / "law.csv"))
    orbit = afmkit.tapping.orbit(units="physical", law="table", force_curve=path, spring_constant=40.0,
                                 resonance_frequency=300.0, quality_factor=400.0, free_amplitude=10.0,
                                 separation=float(l[len(l) // 2] * 1e9), output="")
    assert orbit.results is not None
    with pytest.raises(afmkit.InvalidParameter, match="phase"):
        sr.reconstruct_am(l, a, phi + 4.0, spring_constant=40.0, resonance_frequency=300e3, quality_factor=400.0,
                          free_amplitude=10e-9)


def test_cli_writes_the_table_and_a_law_the_tapping_commands_read(tmp_path):
    cli = os.environ.get("AFMKIT_CLI", "afmkit")
    a = 0.5e-9
    z, df = _exponential_curve(a, 200)
    src = tmp_path / "df.csv"
    src.write_text("distance (nm), frequency shift (Hz)\n" +
                   "".join(f"{zi * 1e9:.12g}, {dfi:.12g}\n" for zi, dfi in zip(z, df)))
    out, law = tmp_path / "force.csv", tmp_path / "law.csv"
    p = subprocess.run([cli, "spectroscopy", "reconstruct", str(src), "--spring-constant", "1800",
                        "--resonance-frequency", "25", "--amplitude", "0.5", "--method", "matrix",
                        "--output", str(out), "--law-output", str(law), "--json"],
                       capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stderr
    import json
    results = json.loads(p.stdout)
    assert results["mode"] == "fm" and results["method"] == "matrix" and results["units"]["residual_rms"] == "Hz"
    side = json.loads((tmp_path / "force.csv.json").read_text())
    assert [c["unit"] for c in side["columns"]][:3] == ["nm", "Hz", "nN"]
    data = np.genfromtxt(out, delimiter=",", names=True)
    np.testing.assert_allclose(data["force"], -1.0 * np.exp(-data["distance"] / 0.1), atol=0.01)  # nN
    q = subprocess.run([cli, "tapping", "orbit", "--units", "physical", "--law", "table", "--force-curve", str(law),
                        "--spring-constant", "1800", "--resonance-frequency", "25", "--free-amplitude", "0.5",
                        "--separation", "1", "--output", ""], capture_output=True, text=True, check=False)
    assert q.returncode == 0, q.stderr


def test_fm_round_trip_through_the_exact_orbits_of_tapping_fm():
    # Δf(z) made by afmkit's own FM forward model (exact orbits, DMT + vdW, a soft 40 N/m cantilever at A = 2 nm,
    # where the first-order formula is not exact); the matrix method's force, run back through the same exact
    # orbits at 20 of the distances, reproduces the measured Δf to 2 % of its largest value
    f = afmkit.tapping.fm(units="physical", law="dmt", hamaker=1e-19, spring_constant=40, resonance_frequency=300,
                          quality_factor=1e4, amplitude=2, axis="min_gap", separation_min=0.4, separation_max=8,
                          points=60, output="")
    z = np.asarray(f["min_gap"]) * 1e-9
    df = np.asarray(f["frequency_shift"])
    r = sr.reconstruct_fm(z, df, spring_constant=40, resonance_frequency=300e3, amplitude=2e-9, method="matrix",
                          tail="exponential", round_trip_points=20)
    assert "exact FM orbits" in r.round_trip_model and "at 20 of the 60" in r.round_trip_model
    visited = np.isfinite(r.round_trip_frequency_shift)
    assert visited.sum() == 20
    assert r.residual_rms < 0.02 * np.max(np.abs(df))
    # the first-order formula is another forward model: its round trip differs from the exact one
    g = sr.reconstruct_fm(z, df, spring_constant=40, resonance_frequency=300e3, amplitude=2e-9, method="matrix",
                          tail="exponential", round_trip_model="first_order")
    assert "first-order" in g.round_trip_model
    assert np.max(np.abs(g.round_trip_frequency_shift[visited] - r.round_trip_frequency_shift[visited])) > 0


def test_cantilever_settings_out_of_the_command_lines_range_are_refused_naming_it():
    # the reconstructions take the ranges of the fit and the command line (SI here: N/m, Hz, m); before, anything
    # up to 1e12 in any unit passed (a 1 km amplitude, Q = 1e11)
    z, df = _exponential_curve(1e-9, 20)
    fm = dict(spring_constant=K, resonance_frequency=F0_HZ, amplitude=1e-9)
    for key, bad, upper in (("spring_constant", 2e6, "1e+06 N/m"), ("resonance_frequency", 2e10, "1e+10 Hz"),
                            ("amplitude", 2e-3, "0.001 m")):
        with pytest.raises(afmkit.InvalidParameter, match=rf"{key} = [^:]+ is out of range: must be > 0 and <= "
                                                          + re.escape(upper)):
            sr.reconstruct_fm(z, df, round_trip=False, **dict(fm, **{key: bad}))
    for q in (2e9, -1.0):  # the exact round trip's Q: was an internal failure (exit-1 class) at -1, ran at 2e9
        with pytest.raises(afmkit.InvalidParameter, match=r"quality_factor = [^:]+ is out of range: must be > 0 and "
                                                          r"<= 1e\+09"):
            sr.reconstruct_fm(z, df, quality_factor=q, **fm)
    l = np.linspace(12e-9, 6e-9, 20)
    a, phi = l * 0.8, np.full(20, 1.2)
    am = dict(spring_constant=40.0, resonance_frequency=300e3, quality_factor=400.0, free_amplitude=10e-9)
    for key, bad, upper in (("quality_factor", 2e9, "1e+09"), ("free_amplitude", 1.0, "0.001 m"),
                            ("drive_frequency", 1e11, "1e+10 Hz")):
        with pytest.raises(afmkit.InvalidParameter, match=rf"{key} = [^:]+ is out of range: must be > 0 and <= "
                                                          + re.escape(upper)):
            sr.reconstruct_am(l, a, phi, round_trip=False, **dict(am, **{key: bad}))
