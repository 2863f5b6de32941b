"""afmkit.tapping.fm: the FM-AFM forward model from Python (docs/commands.md#tapping-fm)."""
import math

import numpy as np
import pytest

import afmkit


def test_fm_approach_in_physical_units_is_consistent():
    k, f0, q, a = 40.0, 300.0, 1000.0, 5.0
    r = afmkit.tapping.fm(units="physical", law="dmt", spring_constant=k, resonance_frequency=f0, quality_factor=q,
                          amplitude=a, separations=[12.0, 8.0, 6.0, 5.0, 4.0], quiet=True)
    assert r.results["status"] == "ok" and r.results["converged_rows"] == 5
    assert r.units["frequency_shift"] == "Hz" and r.units["dissipation"] == "J"
    sep = r["separation"]
    assert list(sep) == [12.0, 8.0, 6.0, 5.0, 4.0]  # an approach: decreasing separations
    # Δf and Δf/f0 agree (f0 in kHz on input), the frequency is f0 + Δf
    np.testing.assert_allclose(r["frequency_shift"], r["relative_frequency_shift"] * f0 * 1e3, rtol=1e-12)
    np.testing.assert_allclose(r["frequency"], f0 * 1e3 + r["frequency_shift"], rtol=1e-12)
    # eV column = J column / e
    np.testing.assert_allclose(r["dissipation_ev"], r["dissipation"] / 1.602176634e-19, rtol=1e-12)
    # attraction far out lowers the frequency, the amplitude is the setpoint, DMT (conservative) dissipates nothing:
    # |E_ts| below 1e-6 of the viscous loss per cycle π k A² / Q
    assert np.all(r["frequency_shift"][:3] < 0)
    np.testing.assert_allclose(r["amplitude"], a, rtol=1e-8)
    viscous = math.pi * k * (a * 1e-9) ** 2 / q
    assert np.all(np.abs(r["dissipation"]) < 1e-6 * viscous)
    assert np.all(r["min_gap"] < sep)


def test_fm_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="amplitude"):
        afmkit.tapping.fm(amplitude=-1.0)
    with pytest.raises(ValueError, match="drive_amplitude does not apply"):
        afmkit.tapping.fm(drive_amplitude=0.3)


def test_fm_is_a_study_computation(tmp_path):
    from afmkit.study import Study, run

    params = dict(units="physical", law="dmt", separations=[8.0, 6.0, 5.0], quiet=True)
    study = Study.make(computation="tapping.fm", axes={"amplitude": [2.0, 5.0]},
                       outputs=["min(frequency_shift)", "converged_rows"], parameters=params)
    ds = run(study, tmp_path / "fm.zarr", scheduler="serial", progress=False).load()
    for i, a in enumerate([2.0, 5.0]):
        r = afmkit.tapping.fm(amplitude=a, **params)
        assert ds["min_frequency_shift"].values[i] == np.min(r["frequency_shift"])
        assert ds["converged_rows"].values[i] == 3
