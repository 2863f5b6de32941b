"""afmkit.tapping.sweep(parameter=...) (docs/commands.md#sweeps-in-another-parameter): the generated command sweeps
the drive frequency; without contact its rows are the linear resonance curve in closed form, the first column is
the swept parameter and Result.plot() draws against it; a name that is not a parameter of the run is refused naming
`parameter`. Small runs: well under a second."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import afmkit  # noqa: E402


def test_frequency_sweep_without_contact_is_the_resonance_curve():
    q, gamma = 100.0, 0.2
    r = afmkit.tapping.sweep(parameter="drive_frequency", parameter_min=0.95, parameter_max=1.05, points=11,
                             mode="instrument", separation=1000.0, quality_factor=q, drive_amplitude=gamma,
                             quiet=True)
    assert list(r.keys())[:3] == ["drive_frequency", "separation", "direction"]
    assert r.results["parameter"] == "drive_frequency"
    assert r.results["down_jumps"] == [] and r.results["up_jumps"] == []
    assert set(r["direction"]) == {"down", "up"}
    w = np.asarray(r["drive_frequency"], float)
    exact = gamma / np.abs(1.0 - w**2 + 1j * w / q)
    np.testing.assert_allclose(r["amplitude"], exact, rtol=1e-9)
    np.testing.assert_allclose(r["separation"], 1000.0)
    ax = r.plot()
    line = ax[0].get_lines()[0]
    np.testing.assert_allclose(line.get_xdata()[np.isfinite(line.get_xdata())], w[: len(w) // 2])
    assert "drive frequency" in ax[-1].get_xlabel()
    plt.close("all")


def test_a_key_of_another_law_is_refused_naming_parameter():
    with pytest.raises(ValueError, match="parameter = effective_modulus is not a parameter of this run"):
        afmkit.tapping.sweep(parameter="effective_modulus", parameter_min=1, parameter_max=2, quiet=True)
